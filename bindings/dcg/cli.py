"""Command line: `/usr/bin/python3 -m dcg skeleton IN -o OUT.json [--tau 0.85 ...]`."""

from __future__ import annotations

import argparse
import sys
from typing import List, Optional

from . import OPTIONS, extract_skeleton, load_mesh


def _add_option_flags(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("engine options (defaults as in ALGORITHM.md)")
    for info in OPTIONS.values():
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
    _add_option_flags(sk)
    return parser


def run_skeleton(args: argparse.Namespace) -> int:
    options = {name: getattr(args, name) for name in OPTIONS if getattr(args, name) is not None}
    V, F = load_mesh(args.input)
    skeleton = extract_skeleton(V, F, **options)
    with open(args.output, "w", encoding="utf-8") as out:
        out.write(skeleton.to_json(indent=args.indent))
    if not args.quiet:
        counts = {k: int((skeleton.kinds == k).sum()) for k in ("end", "joint", "connection")}
        print(f"{args.input}: {len(V)} vertices, {len(F)} faces, genus {skeleton.genus}"
              f"{' (repaired)' if skeleton.repaired else ''}")
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
    except (OSError, ValueError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    return 2
