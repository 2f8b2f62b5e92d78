#!/usr/bin/python3
"""Batch throughput: `dcg batch` on a mesh folder with 1 and with 2 local workers (make bench).

    PYTHONPATH=build/python /usr/bin/python3 scripts/bench_batch.py \\
        [--out out/bench/batch.md] [--workers 1 2] [--tau 0.85 ...] [PATH ...]

PATH: mesh files or folders (default ../shared/meshes); files are linked into one temporary
folder. Each worker count rigs every model from scratch (skeleton and weights, default engine
options unless given) into a fresh temporary output folder on a new Dask LocalCluster, and the
report gives models per minute over the rigging itself (cluster start excluded), the wall time
with it, and the failures. Writes the markdown report to --out and prints it.
"""
import argparse
import datetime
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def gather(paths, folder: Path) -> Path:
    """One folder holding every mesh of `paths` (a single folder is used as it is)."""
    if len(paths) == 1 and paths[0].is_dir():
        return paths[0]
    for path in paths:
        files = [path] if path.is_file() else sorted(p for p in path.rglob("*") if p.is_file())
        for file in files:
            target = folder / file.name
            if not target.exists():
                target.symlink_to(file.resolve())
    return folder


def main():
    from dcg import batch, cli

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="*", type=Path,
                        help="mesh files or folders (default ../shared/meshes)")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "bench" / "batch.md")
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    cli._add_option_flags(parser, cli.OPTIONS)
    args = parser.parse_args()
    paths = args.paths or [ROOT.parent / "shared" / "meshes"]
    missing = [str(p) for p in paths if not p.exists()]
    if missing:
        print(f"bench_batch: not found: {', '.join(missing)}; skipped", file=sys.stderr)
        return 0
    options = {n: getattr(args, n) for n in cli.OPTIONS if getattr(args, n) is not None}

    rows = []
    with tempfile.TemporaryDirectory(prefix="dcg-bench-batch-") as tmp:
        folder = gather(paths, Path(tmp) / "in")
        for workers in args.workers:
            print(f"bench_batch: {folder} with {workers} worker(s)...", file=sys.stderr,
                  flush=True)
            summary = batch.run(folder, Path(tmp) / f"out{workers}", options=options,
                                workers=workers, force=True, progress=None)
            rows.append((workers, summary))
    cores = len(os.sched_getaffinity(0))
    lines = [
        "# dcg batch throughput", "",
        f"{datetime.datetime.now().astimezone():%Y-%m-%d %H:%M %Z}; {cores} cores; "
        f"meshes: {', '.join(map(str, paths))}; options: {options or 'defaults'}.", "",
        "Skeleton JSON and weights for every model; each worker a single-threaded process, on "
        "a fresh Dask LocalCluster each time. Models per minute count the rigging "
        "(first task submitted to last result); the wall time includes starting the cluster.",
        "", "| workers | models | ok | failed | rigging s | wall s | models/min | speed-up |",
        "|---|---|---|---|---|---|---|---|",
    ]
    base = rows[0][1].rate if rows and rows[0][1].rate > 0 else None
    for workers, s in rows:
        speedup = f"{s.rate / base:.2f}x" if base else "-"
        lines.append(f"| {workers} | {s.found} | {s.ok} | {s.failed} | {s.rig_seconds:.1f} | "
                     f"{s.seconds:.1f} | {s.rate:.1f} | {speedup} |")
    failures = {path: message for _, s in rows for path, message in s.failures}
    if failures:
        lines += ["", "Failures:", ""] + [f"- `{p}`: {m}" for p, m in sorted(failures.items())]
    text = "\n".join(lines) + "\n"
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(text + f"\nwritten to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
