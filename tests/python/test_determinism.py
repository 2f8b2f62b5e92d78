"""Determinism across processes: the same input and options give a bit-identical skeleton in two
separate Python processes (other addresses, other hash seeds), so nothing depends on pointer
order or on state left from an earlier run. The 1 vs 2 threads check is in C++
(tests/cpp/test_determinism.cpp, with tbb::global_control)."""

import hashlib
import os
import subprocess
import sys

import numpy as np
import pytest

import dcg

SCRIPT = """
import hashlib, sys
import numpy as np
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



@pytest.mark.parametrize("amplitude, draw",
                         [(1e-5, 1), (1e-5, 3), (1e-5, 12), (1e-5, 17), (1e-5, 26), (1e-4, 4)])
def test_a_tiny_noise_leaves_mannequinys_skeleton_whole(meshes_dir, amplitude, draw):
    # Mannequiny with 1e-5 of its diagonal of noise on its vertices, as a re-export might leave
    # it. Each of these draws broke its skeleton: 1, a stray node in a void its ankle and foot
    # enclose (stage 0 fills such voids now) and a loop at a knee; 3, a hand's fingers lost (a
    # finger measured with its neighbour, sibling_levels); 12, a loop around the tiny tunnel
    # where its knee parts barely meet (a crack, not a handle, keep_handle_cycles); 17 and 26, a
    # thumb lost (its valley moved, its aspect below kThumbAspect; now the mirror image of the
    # other hand's thumb is a thumb too, prong_fingers.cpp). With 1e-4,
    # draw 4 made its head (one of its 59 parts) cross itself, and all the parts went to the
    # wrap, which smoothed all 8 fingers away: now only the head is wrapped (union.h).
    from dcg import bones

    V, F = dcg.load_mesh(meshes_dir / "rigged" / "Mannequiny.obj")
    diagonal = np.linalg.norm(np.ptp(V, axis=0))
    V = V + np.random.default_rng(draw).normal(size=V.shape) * amplitude * diagonal
    skeleton = dcg.extract_skeleton(V, F)
    n, links = skeleton.node_count, skeleton.links
    parent = list(range(n))

    def root(i):
        while parent[i] != i:
            i = parent[i]
        return i

    for a, b in links:
        parent[root(a)] = root(b)
    assert len({root(i) for i in range(n)}) == 1, "one skeleton, no stray node"
    assert len(links) == n - 1, "a tree: no loop"
    assert list(skeleton.kinds).count("end") == 11, "2 feet, the head, 4 ends on each hand"
    assert bones.unpaired_limbs(skeleton, np.array([0.0, 0.0, 1.0])) == 0


@pytest.mark.parametrize("draw", [4, 21])
def test_a_tiny_noise_leaves_the_kittens_tail_loop(meshes_dir, draw):
    # kitten.off (genus 1: its tail meets its body) with 1e-5 of its diagonal of noise: in 6 of
    # draws 1-29 the domain graph sampled the curled tail with fewer points, and the one link
    # that closes the loop crossed the inside of the curl's surface (0.19 radii out of it), so
    # the loop was lost. A link that only grazes the surface may close a cycle (kGraze).
    import mesh_parts

    V, F = dcg.load_mesh(meshes_dir / "kitten.off")
    diagonal = np.linalg.norm(np.ptp(V, axis=0))
    V = V + np.random.default_rng(draw).normal(size=V.shape) * 1e-5 * diagonal
    skeleton = dcg.extract_skeleton(V, F)
    assert len(skeleton.links) - skeleton.node_count + 1 == 1, "one loop, around the tail"
    points = np.vstack([np.reshape(line, (-1, 3)) for line in skeleton.polylines])
    assert mesh_parts.inside_any_part(points, V, F).all()  # the grazing link routed inside


@pytest.mark.parametrize("name, draw", [("rigged/Q_Frog.obj", 2), ("knight.off", 3)])
def test_a_tiny_noise_leaves_mirror_image_limbs_paired(meshes_dir, name, draw):
    # 1e-5 of the diagonal of noise, as above; both pairs did not pair, and the add-on warned:
    # Q_Frog's hips' joint came 0.7 off the plane with the crossing leg's first link still on
    # its side (dcg.junctions takes the first link that crosses); knight.off's arms mirror
    # each other across the surface's own plane (their centres 5.0% of the skeleton's size
    # apart, pairing allows 6%) but not across the plane fitted to its nodes (6.5%: its legs
    # are a little asymmetric), and only that plane paired limbs (symmetry.more_pairs).
    from dcg import bones

    V, F = dcg.load_mesh(meshes_dir / name)
    diagonal = np.linalg.norm(np.ptp(V, axis=0))
    V = V + np.random.default_rng(draw).normal(size=V.shape) * 1e-5 * diagonal
    skeleton = dcg.extract_skeleton(V, F)
    assert bones.unpaired_limbs(skeleton, np.array([0.0, 0.0, 1.0])) == 0
    plan = bones.plan_bones(skeleton)
    assert sum(spec.name.endswith(".L") for spec in plan) >= 8  # 2 pairs of limbs, 4 bones+


def test_a_part_that_crosses_itself_is_wrapped_alone(meshes_dir):
    # Mannequiny's head crosses itself under draw 4 of 1e-4 of the diagonal of noise (above):
    # the head alone is wrapped, the other 58 parts keep their own surface, and the user is told.
    V, F = dcg.load_mesh(meshes_dir / "rigged" / "Mannequiny.obj")
    diagonal = np.linalg.norm(np.ptp(V, axis=0))
    V = V + np.random.default_rng(4).normal(size=V.shape) * 1e-4 * diagonal
    working = dcg.Extractor(V, F).prepare()
    assert working.repaired and working.wrap_alpha == 0  # united, not wrapped whole
    assert working.report["wrapped_parts"] == 1
    assert working.report["part_wrap_alpha"] == pytest.approx(0.02)
    assert len(working.faces) > 20000  # the whole wrap had 3,044 faces
    assert "1 part that crossed itself replaced by its alpha wrap (details below 2.0% of" \
        in dcg.repair_summary(working)
    unperturbed = dcg.Extractor(*dcg.load_mesh(meshes_dir / "rigged" / "Mannequiny.obj"))
    assert unperturbed.prepare().report["wrapped_parts"] == 0


def test_union_of_parts_is_the_same_in_every_call(meshes_dir):
    # Q_Spider is 15 closed parts (legs pushed into the body), which stage 0 unites. CGAL's
    # corefinement returned the union's faces in an order that changed from call to call (its
    # box intersection draws from a shared random generator), and the remeshing and skeleton
    # after it followed (123 to 139 nodes); stage 0 now puts the union in one order.
    V, F = dcg.load_mesh(meshes_dir / "rigged" / "Q_Spider.obj")
    digests = set()
    for _ in range(3):
        ex = dcg.Extractor(V, F)
        working = ex.prepare()
        assert working.repaired and working.wrap_alpha == 0  # united, not wrapped
        h = hashlib.sha256(np.ascontiguousarray(working.vertices).tobytes())
        h.update(np.ascontiguousarray(working.faces).tobytes())
        h.update(np.ascontiguousarray(ex.skeleton().positions).tobytes())
        digests.add(h.hexdigest())
    assert len(digests) == 1


CPU_SCRIPT = """
import hashlib, sys
import numpy as np

