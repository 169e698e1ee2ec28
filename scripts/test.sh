#!/usr/bin/env bash
# Set-up, build and the whole test suite (ctest). Usage: ./scripts/test.sh [ctest args...]
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
cmake --build --preset release
ctest --preset release -j "$(nproc)" "$@"
