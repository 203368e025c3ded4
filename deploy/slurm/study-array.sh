#!/bin/bash
# A twin study sharded over a Slurm job array (docs/deployment.md, "Twin studies on a cluster"):
# array task K of N runs `synbench study run --shard K/N`, every task into one database.
#
#   export SYNBENCH_DB='postgresql://user:pw@db:5432/lab'   # or a SQLite file on a shared disk
#   sbatch --array=0-3 deploy/slurm/study-array.sh my-study.json
#
# N is the array's size (SLURM_ARRAY_TASK_COUNT); a task that was killed or timed out is re-run
# with `sbatch --array=K ...` and resumes its samples at their first missing point (docs/study.md).
#SBATCH --job-name=synbench-study
#SBATCH --cpus-per-task=1
#SBATCH --mem=512M
#SBATCH --time=04:00:00
#SBATCH --output=synbench-study-%A_%a.out
#SBATCH --export=ALL
set -euo pipefail

plan="${1:?usage: sbatch --array=0-3 study-array.sh STUDY.json}"
shard="${SLURM_ARRAY_TASK_ID:?is unset: not in a Slurm job array}"
shards="${SLURM_ARRAY_TASK_COUNT:?is unset: not in a Slurm job array}"
db="${SYNBENCH_DB:?must name the study database: a postgresql URL or a file}"
synbench="${SYNBENCH:-synbench}"

# Arrays may start at another index (--array=1-4): shards are numbered from SLURM_ARRAY_TASK_MIN.
shard=$((shard - ${SLURM_ARRAY_TASK_MIN:-0}))

exec "$synbench" study run "$plan" --shard "$shard/$shards" --db "$db" ${SYNBENCH_STUDY_FLAGS:-}
