#!/usr/bin/env bash
# Formats every C++ source with the repository's .clang-format; --check reports without writing.
# Takes the files git tracks and the new ones it does not ignore yet (a technique folder being
# added is formatted before its first `git add`).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
files=$(git ls-files --cached --others --exclude-standard '*.h' '*.cpp' | sort -u |
        while read -r f; do [ -f "$f" ] && echo "$f"; done)
if [ "${1:-}" = "--check" ]; then
    clang-format --dry-run --Werror $files
else
    clang-format -i $files
fi
