"""Adds up JUnit XML files: one line per suite, then `total: N passed, N failed, N skipped`.

A suite whose file is missing or unreadable counts as one failure (it crashed or never ran).
Exit code 1 when anything failed, else 0.

    python3 scripts/test_summary.py --skip FILE SUITE REASON

writes FILE: a suite of one skipped test that says REASON (a Blender version this machine cannot
run), so that it is counted, never dropped silently.
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


def write_skipped_suite(path, suite, reason):
    root = ET.Element("testsuites")
    cases = ET.SubElement(root, "testsuite", name=suite, tests="1", skipped="1")
    case = ET.SubElement(cases, "testcase", classname=suite, name="the whole suite")
    ET.SubElement(case, "skipped", message=reason)
    ET.ElementTree(root).write(path, encoding="unicode")


def whole_suite_skip(path: Path):
    """The reason when `path` is a suite skipped as a whole (see write_skipped_suite)."""
    cases = list(ET.parse(path).getroot().iter("testcase"))
    if len(cases) == 1 and cases[0].get("name") == "the whole suite":
        skipped = cases[0].find("skipped")
        return None if skipped is None else skipped.get("message")
    return None


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
        print(f"{suite:>16}: {passed} passed, {failed} failed, {skipped} skipped")
        reason = whole_suite_skip(p) if skipped == 1 and passed + failed == 0 else None
        if reason:
            print(f"                  skipped: {reason}")
        for name in failures:
            print(f"                  FAILED {name}")
        totals = [totals[0] + passed, totals[1] + failed, totals[2] + skipped]
    print(f"total: {totals[0]} passed, {totals[1]} failed, {totals[2]} skipped")
    return 1 if totals[1] else 0


if __name__ == "__main__":
    if sys.argv[1:2] == ["--skip"] and len(sys.argv) == 5:
        sys.exit(write_skipped_suite(*sys.argv[2:]))
    sys.exit(main(sys.argv[1:]))
