#!/usr/bin/env bash
# `gilab slurm` on a real one-node Slurm cluster started on localhost (docs/cluster.md, "Tests"):
#   1. the sweep tests/slurm/sweep.json run on this machine: the expected results;
#   2. `gilab slurm --shards 4` on the cluster: the results equal the expected ones run for run,
#      each reference was rendered exactly once, the report was written;
#   3. a second submission into a fresh folder with `scancel` of one run task while it runs: the
#      sweep is incomplete; resubmitting completes it with nothing lost or duplicated;
#   4. the cluster is stopped and nothing of it keeps running.
# Needs Debian's slurm-wlm and munge (scripts/install_deps.sh); exits 77 (skipped) without them.
# Usage: slurm_test.sh BUILD_DIR
set -euo pipefail
build="$(cd "${1:?usage: slurm_test.sh BUILD_DIR}" && pwd)"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
for tool in slurmctld slurmd munged sbatch squeue scancel; do
    if ! command -v "$tool" > /dev/null && [ ! -x "/usr/sbin/$tool" ]; then
        echo "SKIP: $tool not installed (Debian packages slurm-wlm and munge)"
        exit 77
    fi
done
config="$here/sweep.json"
gilab="$build/gilab"
work="$(mktemp -d)"
cluster="$work/cluster"
cleanup() {
    bash "$here/local_cluster.sh" stop "$cluster" || true
    rm -rf "$work"
}
trap cleanup EXIT
fail() {
    echo "FAIL: $*" >&2
    for log in "$work"/*/slurm_sweep/slurm/logs/*.out; do
        [ -f "$log" ] && { echo "---- $log" >&2; tail -20 "$log" >&2; }
    done
    exit 1
}

# Submits the sweep into $1 and prints the three job ids "refs runs report"
submit() {
    "$gilab" slurm "$config" --shards 4 --cpus-per-task 1 --time 00:10:00 --out "$1" \
        --reference-cache "$work/cache" > "$work/submit.log" 2>&1 ||
        { cat "$work/submit.log" >&2; fail "gilab slurm failed"; }
    sed -n 's/^submitted: references job \([0-9]*\) .*runs job \([0-9]*\) .*report job \([0-9]*\)$/\1 \2 \3/p' \
        "$work/submit.log"
}
# Waits until none of the given jobs is queued or running (10 minutes at most)
wait_jobs() {
    local ids
    ids=$(echo "$*" | tr ' ' ',')
    for _ in $(seq 1 1200); do
        [ -z "$(squeue -h -j "$ids" 2> /dev/null)" ] && return 0
        sleep 0.5
    done
    squeue >&2 || true
    fail "jobs $ids did not finish within 10 minutes"
}
count_renders() {  # prints "key count" per cached reference, over all logs of $@
    for key in $(ls "$work/cache" | grep -v '^\.'); do
        echo "$key $(cat "$@" 2> /dev/null | grep -c "rendered reference $key" || true)"
    done
}

# 1. Expected results, on this machine
"$gilab" run "$config" --out "$work/single" --reference-cache "$work/cache-single" --quiet \
    > "$work/single.log" 2>&1 || { cat "$work/single.log"; fail "the single run failed"; }

# The cluster
start=$(date +%s)
bash "$here/local_cluster.sh" start "$cluster" > "$work/cluster.env" || fail "the cluster did not start"
eval "$(grep '^export SLURM_CONF=' "$work/cluster.env")"
echo "cluster up in $(($(date +%s) - start)) s ($SLURM_CONF)"

# 2. One submission
read -r refs runs report <<< "$(submit "$work/a")"
[ -n "$report" ] || fail "no job ids in: $(cat "$work/submit.log")"
wait_jobs "$refs" "$runs" "$report"
python3 "$here/compare_results.py" "$work/single/slurm_sweep" "$work/a/slurm_sweep" ||
    fail "the Slurm results differ from the single-machine run"
[ -f "$work/a/slurm_sweep/report.html" ] || fail "the report job wrote no report.html"
renders=$(count_renders "$work"/a/slurm_sweep/slurm/logs/*.out)
[ "$(echo "$renders" | wc -l)" -eq 2 ] || fail "expected 2 references, got: $renders"
echo "$renders" | awk '$2 != 1 { bad = 1 } END { exit bad }' ||
    fail "a reference was not rendered exactly once: $renders"
grep -l "reused reference" "$work"/a/slurm_sweep/slurm/logs/*runs*.out > /dev/null ||
    fail "no run task reused a reference"

# 3. Cancel one run task mid-run, then resubmit
rm -rf "$work/cache"  # the references are rendered again, once, in this submission
read -r refs runs report <<< "$(submit "$work/b")"
cancelled=""
for _ in $(seq 1 1200); do
    cancelled=$(squeue -h -t RUNNING -j "$runs" -o %i 2> /dev/null | head -1)
    [ -n "$cancelled" ] && break
    sleep 0.1
done
[ -n "$cancelled" ] || fail "no run task started"
scancel "$cancelled"
wait_jobs "$refs" "$runs" "$report"
task=${cancelled#*_}
log=$(ls "$work"/b/slurm_sweep/slurm/logs/*runs-"$runs"_"$task".out)
if grep -q "runs (.* in this shard)" "$log"; then
    echo "note: task $cancelled had finished before scancel reached it"
else
    ! python3 "$here/compare_results.py" "$work/single/slurm_sweep" "$work/b/slurm_sweep" \
        > /dev/null || fail "the sweep is complete although task $cancelled was cancelled"
fi
read -r refs runs report <<< "$(submit "$work/b")"
wait_jobs "$refs" "$runs" "$report"
python3 "$here/compare_results.py" "$work/single/slurm_sweep" "$work/b/slurm_sweep" ||
    fail "the resubmitted sweep differs from the single-machine run"
renders=$(count_renders "$work"/b/slurm_sweep/slurm/logs/*.out)
echo "$renders" | awk '$2 != 1 { bad = 1 } END { exit bad }' ||
    fail "over both submissions a reference was not rendered exactly once: $renders"

# 4. Stop; nothing of the cluster may be left
bash "$here/local_cluster.sh" stop "$cluster"
for pidfile in "$cluster"/*.pid; do
    [ -f "$pidfile" ] || continue
    pid=$(cat "$pidfile")
    ! kill -0 "$pid" 2> /dev/null || fail "process $pid ($pidfile) still runs after stop"
done
echo "PASS: gilab slurm on a one-node cluster: results equal, references once, scancel + resubmit"
