#!/usr/bin/python3
"""Compares a `make bench` summary with the committed reference and flags speed regressions.

    /usr/bin/python3 scripts/bench_compare.py [--reference scripts/bench_reference.json]
                                              [--threshold 0.25] [--min-seconds 0.02]
                                              [--mcf-min-seconds 0.1]
                                              [out/bench/summary.json]

The measure is, per mesh, our total over CGAL's MCF seconds on the same mesh in the same run
(`ours_over_mcf`): both run on the same machine at the same moment, so the ratio does not move
when the machine is faster, slower or busier. A mesh regresses when that ratio grew by more
than --threshold (0.25: 25%) over the reference and the growth costs at least --min-seconds of
our time (today's MCF seconds times the ratio's growth; it keeps the jitter of meshes that take
a few milliseconds out). Meshes that MCF does not run on (open, pinched, failed), or on which
it took less than --mcf-min-seconds in either summary (its time on a few hundred faces swings
by 2x from run to run: the ratio would flag noise), are compared by our total divided by the
machine factor: the median, over the meshes with MCF in both
summaries, of MCF's seconds now over its seconds in the reference. A mesh that fails now but
did not in the reference is a regression too. New meshes and meshes missing from the summary
are listed, not flagged.

Prints one table either way; exit status 1 when some mesh regressed, 2 when a summary cannot
be read, 0 otherwise. The summary is scripts/bench.py's `--summary` (make bench writes
out/bench/summary.json); a new reference is a summary copied over scripts/bench_reference.json.
The functions (compare, machine_factor, format_table) are tested in
tests/python/test_bench_compare.py.
"""
import argparse
import json
import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
THRESHOLD = 0.25
MIN_SECONDS = 0.02
MCF_MIN_SECONDS = 0.1

# Statuses of a row; the first two make the exit status 1.
REGRESSED, ERROR = "REGRESSED", "ERROR"
OK, IMPROVED, NEW, MISSING, NOT_COMPARED = "ok", "improved", "new", "missing", "not compared"


def load_summary(path):
    """The summary's {key: mesh record} (key: "set/mesh"). Raises OSError or ValueError."""
    data = json.loads(Path(path).read_text())
    meshes = data.get("meshes") if isinstance(data, dict) else None
    if not isinstance(meshes, dict):
        raise ValueError(f"{path}: not a bench summary (no 'meshes' object)")
    return meshes


def _number(record, key):
    value = (record or {}).get(key)
    return float(value) if isinstance(value, (int, float)) and value > 0 else None


def machine_factor(reference, current):
    """How much longer MCF took now than in the reference: the median over the meshes with MCF
    seconds in both (None when there is none)."""
    ratios = [_number(current[k], "mcf_seconds") / _number(reference[k], "mcf_seconds")
              for k in reference if k in current
              and _number(reference[k], "mcf_seconds") and _number(current[k], "mcf_seconds")]
    return statistics.median(ratios) if ratios else None


def _grown_stage(ref, cur, scale):
    """(stage, extra seconds) of the stage that grew most, today's seconds divided by
    `scale` (the machine), or None."""
    ref_stages, cur_stages = ref.get("stages") or {}, cur.get("stages") or {}
    grown = [(name, cur_stages[name] / scale - ref_stages.get(name, 0.0)) for name in cur_stages
             if isinstance(cur_stages[name], (int, float))]
    grown = [g for g in grown if g[1] > 0]
    return max(grown, key=lambda g: g[1]) if grown else None


