#!/usr/bin/env bash
# Configures (once) and builds gilab in Release into build/. Incremental on re-runs.
# Arguments go to `cmake --build` (scripts/main.sh: `--target gilab`, the tool without the tests).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${GILAB_BUILD_DIR:-$root/build}"
jobs="${GILAB_JOBS:-$(nproc)}"
if [ ! -f "$build/build.ninja" ]; then
    cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
fi
cmake --build "$build" -j "$jobs" "$@"
