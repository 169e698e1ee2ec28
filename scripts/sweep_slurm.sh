#!/usr/bin/env bash
# A leglab sweep on a Slurm cluster: one array task per shard, then the merge.
#
# Submit from the login node, in the leglab folder (built: build/bin/sweep; SWEEP.yaml and
# OUT_DIR relative to it or absolute):
#   scripts/sweep_slurm.sh SWEEP.yaml OUT_DIR SHARDS [sbatch options...]
# It submits `sbatch --array=0-(SHARDS-1)` of this script (each task runs
# `sweep --shard $SLURM_ARRAY_TASK_ID/SHARDS --threads $SLURM_CPUS_PER_TASK` into OUT_DIR) and
# a merge job that starts when every task has succeeded and writes OUT_DIR/sweep.csv.
# If some tasks fail, the merge names the missing shards and prints the sbatch line that
# reruns only those (this script with --array=<missing>); then merge again:
#   build/bin/sweep merge OUT_DIR --out OUT_DIR --config SWEEP.yaml
#
#SBATCH --job-name=leglab-sweep
#SBATCH --cpus-per-task=2
#SBATCH --output=leglab-sweep-%A_%a.log
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 SWEEP.yaml OUT_DIR SHARDS [sbatch options...]" >&2
  exit 2
fi
sweep_file=$1 out=$2 shards=$3
shift 3
# Paths are relative to the leglab folder it is submitted from (under sbatch the script runs
# from a spool copy, so it cannot find leglab from its own path).
cd "${SLURM_SUBMIT_DIR:-.}"
bin=build/bin/sweep

if [ -n "${SLURM_ARRAY_TASK_ID:-}" ]; then  # one shard
  exec "$bin" --config "$sweep_file" --out "$out" --shard "$SLURM_ARRAY_TASK_ID/$shards" \
    --threads "${SLURM_CPUS_PER_TASK:-1}" --quiet
fi
if [ -n "${LEGLAB_SWEEP_MERGE:-}" ]; then  # the merge, after every shard
  exec "$bin" merge "$out" --out "$out" --config "$sweep_file"
fi

# On the login node: submit the array, then the merge that waits for it.
[ -x "$bin" ] || { echo "$0: no $bin: build leglab first (cmake --build --preset release)" >&2; exit 2; }
[ -x scripts/sweep_slurm.sh ] || { echo "$0: run it from the leglab folder" >&2; exit 2; }
array=$(sbatch --parsable --array="0-$((shards - 1))" "$@" scripts/sweep_slurm.sh "$sweep_file" \
  "$out" "$shards")
array=${array%%;*}
merge=$(sbatch --parsable --dependency="afterok:$array" --cpus-per-task=1 \
  --export=ALL,LEGLAB_SWEEP_MERGE=1 "$@" scripts/sweep_slurm.sh "$sweep_file" "$out" "$shards")
echo "submitted shards as job $array (array 0-$((shards - 1))), the merge as job ${merge%%;*}"
