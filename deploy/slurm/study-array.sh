#!/bin/bash
# A twin study sharded over a Slurm job array (docs/deployment.md, "Twin studies on a cluster"):
# array task K runs `synbench study run --shard K/N`, every task into one database. N, the shard
# count, is part of what is submitted, so a task re-run alone still runs its own shard:
#
#   export SYNBENCH_DB='postgresql://user:pw@db:5432/lab'   # or a SQLite file on a shared disk
#   sbatch --array=0-3 deploy/slurm/study-array.sh my-study.json 4
#
# A task that was cancelled, killed or timed out is re-run with the same arguments and its index,
#   sbatch --array=1 deploy/slurm/study-array.sh my-study.json 4
# and resumes its samples at their first missing point (docs/study.md). The array's indices are
# the shards themselves: any subset of 0..N-1 (--array=1,3 or --array=0-6:2 with N=8) runs those
# shards; an index outside 0..N-1 is refused.
#SBATCH --job-name=synbench-study
#SBATCH --cpus-per-task=1
#SBATCH --mem=512M
#SBATCH --time=04:00:00
#SBATCH --output=synbench-study-%A_%a.out
#SBATCH --export=ALL
set -euo pipefail

usage="usage: sbatch --array=0-<N-1> study-array.sh STUDY.json N"
plan="${1:?$usage}"
shards="${2:?$usage (N, the shard count, is required: the array's size is not the study's when one task is re-run)}"
shard="${SLURM_ARRAY_TASK_ID:?is unset: not in a Slurm job array ($usage)}"
db="${SYNBENCH_DB:?must name the study database: a postgresql URL or a file}"
synbench="${SYNBENCH:-synbench}"

if ! [[ "$shards" =~ ^[1-9][0-9]*$ ]]; then
  echo "study-array.sh: N (the shard count) must be a positive integer, not '$shards' ($usage)" >&2
  exit 2
fi
if ! [[ "$shard" =~ ^[0-9]+$ ]] || ((shard >= shards)); then
  echo "study-array.sh: array index $shard is not a shard of $shards: submit indices 0..$((shards - 1)) ($usage)" >&2
  exit 2
fi

exec "$synbench" study run "$plan" --shard "$shard/$shards" --db "$db" ${SYNBENCH_STUDY_FLAGS:-}
