#!/usr/bin/env bash
# Set-up, build and the whole test suite (ctest), each stage's wall time printed and the ten
# slowest tests listed. Usage: ./scripts/test.sh [ctest args...]
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/stages.sh
trap stage_summary EXIT

release_tests() {
  ctest --preset release -j "$(nproc)" "$@" | tee build/ctest.log
  slowest_tests build/ctest.log
}

stage "set-up" ./scripts/setup.sh
stage "release: build" cmake --build --preset release
stage "release: tests" release_tests "$@"
