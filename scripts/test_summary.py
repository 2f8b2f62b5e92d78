"""Adds up JUnit XML files: one line per suite, then `total: N passed, N failed, N skipped`.

A suite whose file is missing or unreadable counts as one failure (it crashed or never ran).
Exit code 1 when anything failed, else 0.
"""

import sys
import xml.etree.ElementTree as ET
from pathlib import Path


def count(path: Path):
    """(passed, failed, skipped, names of failed tests) of one JUnit file."""
    passed = failed = skipped = 0
    failures = []
    for case in ET.parse(path).getroot().iter("testcase"):
        name = f"{case.get('classname', '')}.{case.get('name', '')}".strip(".")
        status = (case.get("status") or "").lower()
        if case.find("failure") is not None or case.find("error") is not None or status == "fail":
            failed += 1
            failures.append(name)
        elif case.find("skipped") is not None or status in ("notrun", "disabled", "skipped"):
            skipped += 1
        else:
            passed += 1
    return passed, failed, skipped, failures


def main(paths):
    totals = [0, 0, 0]
    for p in map(Path, paths):
        suite = p.stem
        try:
            passed, failed, skipped, failures = count(p)
        except (OSError, ET.ParseError) as error:
            passed, failed, skipped, failures = 0, 1, 0, [f"{suite}: no results ({error})"]
        if passed + failed + skipped == 0:
            failed, failures = 1, [f"{suite}: ran no test"]
        print(f"{suite:>8}: {passed} passed, {failed} failed, {skipped} skipped")
        for name in failures:
            print(f"          FAILED {name}")
        totals = [totals[0] + passed, totals[1] + failed, totals[2] + skipped]
    print(f"total: {totals[0]} passed, {totals[1]} failed, {totals[2]} skipped")
    return 1 if totals[1] else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
