#!/usr/bin/env bash
# Runs clang-tidy (.clang-tidy) over the project's sources with the Release build's compile
# commands; any finding fails. Needs a configured build/ (./scripts/setup.sh makes one).
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f build/compile_commands.json ] || ./scripts/setup.sh
# tests/install/consumer/ is another project's code, built against an installed leglab by the
# Install.Consumer test: this build has no compile command for it.
mapfile -t files < <(git ls-files '*.cc' ':!tests/install/consumer/')
out=$(printf '%s\n' "${files[@]}" |
  xargs -P "$(nproc)" -n 4 clang-tidy -p build --quiet --warnings-as-errors='*' 2>/dev/null) || {
  printf '%s\n' "$out" | grep -E "(warning|error):" | sort -u
  echo "tidy: findings above"
  exit 1
}
echo "tidy: ${#files[@]} files clean"
