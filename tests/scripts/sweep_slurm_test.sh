#!/usr/bin/env bash
# scripts/sweep_slurm.sh against a stand-in for sbatch that runs each job at once, in order:
# the array's tasks (with SLURM_ARRAY_TASK_ID set), then the merge. Checks that the merged
# sweep.csv is byte for byte the unsharded one, that a lost shard is named with the sbatch
# line that reruns it, and that docs/design/sweeps.md's GNU parallel line gives the same bytes.
# Usage: sweep_slurm_test.sh SOURCE_DIR SWEEP_BIN WORK_DIR
set -euo pipefail
source_dir=$1 sweep_bin=$2 work=$3
rm -rf "$work" && mkdir -p "$work/bin"
# The stand-in: --array=a-b or a list runs the script once per task; anything else once.
cat >"$work/bin/sbatch" <<'FAKE'
#!/usr/bin/env bash
set -euo pipefail
array="" args=()
for a in "$@"; do  # sbatch's options come before the script; keep --array, drop the rest
  if [ ${#args[@]} -eq 0 ] && [ "${a#--}" != "$a" ]; then
    case $a in --array=*) array=${a#--array=} ;; esac
  else
    args+=("$a")
  fi
done
if [ -n "$array" ]; then
  for part in ${array//,/ }; do
    for ((i = ${part%-*}; i <= ${part#*-}; i++)); do
      SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_COUNT=99 SLURM_SUBMIT_DIR=$PWD "${args[@]}"
    done
  done
else
  LEGLAB_SWEEP_MERGE=1 SLURM_SUBMIT_DIR=$PWD "${args[@]}"
fi
echo "$RANDOM"
FAKE
chmod +x "$work/bin/sbatch"
cat >"$work/sweep.yaml" <<YAML
base: $source_dir/experiments/configs/track.yaml
plant: model
model: {v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}
controller: {modes: [direct, time_shift, model_based]}
warmup_steps: 2
steps: 2
grid:
  track.t_step_ticks: [40, 56, 72, 88, 104]
YAML
cd "$source_dir"
mkdir -p "$work/build/bin" && ln -s "$sweep_bin" "$work/build/bin/sweep"
unset SLURM_ARRAY_TASK_ID SLURM_ARRAY_TASK_COUNT JOB_COMPLETION_INDEX LEGLAB_SWEEP_MERGE
"$sweep_bin" --quiet --config "$work/sweep.yaml" --out "$work/whole"
# The script runs from the leglab folder it was submitted in: here, one whose build/bin/sweep
# is the binary under test.
mkdir -p "$work/scripts" && cp scripts/sweep_slurm.sh "$work/scripts/"
(cd "$work" && PATH="$work/bin:$PATH" scripts/sweep_slurm.sh sweep.yaml sharded 3 --time=10)
cmp "$work/whole/sweep.csv" "$work/sharded/sweep.csv"
# A lost shard: the merge names it and prints the line that reruns only it.
rm "$work/sharded/sweep.shard-1-of-3.csv" "$work/sharded/sweep.csv"
if (cd "$work" && "$sweep_bin" merge sharded --out sharded --config sweep.yaml 2>merge.err); then
  echo "merge with a missing shard succeeded" >&2
  exit 1
fi
grep -q "sweep.shard-1-of-3.csv" "$work/merge.err"
rerun=$(grep -o "sbatch --array=1 scripts/sweep_slurm.sh sweep.yaml sharded 3" "$work/merge.err")
test -n "$rerun"
# Rerun exactly the printed line (from the leglab folder), then merge: the same bytes.
(cd "$work" && PATH="$work/bin:$PATH" $rerun)
(cd "$work" && "$sweep_bin" merge sharded --out sharded --config sweep.yaml 2>/dev/null)
cmp "$work/whole/sweep.csv" "$work/sharded/sweep.csv"
# docs/design/sweeps.md's GNU parallel line: four shards on this machine, then the merge.
(cd "$work" && parallel --will-cite build/bin/sweep --quiet --config sweep.yaml --out gnu \
  --shard {}/4 ::: 0 1 2 3 && build/bin/sweep merge gnu --out gnu 2>/dev/null)
cmp "$work/whole/sweep.csv" "$work/gnu/sweep.csv"
echo "sweep_slurm.sh and GNU parallel: shards, merge and rerun agree with the unsharded sweep"
