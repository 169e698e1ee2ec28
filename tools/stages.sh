# Stage timing for scripts/test.sh and .ci/run (sourced, not run).
#   stage NAME COMMAND...  runs COMMAND and prints its wall time;
#   stage_summary          prints every stage's time (set it as the EXIT trap, so that a failed
#                          run still shows where its time went);
#   slowest_tests LOG      prints the ten slowest tests of the ctest run whose output is LOG.
# A script run by another that sourced this file (test.sh under .ci/run) adds its stages to the
# caller's summary (LEGLAB_STAGE_LOG) instead of printing its own.
if [ -z "${LEGLAB_STAGE_LOG:-}" ]; then
  LEGLAB_STAGE_LOG=$(mktemp)
  export LEGLAB_STAGE_LOG
  leglab_stage_owner=1
else
  leglab_stage_owner=0
fi
leglab_stage_start=$SECONDS

stage() {
  local name=$1
  shift
  echo "== stage: $name"
  local start=$SECONDS
  "$@"
  local took=$((SECONDS - start))
  printf '%-40s %6d s\n' "$name" "$took" >>"$LEGLAB_STAGE_LOG"
  echo "== stage: $name took ${took} s"
}

stage_summary() {
  [ "$leglab_stage_owner" = 1 ] || return 0
  echo "== stage times (wall):"
  sed 's/^/   /' "$LEGLAB_STAGE_LOG"
  printf '   %-40s %6d s\n' "in all" "$((SECONDS - leglab_stage_start))"
  rm -f "$LEGLAB_STAGE_LOG"
}

slowest_tests() {
  echo "== the ten slowest tests of this run:"
  awk '/Test +#[0-9]+: / {
         for (i = NF; i > 4; --i) if ($i == "sec") { printf "   %8.2f s  %s\n", $(i - 1), $4; break }
       }' "$1" | sort -rn | awk 'NR <= 10'
}