def compare_mesh(key, ref, cur, factor, threshold=THRESHOLD, min_seconds=MIN_SECONDS,
                 mcf_min_seconds=MCF_MIN_SECONDS):
    """One row: key, status, basis ("ours/MCF", "total / machine", ""), reference and current
    value of that basis, change (current / reference - 1), grown stage, note."""
    row = {"mesh": key, "status": NOT_COMPARED, "basis": "", "reference": None, "current": None,
           "change": None, "stage": None, "note": ""}
    if ref is None:
        row.update(status=NEW, note="not in the reference")
        return row
    if cur is None:
        row.update(status=MISSING, note="not in this run")
        return row
    if cur.get("error"):
        if ref.get("error"):
            row.update(note=f"fails, as in the reference: {cur['error']}")
        else:
            row.update(status=ERROR, note=f"fails now: {cur['error']}")
        return row
    ref_total, cur_total = _number(ref, "total"), _number(cur, "total")
    if ref_total is None or cur_total is None:
        row.update(note="no total in " + ("the reference" if ref_total is None else "this run"))
        return row
    ref_ratio, cur_ratio = _number(ref, "ours_over_mcf"), _number(cur, "ours_over_mcf")
    long_enough = ref_ratio and cur_ratio and min(
        _number(ref, "mcf_seconds"), _number(cur, "mcf_seconds")) >= mcf_min_seconds
    if long_enough:
        scale = _number(cur, "mcf_seconds") / _number(ref, "mcf_seconds")
        row.update(basis="ours/MCF", reference=ref_ratio, current=cur_ratio)
        change = cur_ratio / ref_ratio - 1
        extra = (cur_ratio - ref_ratio) * _number(cur, "mcf_seconds")
    elif factor:
        scale = factor
        row.update(basis="total / machine", reference=ref_total, current=cur_total / factor)
        change = cur_total / factor / ref_total - 1
        extra = cur_total - ref_total * factor
    else:
        row.update(note="no MCF seconds to scale by")
        return row
    row["change"] = change
    if change > threshold and extra >= min_seconds:
        row["status"] = REGRESSED
        row["stage"] = _grown_stage(ref, cur, scale)
    elif change > threshold:
        row.update(status=OK, note=f"+{change:.0%} but only {extra * 1000:.0f} ms "
                                   f"(under --min-seconds)")
    elif change < -threshold:
        row["status"] = IMPROVED
    else:
        row["status"] = OK
    return row


def compare(reference, current, threshold=THRESHOLD, min_seconds=MIN_SECONDS,
            mcf_min_seconds=MCF_MIN_SECONDS):
    """(rows, machine factor): a row per mesh of either summary, the reference's order first,
    then the new meshes."""
    factor = machine_factor(reference, current)
    keys = list(reference) + [k for k in current if k not in reference]
    rows = [compare_mesh(k, reference.get(k), current.get(k), factor, threshold, min_seconds,
                         mcf_min_seconds) for k in keys]
    return rows, factor


def regressions(rows):
    return [r for r in rows if r["status"] in (REGRESSED, ERROR)]


def _value(value, basis):
    if value is None:
        return "-"
    return f"{value:.3f}" if basis == "ours/MCF" else f"{value:.3f} s"


def format_table(rows, factor, threshold=THRESHOLD):
    """A Markdown table of the rows and a closing line."""
    lines = ["| mesh | status | compared by | reference | now | change | stage grown most "
             "| note |", "|---|---|---|---:|---:|---:|---|---|"]
    for r in rows:
        change = "-" if r["change"] is None else f"{r['change']:+.0%}"
        stage = f"{r['stage'][0]} +{r['stage'][1]:.3f} s" if r["stage"] else ""
        status = f"**{r['status']}**" if r["status"] in (REGRESSED, ERROR) else r["status"]
        lines.append("| " + " | ".join([
            r["mesh"], status, r["basis"], _value(r["reference"], r["basis"]),
            _value(r["current"], r["basis"]), change, stage,
            r["note"].replace("|", "\\|")]) + " |")
    bad = regressions(rows)
    counts = {s: sum(r["status"] == s for r in rows) for s in (OK, IMPROVED, NEW, MISSING,
                                                              NOT_COMPARED)}
    machine = (f"MCF took {factor:.2f}x its reference time (median)" if factor
               else "no mesh has MCF seconds in both")
    names = ", ".join(r["mesh"] for r in bad) or "none"
    lines += ["", f"{len(bad)} regression(s) over {threshold:.0%} ({names}); "
              + ", ".join(f"{n} {s}" for s, n in counts.items() if n) + f". {machine}."]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("summary", nargs="?", type=Path,
                        default=ROOT / "out" / "bench" / "summary.json")
    parser.add_argument("--reference", type=Path,
                        default=ROOT / "scripts" / "bench_reference.json")
    parser.add_argument("--threshold", type=float, default=THRESHOLD,
                        help="flag a ratio that grew by more than this (default 0.25)")
    parser.add_argument("--min-seconds", type=float, default=MIN_SECONDS,
                        help="and that costs at least this many of our seconds (default 0.02)")
    parser.add_argument("--mcf-min-seconds", type=float, default=MCF_MIN_SECONDS,
                        help="compare by our total over the machine factor where MCF took less "
                             "(default 0.1)")
    args = parser.parse_args(argv)
    try:
        reference = load_summary(args.reference)
        current = load_summary(args.summary)
    except (OSError, ValueError) as e:
        print(f"bench_compare: {e}", file=sys.stderr)
        return 2
    rows, factor = compare(reference, current, args.threshold, args.min_seconds,
                           args.mcf_min_seconds)
    print(f"Speed against {args.reference} ({args.summary}):\n")
    print(format_table(rows, factor, args.threshold))
    return 1 if regressions(rows) else 0


if __name__ == "__main__":
    sys.exit(main())
