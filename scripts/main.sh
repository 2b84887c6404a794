#!/usr/bin/env bash
# README command 1: install, build, and run the main job on the built-in default scene.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install_deps.sh"
"$root/scripts/build.sh"
cd "$root"
./build/gilab render --technique direct --out results/main
