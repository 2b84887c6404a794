#!/usr/bin/env python3
"""Prints how many ctest tests skipped and why, from ctest's LastTest.log (scripts/test.sh).

A GoogleTest skip prints "<file>:<line>: Skipped" and then its message; a script test that
exits 77 (SKIP_RETURN_CODE) prints its own reason. Tests are grouped by the first line of the
message, so "shared scenes not found" is counted once with the number of tests it skipped.
Usage: skipped_summary.py LOG [LOG...]  (ctest's <build>/Testing/Temporary/LastTest.log of each
ctest call; scripts/test.sh makes two: the fast tests two at a time, then the slow ones)
"""
import re
import sys
from collections import OrderedDict


def skipped_tests(text):
    """(name, reason) of every test whose block ends in "Test Skipped" or holds a gtest skip."""
    out = []
    for block in re.split(r"\n(?=\d+/\d+ Testing: )", text):
        m = re.match(r"\d+/\d+ Testing: (\S+)", block)
        if not m:
            continue
        gtest = re.search(r": Skipped\n(.*)", block)
        if gtest is None and "Test Skipped" not in block and "[  SKIPPED ]" not in block:
            continue
        reason = gtest.group(1).strip() if gtest else ""
        if not reason:
            body = block.split("Output:", 1)[-1].split("<end of output>", 1)[0].splitlines()
            lines = [l.strip() for l in body if l.strip() and not l.startswith(("-", "<", "["))]
            reason = lines[-1] if lines else "no reason printed"
        out.append((m.group(1), reason))
    return out


def main(paths):
    tests = []
    for path in paths:
        try:
            text = open(path, encoding="utf-8", errors="replace").read()
        except OSError as e:
            print(f"skipped tests: cannot read {path}: {e.strerror}")
            continue
        tests += skipped_tests(text)
    if not tests:
        print("skipped tests: none")
        return 0
    groups = OrderedDict()
    for name, reason in tests:
        groups.setdefault(reason, []).append(name)
    print(f"skipped tests: {len(tests)}")
    for reason, names in groups.items():
        shown = ", ".join(names[:4]) + (f", ... ({len(names) - 4} more)" if len(names) > 4 else "")
        print(f"  {len(names)} x {reason}: {shown}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1:]))
