#!/usr/bin/env bash
# scripts/skipped_summary.py on a ctest log with a GoogleTest skip, a script skip (exit 77) and a
# passed test: the summary counts two skips and names each reason (issue 43).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="$(python3 "$here/../../scripts/skipped_summary.py" "$here/last_test.log")"
echo "$out"
grep -qx "skipped tests: 2" <<<"$out"
grep -q "1 x shared scenes not found at /x/shared/scenes: CpuAnimationScenes.SponzaSunArc" <<<"$out"
grep -q "1 x slurm_test: slurmctld not installed; skipping: GpuCluster.SlurmArrayOnALocalCluster" <<<"$out"
if grep -q "CpuA.B" <<<"$out"; then echo "a passed test was listed as skipped"; exit 1; fi
