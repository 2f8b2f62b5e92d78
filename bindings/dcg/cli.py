"""Command line: `/usr/bin/python3 -m dcg skeleton IN -o OUT.json [--tau 0.85 ...]`,
`/usr/bin/python3 -m dcg batch IN_DIR OUT_DIR [--scheduler tcp://HOST:8786] ...` (dcg.batch)."""

from __future__ import annotations

import argparse
import sys
from typing import List, Optional

from . import OPTIONS, Extractor, bones, load_mesh, repair_summary
from .options import SKELETON_OPTIONS


def _add_option_flags(parser: argparse.ArgumentParser, names) -> None:
    group = parser.add_argument_group("engine options (defaults as in ALGORITHM.md)")
    for info in (OPTIONS[name] for name in names):
        flags = [f"--{info.name.replace('_', '-')}"]
        if "_" in info.name:
            flags.append(f"--{info.name}")
        help_text = f"{info.description} (default {info.default}"
        if info.kind == "choice":
            group.add_argument(*flags, dest=info.name, choices=info.choices, default=None,
                               help=help_text + ")")
        else:
            unit = f", {info.unit}" if info.unit else ""
            group.add_argument(*flags, dest=info.name, default=None,
                               type=int if info.kind == "int" else float,
                               help=f"{help_text}, range {info.minimum:g}..{info.maximum:g}"
                               f"{unit})")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m dcg", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    sk = commands.add_parser("skeleton", help="extract the DCG skeleton of a mesh file as JSON")
    sk.add_argument("input", help="mesh file (.obj, .off, .ply, .stl)")
    sk.add_argument("-o", "--output", required=True, help="JSON file to write (dcg-skeleton/1)")
    sk.add_argument("--indent", type=int, default=None, help="pretty-print the JSON")
    sk.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    _add_option_flags(sk, SKELETON_OPTIONS)
    batch = commands.add_parser(
        "batch", help="rig every mesh under a folder, on this machine or a Dask cluster",
        description="Writes OUT_DIR/<relative path>.json (skeleton), .weights.npz and with "
        "--glb .glb for every OBJ/OFF/PLY/STL (with --glb also FBX/glTF) under IN_DIR, and "
        "OUT_DIR/index.jsonl (one record per model). Finished models are skipped. Exit status "
        "0 when every model of the run succeeded, 1 when some failed, 2 when it cannot run.")
    batch.add_argument("input", help="folder of meshes (searched recursively)")
    batch.add_argument("output", help="output folder")
    batch.add_argument("--scheduler", help="address of a running Dask scheduler "
                       "(tcp://HOST:8786); default: a local cluster")
    batch.add_argument("--workers", type=int, help="local worker processes (default: one per "
                       "core; ignored with --scheduler)")
    batch.add_argument("--glb", action="store_true", help="also write a rigged .glb with the "
                       "add-on's headless Blender CLI (and read FBX/glTF inputs)")
    batch.add_argument("--force", action="store_true", help="redo finished models too")
    batch.add_argument("--retry-failed", action="store_true",
                       help="redo the models whose last run failed")
    batch.add_argument("--timeout", type=float, help="seconds allowed per model")
    batch.add_argument("--retries", type=int, default=2,
                       help="times a task is retried when it raises (default 2)")
    batch.add_argument("--blender", help="Blender executable (default $BLENDER or blender)")
    batch.add_argument("--blender-cli", help="the add-on's headless entry point, "
                       "dcg_rig/cli.py (default $DCG_BLENDER_CLI, else the dcg_rig add-on "
                       "installed in that Blender)")
    batch.add_argument("--bone-detail", type=float, default=bones.BONE_DETAIL,
                       help="the bone plan's detail, 0 (one bone per limb) to 1 (a bone per "
                       "polyline segment; dcg.bones explains the count), for the .weights.npz and "
                       f"the .glb alike (default {bones.BONE_DETAIL}, the add-on's)")
    batch.add_argument("--bone-names", choices=bones.BONE_NAME_CONVENTIONS,
                       default=bones.BONE_NAMES,
                       help="how bones are named: dcg (by limb and side, arm.002.L) or mixamo (a "
                       "humanoid's bones named and counted after Mixamo's rig, for retargeting; "
                       f"other shapes keep the dcg names; default {bones.BONE_NAMES})")
    batch.add_argument("--root-bone", action=argparse.BooleanOptionalAction,
                       default=bones.ROOT_BONE,
                       help="start each rig with a root bone on the floor (+Y up for OBJ, +Z "
                       "for the others, as the add-on's CLI imports them) that deforms nothing "
                       f"(default {'on' if bones.ROOT_BONE else 'off'})")
    batch.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    _add_option_flags(batch, OPTIONS)
    return parser


def run_batch(args: argparse.Namespace) -> int:
    from . import batch

    options = {name: getattr(args, name) for name in OPTIONS if getattr(args, name) is not None}
    try:
        summary = batch.run(args.input, args.output, options=options, scheduler=args.scheduler,
                            workers=args.workers, glb=args.glb, force=args.force,
                            retry_failed=args.retry_failed, blender=args.blender,
                            blender_cli=args.blender_cli, timeout=args.timeout,
                            retries=args.retries, bone_detail=args.bone_detail,
                            bone_names=args.bone_names, root_bone=args.root_bone,
                            progress=None if args.quiet else sys.stderr)
    except batch.BatchError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(f"dcg batch: {summary.text()}")
    return 1 if summary.failed else 0


def run_skeleton(args: argparse.Namespace) -> int:
    options = {name: getattr(args, name) for name in SKELETON_OPTIONS
               if getattr(args, name) is not None}
    V, F = load_mesh(args.input)
    extractor = Extractor(V, F, **options)
    skeleton = extractor.skeleton()
    with open(args.output, "w", encoding="utf-8") as out:
        out.write(skeleton.to_json(indent=args.indent))
    if not args.quiet:
        counts = {k: int((skeleton.kinds == k).sum()) for k in ("end", "joint", "connection")}
        print(f"{args.input}: {len(V)} vertices, {len(F)} faces, genus {skeleton.genus}")
        repair = repair_summary(extractor.prepare())
        if repair:
            print(f"repaired: {repair}")
        print(f"skeleton ({skeleton.method}): {skeleton.node_count} nodes "
              f"({counts['end']} end, {counts['joint']} joint, {counts['connection']} "
              f"connection), {len(skeleton.links)} links -> {args.output}")
        for stage, seconds in skeleton.timings.items():
            print(f"  {stage:<16} {seconds:8.3f} s")
    return 0


def main(argv: Optional[List[str]] = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        if args.command == "skeleton":
            return run_skeleton(args)
        if args.command == "batch":
            return run_batch(args)
    except (OSError, ValueError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    return 2
