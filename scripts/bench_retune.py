"""The live-tau row of `make bench`: how fast `Extractor.retune(tau)` re-thresholds the prongs
and how fast the skeleton at the new tau follows (only the end points, the domain graph, the
remap and the skeleton run again), against issue 18's limits: the re-threshold at most 50 ms at
100k faces, the new skeleton at most 0.3 s on hand.obj. Writes out/bench/retune.md (and .jsonl).

    PYTHONPATH=build/python python3 scripts/bench_retune.py [MESH ...] [--out out/bench/retune.md]

Each mesh: one full skeleton at the default tau, then rounds of retunes through --tau values
(each a change of tau), the fastest of the rounds per tau kept.
"""

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import quality_tables  # beside this script (scripts/)

ROOT = Path(__file__).resolve().parents[1]
MESHES = Path(os.environ.get("DCG_MESHES", ROOT.parent / "shared" / "meshes"))
DEFAULT_MESHES = [MESHES / "hand.obj", MESHES / "horse.ply",
                  ROOT / "out/bench/stress/quadruped-100k.ply"]
#: Issue 18's limits: the re-threshold on meshes from LARGE_FACES faces up, the new skeleton on
#: the hand.
RETHRESHOLD_LIMIT_S = 0.050
LARGE_FACES = 90_000
SKELETON_LIMIT_S = 0.3
SKELETON_LIMIT_MESH = "hand.obj"
COLUMNS = [("mesh", "mesh", ""), ("faces", "faces", "d"), ("full s", "full_s", ".3f"),
           ("tau", "tau", "g"), ("ends", "ends", "d"), ("re-threshold ms", "rethreshold_ms", ".2f"),
           ("new skeleton ms", "skeleton_ms", ".1f"), ("limits", "limits", "")]


def measure(path, taus, rounds):
    """(faces, full skeleton seconds, {tau: (re-threshold s, new skeleton s, ends)})."""
    import dcg

    V, F = dcg.load_mesh(path)
    ex = dcg.Extractor(V, F)
    start = time.perf_counter()
    ex.skeleton()
    full = time.perf_counter() - start
    best = {}
    for _ in range(rounds):
        for tau in taus:
            start = time.perf_counter()
            ex.retune(tau)
            rethreshold = time.perf_counter() - start
            skeleton = ex.skeleton()
            total = time.perf_counter() - start
            ends = int((skeleton.kinds == "end").sum())
            old = best.get(tau)
            best[tau] = (min(rethreshold, old[0]) if old else rethreshold,
                         min(total, old[1]) if old else total, ends)
    return len(F), full, best


def verdicts(name, faces, rethreshold, skeleton):
    """The limits that apply to this mesh, each met or missed."""
    out = []
    if faces >= LARGE_FACES:
        out.append(("re-threshold", rethreshold, RETHRESHOLD_LIMIT_S))
    if name == SKELETON_LIMIT_MESH:
        out.append(("new skeleton", skeleton, SKELETON_LIMIT_S))
    return "; ".join(f"{what} {'met' if value <= limit else '**missed**'} "
                     f"(limit {1000 * limit:g} ms)" for what, value, limit in out) or "-"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("meshes", nargs="*", type=Path, default=DEFAULT_MESHES)
    parser.add_argument("--tau", type=float, nargs="+", default=[0.7, 0.95, 0.85],
                        help="the taus retuned to, in turn (default 0.7 0.95 0.85)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--out", type=Path, default=ROOT / "out/bench/retune.md")
    args = parser.parse_args(argv)
    records = []
    for path in args.meshes:
        if not path.is_file():
            print(f"bench_retune: {path} not found, skipped", file=sys.stderr)
            continue
        faces, full, best = measure(path, args.tau, args.rounds)
        records += [{"mesh": path.name, "faces": faces, "full_s": full, "tau": tau, "ends": ends,
                     "rethreshold_ms": 1000 * rethreshold, "skeleton_ms": 1000 * skeleton,
                     "limits": verdicts(path.name, faces, rethreshold, skeleton)}
                    for tau, (rethreshold, skeleton, ends) in best.items()]
        print(f"bench_retune: {path.name} done", file=sys.stderr)
    lines = quality_tables.header("Live tau: Extractor.retune")
    lines += [f"{platform.node()}, {os.cpu_count()} cores, load average "
              f"{os.getloadavg()[0]:.2f}; `scripts/bench_retune.py`. Full: the first skeleton at "
              "the default tau; re-threshold: the `retune(tau)` call; new skeleton: from that call "
              f"to the skeleton at the new tau; fastest of {args.rounds} rounds. Limits (issue "
              f"18): the re-threshold at most {1000 * RETHRESHOLD_LIMIT_S:g} ms from "
              f"{LARGE_FACES:,} faces, the new skeleton at most {SKELETON_LIMIT_S:g} s on "
              f"{SKELETON_LIMIT_MESH}.", ""]
    lines += quality_tables.table(COLUMNS, records) + [""]
    quality_tables.write(args.out, lines, records)
    return 0


if __name__ == "__main__":
    sys.exit(main())
