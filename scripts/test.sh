#!/usr/bin/env bash
# README command 2: install, build, and run the whole test suite (ctest). .ci/run calls this.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh"
cd "$root/build"
status=0
# The fast tests (label `fast`, under 10 s each) two at a time: 1.55x faster than one at a time on
# the 2-core VM. The slow ones (the audit, the cluster and Chromium tests, ...) one at a time, as
# they were measured: lavapipe uses every core per draw and they start processes of their own.
ctest --output-on-failure --timeout 900 -L fast -j "${GILAB_TEST_JOBS:-2}" || status=$?
cp Testing/Temporary/LastTest.log Testing/Temporary/LastTest_fast.log 2>/dev/null || true
ctest --output-on-failure --timeout 900 -LE fast || status=$?
# How many tests skipped and why (e.g. the real scenes of ../shared missing), in the summary.
python3 "$root/scripts/skipped_summary.py" Testing/Temporary/LastTest_fast.log \
    Testing/Temporary/LastTest.log || true
exit "$status"
