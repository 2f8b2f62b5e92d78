"""Determinism across processes: the same input and options give a bit-identical skeleton in two
separate Python processes (other addresses, other hash seeds), so nothing depends on pointer
order or on state left from an earlier run. The 1 vs 2 threads check is in C++
(tests/cpp/test_determinism.cpp, with tbb::global_control)."""

import hashlib
import os
import subprocess
import sys

import dcg

SCRIPT = """
import hashlib, sys
import numpy as np
import dcg
V, F = dcg.load_mesh(sys.argv[1])
s = dcg.extract_skeleton(V, F, samples=800, target_faces=3000, seed=3)
h = hashlib.sha256()
for a in [s.positions, s.radii, s.significance, s.links, s.face_labels, *s.polylines]:
    h.update(np.ascontiguousarray(a).tobytes())
h.update(("|".join(s.kinds) + s.method + str(s.root)).encode())
print(h.hexdigest())
"""


def test_same_skeleton_in_separate_processes(repo):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [os.path.dirname(os.path.dirname(dcg.__file__)), os.environ.get("PYTHONPATH", "")]))
    digests = set()
    for hash_seed in ("1", "2"):
        env["PYTHONHASHSEED"] = hash_seed
        out = subprocess.run([sys.executable, "-c", SCRIPT, str(repo / "data" / "spot.obj")],
                             env=env, capture_output=True, text=True, check=True)
        digests.add(out.stdout.strip())
    assert len(digests) == 1, digests
    assert len(next(iter(digests))) == len(hashlib.sha256().hexdigest())
