#!/usr/bin/env bash
# `cmake --install` gives a binary that works away from the build and source trees: it runs,
# reports its version and finds the report code relative to itself (issue 10).
set -euo pipefail
build_dir="$1"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build_dir" --prefix "$tmp/prefix" >/dev/null
mkdir -p "$tmp/work/results/empty/runs"
cd "$tmp/work"
"$tmp/prefix/bin/gilab" --version | grep -q '^gilab '
# The report must come from the installed copy, not the source tree.
out="$(GILAB_REPORT_PACKAGE_DIR= "$tmp/prefix/bin/gilab" report results/empty 2>&1)" || {
    echo "$out"; exit 1; }
test -f results/empty/report.html
pkg="$tmp/prefix/share/gilab/gilab_report"
for f in __init__.py __main__.py make.py data.py exr.py findings.py templates/page.html.j2 \
         templates/header.html.j2 templates/verdict.html.j2 static/report.css static/head.js \
         static/body.js static/inspector.js; do
    test -f "$pkg/$f" || { echo "not installed: $pkg/$f"; exit 1; }
done
# The paper facts the report reads (issue 44), beside it.
test -f "$tmp/prefix/share/gilab/techniques/vct/paper.json"
echo "install ok: $tmp/prefix/bin/gilab"
