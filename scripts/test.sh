#!/usr/bin/env bash
# README command 2: install, build, and run the whole test suite (ctest). .ci/run calls this.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh"
cd "$root/build"
# Lavapipe uses every core per draw; running tests one at a time is faster than in parallel here.
status=0
ctest --output-on-failure --timeout 900 || status=$?
# How many tests skipped and why (e.g. the real scenes of ../shared missing), in the summary.
python3 "$root/scripts/skipped_summary.py" Testing/Temporary/LastTest.log || true
exit "$status"
