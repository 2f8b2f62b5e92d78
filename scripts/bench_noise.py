"""Skeletons under a tiny noise: out/bench/noise.md.

    PYTHONPATH=build/python /usr/bin/python3 scripts/bench_noise.py [--draws 9]
        [--amplitude 1e-5] [--out out/bench/noise.md] [MESH ...]

Each mesh (by default the closed meshes of MANIFEST.tsv in $DCG_MESHES or ../shared/meshes, and
the rigged characters of its rigged/), unperturbed and with `draws` draws of Gaussian noise of
`amplitude` times its bounding-box diagonal on its vertices (numpy's default_rng(draw), draws
1..N): what a re-export, a format's rounding or a scan leaves. A draw keeps the skeleton when
its ends, components, cycles and unpaired limbs (`dcg.bones.unpaired_limbs` across the file's
up axis, `bench_rig_quality.floor_up`: limbs whose ends mirror each other yet did not pair, what
the add-on warns of) are the unperturbed skeleton's; joints are shown, not compared (a joint may
split or merge with the noise without harm to the rig). The table gives each mesh's unperturbed
counts, how many draws kept them, and what each other draw gave. How the last sessions found
skeletons that broke under such noise (a stray node, a lost loop, a lost finger, legs that did
not pair); ends and cycles are the ones `make bench`'s stability column compares, there under a
rotation, a scale and a 0.3% noise at once. Not part of `make test`; about 3 minutes on 2 cores.
"""

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

import mesh_parts
import quality_tables

COMPARED = ("ends", "components", "cycles", "unpaired")
COLUMNS = [("mesh", "name", ""), ("ends", "ends", "d"), ("joints", "joints", "d"),
           ("components", "components", "d"), ("cycles", "cycles", "d"),
           ("unpaired limbs", "unpaired", "d"), ("draws kept", "kept", ""),
           ("the other draws: ends / joints / components / cycles / unpaired", "others", ""),
           ("seconds", "seconds", ".1f")]


def default_meshes(public, rigged) -> list:
    """The closed meshes of public/MANIFEST.tsv (its `closed` column) and rigged/*.obj."""
    found = []
    manifest = Path(public) / "MANIFEST.tsv"
    if manifest.exists():
        with manifest.open(newline="") as f:
            found += [Path(public) / row["file"] for row in csv.DictReader(f, delimiter="\t")
                      if row.get("closed") == "yes" and (Path(public) / row["file"]).exists()]
    return found + sorted(Path(rigged).glob("*.obj"))


def counts(skeleton, up) -> dict:
    """The skeleton's ends, joints, components, cycles (links - nodes + components) and
    unpaired limbs across `up`."""
    from dcg import bones

    kinds = np.asarray(skeleton.kinds)
    links = np.asarray(skeleton.links, dtype=np.int64).reshape(-1, 2)
    nodes = len(kinds)
    components = len(np.unique(mesh_parts.connected_components(nodes, links)))
    return {"ends": int((kinds == "end").sum()), "joints": int((kinds == "joint").sum()),
            "components": components, "cycles": len(links) - nodes + components,
            "unpaired": int(bones.unpaired_limbs(skeleton, up))}


def differs(base, other) -> list:
    """The COMPARED counts in which `other` is not `base`."""
    return [key for key in COMPARED if other[key] != base[key]]


def noisy(V, draw, amplitude) -> np.ndarray:
    """V with Gaussian noise of `amplitude` x its bounding-box diagonal (numpy draw `draw`)."""
    V = np.asarray(V, dtype=float)
    diagonal = float(np.linalg.norm(np.ptp(V, axis=0)))
    return V + np.random.default_rng(draw).normal(size=V.shape) * amplitude * diagonal


def measure(path, draws, amplitude) -> dict:
    """One mesh's row."""
    import dcg
    from bench_rig_quality import floor_up

    start = time.perf_counter()
    V, F = dcg.load_mesh(str(path))
    up = floor_up(V)
    row = {"name": Path(path).name, **counts(dcg.extract_skeleton(V, F), up), "draws": draws}
    others = []
    for draw in range(1, draws + 1):
        got = counts(dcg.extract_skeleton(noisy(V, draw, amplitude), F), up)
        if differs(row, got):
            others.append(f"{draw}: " + " / ".join(str(got[k]) for k in
                                                   ("ends", "joints", "components", "cycles",
                                                    "unpaired")))
    row.update(kept=f"{draws - len(others)} of {draws}", kept_count=draws - len(others),
               others="; ".join(others) or "-", seconds=time.perf_counter() - start)
    return row


def report(rows, draws, amplitude) -> list:
    """The Markdown lines of `rows`."""
    kept = sum(row["kept_count"] for row in rows)
    whole = sum(row["kept_count"] == draws for row in rows)
    lines = quality_tables.header("Skeletons under a tiny noise")
    lines += [f"Gaussian noise of {amplitude:g} x each mesh's bounding-box diagonal on its "
              f"vertices, numpy draws 1-{draws}. A draw keeps the skeleton when its "
              f"{', '.join(COMPARED)} are the unperturbed one's (unpaired: limbs whose ends "
              "mirror each other that did not pair, `dcg.bones.unpaired_limbs`). "
              f"Kept: {kept} of {draws * len(rows)} draws; {whole} of {len(rows)} meshes in "
              "every draw.", ""]
    return lines + quality_tables.table(COLUMNS, rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("meshes", nargs="*", type=Path,
                        help="mesh files (default: the closed meshes of --public's "
                             "MANIFEST.tsv and --rigged's characters)")
    parser.add_argument("--public", type=Path, default=quality_tables.default_rigged().parent)
    parser.add_argument("--rigged", type=Path, default=quality_tables.default_rigged())
    parser.add_argument("--draws", type=int, default=9)
    parser.add_argument("--amplitude", type=float, default=1e-5)
    parser.add_argument("--out", type=Path,
                        default=quality_tables.ROOT / "out" / "bench" / "noise.md")
    args = parser.parse_args()
    meshes = args.meshes or default_meshes(args.public, args.rigged)
    if not meshes:
        print("bench_noise: no meshes found; skipped", file=sys.stderr)
        return 0
    rows = []
    for path in meshes:
        rows.append(measure(path, args.draws, args.amplitude))
        print(f"bench_noise: {rows[-1]['name']}: kept {rows[-1]['kept']}", file=sys.stderr,
              flush=True)
    quality_tables.write(args.out, report(rows, args.draws, args.amplitude), rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
