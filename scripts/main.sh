#!/usr/bin/env bash
# README command 1: install, build the tool (not the tests), run the default experiment (the
# built-in Cornell box and its spot-light variant at 128^2: all five techniques and direct against
# the path-traced reference) and write its report. Re-running skips finished runs and reuses the
# cached references.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh" --target gilab
cd "$root"
./build/gilab run experiments/configs/default.json
./build/gilab report results/default
echo "gilab: open results/default/report.html"
