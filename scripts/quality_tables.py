"""The two quality benches' shared pieces (scripts/bench_rig_quality.py, inside Blender
scripts/bench_weights_quality.py): where the rigged characters are, the header, a mean row, and
the Markdown table with its JSON lines. No bpy, no dcg."""

import datetime
import json
import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def default_rigged() -> Path:
    """$DCG_MESHES/rigged, or ../shared/meshes/rigged beside the repository."""
    meshes = os.environ.get("DCG_MESHES") or str(ROOT.parent / "shared" / "meshes")
    return Path(meshes) / "rigged"


def header(title: str) -> list:
    """A title and the run's date and commit."""
    try:
        commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                                capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    date = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    return [f"# {title}", "", f"{date}, commit {commit}.", ""]


def mean_row(rows, keys, name="mean") -> dict:
    """A row holding the mean of `keys` over `rows` (None where a row lacks one)."""
    row = {"name": name}
    for key in keys:
        values = [r[key] for r in rows if r.get(key) is not None]
        row[key] = sum(values) / len(values) if values else None
    return row


def cell(value, spec: str) -> str:
    """value formatted by spec ('-' for None); spec '%' prints a fraction as a percentage."""
    if value is None:
        return "-"
    if spec == "%":
        return f"{100 * value:.1f}%"
    if spec == "d" and not isinstance(value, int):
        return f"{value:.1f}"  # a mean of counts
    return format(value, spec)


def table(columns, rows) -> list:
    """Markdown lines of rows (dicts) under columns [(title, key, spec)]."""
    lines = ["| " + " | ".join(title for title, _, _ in columns) + " |",
             "|" + "---|" * len(columns)]
    for row in rows:
        lines.append("| " + " | ".join(
            cell(row.get(key), spec) if spec else str(row.get(key, "-"))
            for _, key, spec in columns) + " |")
    return lines


def write(out, lines, rows) -> str:
    """Write the Markdown `lines` to `out` and one JSON line per row to out's .jsonl; print
    the Markdown and return it."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    text = "\n".join(lines) + "\n"
    out.write_text(text)
    out.with_suffix(".jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    print(text, flush=True)
    return text
