#!/usr/bin/env bash
# A technique in its own repository (issue 45; docs/tutorial.md, "Your technique in your own
# repository"): the tutorial's folder docs/tutorial/ambient/, copied away from the tree, builds
# against an installed gilab (find_package(gilab), gilab_add_technique), passes its own test,
# is listed with where it came from, runs in an experiment config beside `direct`, is found in
# the report, has its declared weaknesses shown as declared in the audit, and a module built
# against another gilab version is refused with a clear error.
set -euo pipefail
build_dir="$(cd "$1" && pwd)"
generator="${2:-Ninja}"
src="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cmake --install "$build_dir" --prefix "$tmp/prefix" >/dev/null
cp -r "$src/docs/tutorial/ambient" "$tmp/ambient"
# Where the tree already has `ambient` built in (docs/tutorial.md 5.4 done), the copy takes
# another id: two techniques of one id are refused.
id=ambient
GILAB_TECHNIQUE_PATH= "$tmp/prefix/bin/gilab" list >"$tmp/builtin.txt"
if grep -q '^ambient ' "$tmp/builtin.txt"; then
    id=ambient_oot
    sed -i "s|info.id = \"ambient\"|info.id = \"$id\"|; s|\"ambient/ambient.comp\"|\"$id/ambient.comp\"|" \
        "$tmp/ambient/ambient.cpp"
    sed -i "s|gilab_add_technique(ambient)|gilab_add_technique($id)|; s|gilab_technique_ambient|gilab_technique_$id|; s|-t ambient|-t $id|" \
        "$tmp/ambient/CMakeLists.txt"
    sed -i "s|\"technique\": \"ambient\"|\"technique\": \"$id\"|; s|\"name\": \"ambient_vs_direct\"|\"name\": \"${id}_vs_direct\"|" \
        "$tmp/ambient/configs/ambient_vs_direct.json"
fi
cmake -S "$tmp/ambient" -B "$tmp/ambient/build" -G "$generator" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
    >"$tmp/configure.log" 2>&1 || { cat "$tmp/configure.log"; fail "configure against the prefix"; }
cmake --build "$tmp/ambient/build" >"$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; fail "build"; }
module="$tmp/ambient/build/gilab-technique-$id.so"
test -f "$module" || fail "no $module"
# Its own test (a render under the validation layers).
(cd "$tmp/ambient/build" && ctest --output-on-failure >"$tmp/ctest.log" 2>&1) || {
    cat "$tmp/ctest.log"; fail "the module's own test"; }

gilab="$tmp/prefix/bin/gilab"
export GILAB_TECHNIQUE_PATH="$tmp/ambient/build"
"$gilab" list >"$tmp/list.txt"
grep -A1 "^$id " "$tmp/list.txt" | grep -q "from: $module" || {
    cat "$tmp/list.txt"; fail "gilab list does not show $id from $module"; }
grep -A1 '^direct ' "$tmp/list.txt" | grep -q 'from: built in' || fail "direct is not 'built in'"

# An experiment config beside direct, then the report.
mkdir -p "$tmp/work" && cd "$tmp/work"
"$gilab" run "$tmp/ambient/configs/ambient_vs_direct.json" -o results --quiet \
    --reference-cache "$tmp/cache" >"$tmp/run.log" 2>&1 || { cat "$tmp/run.log"; fail "gilab run"; }
grep -q '4 ran' "$tmp/run.log" || { cat "$tmp/run.log"; fail "expected 4 runs"; }
GILAB_REPORT_PACKAGE_DIR= "$gilab" report "results/${id}_vs_direct" >"$tmp/report.log" 2>&1 || {
    cat "$tmp/report.log"; fail "gilab report"; }
test "$(grep -o "\"technique\": *\"$id\"" "results/${id}_vs_direct/results.jsonl" | wc -l)" -eq 3 ||
    fail "results.jsonl does not hold the 3 $id runs"
grep -q "$id" "results/${id}_vs_direct/report.html" || fail "$id is not in the report"

# The audit shows its declared weaknesses as declared, not red (exit 0), and the rest as graded.
"$gilab" audit --quick --techniques "$id" --cases saturated_walls,thin_wall_window -o audit \
    --reference-cache "$tmp/cache" -q >"$tmp/audit.log" 2>&1 || {
    cat "$tmp/audit.log"; fail "audit exit code (a declared weakness must not be red)"; }
grep -q '1 declared, 0 red' "$tmp/audit.log" || { cat "$tmp/audit.log"; fail "audit counts"; }
grep -q '| saturated_walls | .* | declared ' audit/audit.md || { cat audit/audit.md; fail "audit table"; }

# `cmake --install` of the module into gilab's prefix puts it where gilab looks beside itself.
cmake --install "$tmp/ambient/build" --prefix "$tmp/prefix" >/dev/null
GILAB_TECHNIQUE_PATH= "$gilab" list >"$tmp/list2.txt"
grep -A1 "^$id " "$tmp/list2.txt" | grep -q "from: $tmp/prefix/.*gilab/techniques/gilab-technique-$id.so" || {
    cat "$tmp/list2.txt"; fail "the installed module is not found beside the binary"; }

# The long form of the CMake line must list every stage in shaders/: one left out is a configure
# error naming it, not a shader missing at run time.
mkdir -p "$tmp/long"
cp -r "$tmp/ambient/shaders" "$tmp/ambient/ambient.cpp" "$tmp/long/"
cp "$tmp/ambient/shaders/ambient.comp" "$tmp/long/shaders/unlisted.comp"
cat >"$tmp/long/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.25)
project(long LANGUAGES CXX)
find_package(gilab REQUIRED)
gilab_add_technique($id SOURCES ambient.cpp SHADERS shaders/ambient.comp)
CMAKE
if cmake -S "$tmp/long" -B "$tmp/long/build" -G "$generator" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
    >"$tmp/long.log" 2>&1; then
    fail "an unlisted shader did not stop the configure"
fi
grep -q "shaders/unlisted.comp is not in SHADERS" "$tmp/long.log" || {
    cat "$tmp/long.log"; fail "the configure error does not name the unlisted shader"; }

# A module built against another gilab version is refused, naming the file and both versions.
mkdir -p "$tmp/wrong"
# (its gilab_module_abi() says what the one built from another gilab's headers would say)
cat >"$tmp/wrong/wrong.cpp" <<'CPP'
extern "C" const char* gilab_module_abi() { return "gilab 0.0.0 (elsewhere)"; }
CPP
cat >"$tmp/wrong/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.25)
project(wrong LANGUAGES CXX)
find_package(gilab REQUIRED)
add_library(wrong MODULE wrong.cpp)
target_link_libraries(wrong PRIVATE gilab::core)
set_target_properties(wrong PROPERTIES PREFIX "" OUTPUT_NAME gilab-technique-wrong)
CMAKE
cmake -S "$tmp/wrong" -B "$tmp/wrong/build" -G "$generator" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
    >/dev/null 2>&1 && cmake --build "$tmp/wrong/build" >/dev/null 2>&1 || fail "build the wrong module"
set +e
out="$(GILAB_TECHNIQUE_PATH= "$gilab" --technique-dir "$tmp/wrong/build" list 2>&1)"
rc=$?
set -e
[ $rc -eq 1 ] || { echo "$out"; fail "a module of another version: exit $rc, expected 1"; }
echo "$out" | grep -q "gilab-technique-wrong.so: technique module built against gilab 0.0.0 (elsewhere), but this is gilab " ||
    { echo "$out"; fail "the refusal does not name the file and both versions"; }
echo "out of tree ok: $module"
