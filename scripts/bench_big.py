"""The scale row of `make bench`: the whole pipeline on a ~1M-face mesh (armadillo.obj midpoint-
subdivided twice, scripts/make_big_mesh.py), with progress reporting, then skinning weights
transferred back to every input vertex. Reports seconds and peak RSS against the issue's limits
(30 s, 2 GB on 2 cores) in out/bench/big.md.

The work runs in a child process so that its peak RSS (getrusage of the children) is the
pipeline's alone.

    PYTHONPATH=build/python python3 scripts/bench_big.py [--mesh out/bench/armadillo-1m.ply]
                                                          [--out out/bench/big.md]
"""

import argparse
import datetime
import json
import os
import platform
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LIMIT_SECONDS = 30.0
LIMIT_RSS_MB = 2048.0

CHILD = r"""
import json, sys, time
import numpy as np
import dcg
t0 = time.perf_counter()
V, F = dcg.load_mesh(sys.argv[1])
t_load = time.perf_counter() - t0
last = [None]
def progress(stage, fraction):
    if stage != last[0]:
        print(f"  {time.perf_counter() - t0:6.1f} s  {stage}", file=sys.stderr, flush=True)
        last[0] = stage
    return True
t1 = time.perf_counter()
ex = dcg.Extractor(V, F, progress)
skeleton = ex.skeleton()
t_skeleton = time.perf_counter() - t1
t2 = time.perf_counter()
weights = dcg.skin_weights(V, F, skeleton, prepared=ex.prepare(), progress=progress)
t_weights = time.perf_counter() - t2
rows = np.asarray(weights.rows)
print(json.dumps({
    "vertices": len(V), "faces": len(F), "load_s": t_load, "skeleton_s": t_skeleton,
    "weights_s": t_weights, "total_s": time.perf_counter() - t0, "nodes": skeleton.node_count,
    "method": skeleton.method, "weighted_vertices": int(len(np.unique(rows))),
    "stages": ex.timings}))
"""


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", type=Path, default=ROOT / "out/bench/armadillo-1m.ply")
    parser.add_argument("--source", type=Path, default=None,
                        help="armadillo.obj to subdivide when --mesh is missing")
    parser.add_argument("--out", type=Path, default=ROOT / "out/bench/big.md")
    args = parser.parse_args(argv)
    if not args.mesh.is_file():
        cmd = [sys.executable, str(ROOT / "scripts/make_big_mesh.py"), "--out", str(args.mesh)]
        if args.source:
            cmd += ["--mesh", str(args.source)]
        if subprocess.run(cmd).returncode != 0:
            print("bench_big: no big mesh, row skipped", file=sys.stderr)
            return 0
    print(f"bench_big: {args.mesh}", file=sys.stderr)
    load_before = os.getloadavg()  # the machine may be shared: timings mean little without it
    start = time.perf_counter()
    child = subprocess.run([sys.executable, "-c", CHILD, str(args.mesh)], stdout=subprocess.PIPE,
                           text=True, env=os.environ)
    wall = time.perf_counter() - start
    load_after = os.getloadavg()
    peak_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0  # KiB on Linux
    if child.returncode != 0:
        print(f"bench_big: the pipeline failed (exit {child.returncode})", file=sys.stderr)
        return 1
    r = json.loads(child.stdout.strip().splitlines()[-1])
    seconds = r["load_s"] + r["skeleton_s"] + r["weights_s"]
    verdict = []
    for name, value, limit, unit in (("time", seconds, LIMIT_SECONDS, "s"),
                                     ("peak RSS", peak_mb, LIMIT_RSS_MB, "MB")):
        if value <= limit:
            verdict.append(f"{name} within {limit:g} {unit}")
        else:
            verdict.append(f"{name} misses {limit:g} {unit} by {value - limit:.1f} {unit} "
                           f"({value / limit:.2f}x)")
    stages = ", ".join(f"{name} {s:.2f}" for name, s in r["stages"])
    slowest, slowest_s = max(r["stages"], key=lambda item: item[1])
    why = (f"Slowest stage: {slowest}, {slowest_s:.2f} s ({100 * slowest_s / seconds:.0f} % of "
           "the total)" + (" (stage 0: welding, checks, the reduction to target_faces by a fast "
                          "pass-wise edge collapse, then CGAL's edge collapse and isotropic "
                          "remeshing, and the map back to every input vertex)"
                          if slowest == "prepare" else "") + ".")
    lines = [
        "# Scale: a ~1M-face mesh through the whole pipeline",
        "",
        f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, "
        f"{platform.node()}, {os.cpu_count()} cores, default options; "
        "`scripts/bench_big.py` (mesh: `scripts/make_big_mesh.py`).",
        "",
        "| mesh | vertices | faces | load s | skeleton s | weights s | total s | peak RSS MB "
        "| nodes | weighted vertices | verdict |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
        f"| {args.mesh.name} | {r['vertices']} | {r['faces']} | {r['load_s']:.2f} "
        f"| {r['skeleton_s']:.2f} | {r['weights_s']:.2f} | {seconds:.2f} | {peak_mb:.0f} "
        f"| {r['nodes']} | {r['weighted_vertices']} | {'; '.join(verdict)} |",
        "",
        f"Stages (s): {stages}. Method: {r['method']}. Child wall time {wall:.1f} s (with "
        "interpreter start).",
        "",
        f"Load average (1, 5, 15 min) before: {', '.join(f'{x:.2f}' for x in load_before)}; "
        f"after: {', '.join(f'{x:.2f}' for x in load_after)} (on {os.cpu_count()} cores: a "
        "load above that means other work shared the machine and the times are inflated).",
        "",
        why,
        "",
    ]
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text("\n".join(lines))
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
