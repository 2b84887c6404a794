#!/usr/bin/env bash
# Several `gilab run` processes on one results folder and one empty reference cache
# (docs/cluster.md, "Shared results folder"), without Slurm:
#   1. a single run of tests/slurm/sweep.json: the expected results;
#   2. three concurrent processes: all exit 0, each reference is rendered exactly once (one
#      "rendered reference KEY" log line per key), the results equal the single run, one table
#      row per run;
#   3. a process SIGKILLed mid-run leaves nothing that looks finished, and running again
#      completes exactly the missing runs and removes the dead process's temporary folder.
# Usage: concurrent_runs_test.sh BUILD_DIR
set -euo pipefail
build="$(cd "${1:?usage: concurrent_runs_test.sh BUILD_DIR}" && pwd)"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
config="$here/sweep.json"
gilab="$build/gilab"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# 1. Expected
"$gilab" run "$config" --out "$work/single" --reference-cache "$work/cache-single" --quiet \
    > "$work/single.log" 2>&1 || { cat "$work/single.log"; fail "the single run failed"; }

# 2. Three processes at once on an empty cache
pids=()
for i in 1 2 3; do
    "$gilab" run "$config" --out "$work/shared" --reference-cache "$work/cache" --quiet \
        > "$work/p$i.log" 2>&1 &
    pids+=($!)
done
for i in 1 2 3; do
    wait "${pids[$((i - 1))]}" || { cat "$work/p$i.log"; fail "process $i exited $?"; }
done
keys=$(ls "$work/cache" | grep -v '^\.' || true)
[ "$(echo "$keys" | wc -w)" -eq 2 ] || fail "expected 2 cached references, found: $keys"
for key in $keys; do
    n=$(cat "$work"/p*.log | grep -c "rendered reference $key" || true)
    [ "$n" -eq 1 ] || { cat "$work"/p*.log; fail "reference $key rendered $n times (want 1)"; }
done
python3 "$here/compare_results.py" "$work/single/slurm_sweep" "$work/shared/slurm_sweep" ||
    fail "three concurrent processes differ from the single run"

# 3. SIGKILL in the middle of a run, then run again
"$gilab" run "$config" --out "$work/killed" --reference-cache "$work/cache" --quiet \
    > "$work/killed.log" 2>&1 &
pid=$!
runs="$work/killed/slurm_sweep/runs"
for _ in $(seq 1 600); do
    ls -d "$runs"/.tmp-* > /dev/null 2>&1 && break
    sleep 0.05
done
kill -9 "$pid" 2> /dev/null || true
wait "$pid" 2> /dev/null || true
ls -d "$runs"/.tmp-* > /dev/null 2>&1 || fail "no run was in progress when the process was killed"
for dir in "$runs"/*/; do
    [ -d "$dir" ] || continue
    python3 - "$dir/result.json" <<'PY' || fail "$dir looks finished but is not"
import json, sys
status = json.load(open(sys.argv[1]))["status"]
sys.exit(0 if status in ("ok", "nonfinite", "unsupported") else 1)
PY
done
before=$(ls "$runs" | grep -vc '^\.' || true)
"$gilab" run "$config" --out "$work/killed" --reference-cache "$work/cache" --quiet \
    > "$work/resumed.log" 2>&1 || { cat "$work/resumed.log"; fail "the resumed run failed"; }
ran=$(sed -n 's/.* \([0-9]*\) ran (.*/\1/p' "$work/resumed.log")
[ "$ran" -eq $((8 - before)) ] || fail "resumed: ran $ran runs, want $((8 - before))"
! ls -d "$runs"/.tmp-* > /dev/null 2>&1 || fail "the killed process's temporary folder is left"
python3 "$here/compare_results.py" "$work/single/slurm_sweep" "$work/killed/slurm_sweep" ||
    fail "the killed and resumed folder differs from the single run"
echo "PASS: 3 concurrent processes, references rendered once, results equal; kill -9 + resume"
