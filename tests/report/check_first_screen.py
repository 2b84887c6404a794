#!/usr/bin/python3
"""Loads a report in headless Chromium and checks its first screen (issue 44): the page loads
without console errors and the verdict table (technique x budget, marks, ladder reach, noise)
sits under the title, above the provenance, with a line per scene (page_checks.check_verdict).
For a real study's report, e.g. the pilot's:

    PYTHONPATH=scripts /usr/bin/python3 tests/report/check_first_screen.py \\
        results/study_pilot/report.html

Prints each check; exits 1 if one fails, 77 without /usr/bin/chromium.
"""
import os
import sys
import tempfile

import page_checks
from test_report import CHROMIUM, Checks, load_dom


def main(argv: list[str]) -> int:
    if len(argv) != 1 or not os.path.isfile(argv[0]):
        print(__doc__, file=sys.stderr)
        return 2
    if not os.path.exists(CHROMIUM):
        print(f"check_first_screen: {CHROMIUM} not installed; skipping")
        return 77
    checks = Checks()
    with tempfile.TemporaryDirectory() as tmp:
        dom = load_dom(checks, tmp, os.path.abspath(argv[0]), "report")
        page_checks.check_verdict(checks, dom)
    print("\n".join(checks.lines))
    print(f"{checks.passed} passed, {len(checks.failed)} failed")
    return 1 if checks.failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