import dcg
for path in sys.argv[1:]:
    V, F = dcg.load_mesh(path)
    s = dcg.extract_skeleton(V, F)
    h = hashlib.sha256()
    for a in [s.positions, s.radii, s.links, s.face_labels, *s.polylines]:
        h.update(np.ascontiguousarray(a).tobytes())
    print("digest", path, h.hexdigest())
"""

#: The rigged characters whose skeletons changed with Embree's kernels before every distance
#: was recomputed in double and ties went to the lowest face (10 of the 14 between SSE2 and
#: AVX2; these three were the last to differ).
CPU_SENSITIVE = ("Q_Goblin", "Q_Dragon", "Q_Snake")


def _digests(config, paths):
    """{path: skeleton digest} with Embree's device configured by `config` (None: its own
    choice), and the configuration Embree reports (the text after 'Config' when verbose)."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [os.path.dirname(os.path.dirname(dcg.__file__)), os.environ.get("PYTHONPATH", "")]))
    env.pop("DCG_EMBREE_CONFIG", None)
    if config:
        env["DCG_EMBREE_CONFIG"] = config + ",verbose=1"
    out = subprocess.run([sys.executable, "-c", CPU_SCRIPT, *map(str, paths)], env=env,
                         capture_output=True, text=True, check=True).stdout
    digests = {line.split()[1]: line.split()[2] for line in out.splitlines()
               if line.startswith("digest ")}
    return digests, out.partition("Config")[2]


def test_same_skeleton_with_every_cpus_kernels(meshes_dir):
    # Embree picks SSE2, AVX, AVX2 or AVX-512 kernels for the CPU it runs on, and their float
    # distances differ in the last bits: the same character rigged differently on another
    # machine (a batch on a mixed cluster, a user's laptop against CI). Forcing the older
    # kernels here stands in for the other CPUs.
    paths = [meshes_dir / "rigged" / f"{name}.obj" for name in CPU_SENSITIVE]
    native, _ = _digests(None, paths)
    assert len(native) == len(paths)
    for isa in ("sse2", "avx"):
        digests, config = _digests(f"isa={isa}", paths)
        isa_line = next(line for line in config.splitlines() if line.strip().startswith("ISA"))
        assert "AVX2" not in isa_line, f"Embree did not take isa={isa}: {isa_line}"
        assert digests == native, f"isa={isa}"
