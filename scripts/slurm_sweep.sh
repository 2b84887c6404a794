#!/usr/bin/env bash
# Runs one shard of an experiment as a Slurm job-array task, e.g.
#   sbatch --array=0-15 scripts/slurm_sweep.sh experiments/configs/default.json
# Each task writes results/<experiment>/runs/<key>/ folders; run keys make merging exact:
#   build/gilab report results/<experiment>          (shared filesystem), or copy runs/* together.
#SBATCH --job-name=gilab-sweep
#SBATCH --cpus-per-task=4
#SBATCH --time=04:00:00
set -euo pipefail
config="${1:?usage: slurm_sweep.sh CONFIG [extra gilab run options]}"
shift
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
index="${SLURM_ARRAY_TASK_ID:-0}"
count="${SLURM_ARRAY_TASK_COUNT:-1}"
exec "$root/build/gilab" run "$config" --shard "$index/$count" "$@"
