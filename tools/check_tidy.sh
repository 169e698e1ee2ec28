#!/usr/bin/env bash
# Runs clang-tidy (.clang-tidy) over the project's sources with the Release build's compile
# commands; any finding fails. Usage: ./tools/check_tidy.sh [--all]
#
# A file found clean is remembered (in ${XDG_CACHE_HOME:-~/.cache}/leglab/tidy) by a hash of
# everything its check reads: clang-tidy's version, .clang-tidy, the file's compile commands, and
# the file and every header it includes as the last build recorded them (ninja's deps). A run
# checks only the files whose hash it has not found clean before, which after a change is the
# changed files and those that include a changed header; a file the build has not compiled, and
# every file with --all, is checked whatever the cache holds. Needs a built build/
# (./scripts/test.sh makes one).
set -euo pipefail
cd "$(dirname "$0")/.."
[ -f build/compile_commands.json ] || ./scripts/setup.sh
cache="${XDG_CACHE_HOME:-$HOME/.cache}/leglab/tidy"
mkdir -p "$cache"
all=0
[ "${1:-}" = "--all" ] && all=1

# tests/install/consumer/ is another project's code, built against an installed leglab by the
# Install.Consumer test: this build has no compile command for it.
mapfile -t files < <(git ls-files '*.cc' ':!tests/install/consumer/')
# "<hash or -> <file>" per file: - where the build recorded no dependencies for it.
mapfile -t keyed < <(
  { clang-tidy --version; cat .clang-tidy; } | PYTHONPATH="$PWD/python" /usr/bin/python3 tools/tidy_keys.py build "${files[@]}")

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
todo=()
for line in "${keyed[@]}"; do
  key=${line%% *}
  if [ $all = 1 ] || [ "$key" = - ] || [ ! -e "$cache/$key" ]; then todo+=("$line"); fi
done

# One clang-tidy per file, so that each clean file can be remembered on its own.
check_one() {
  local key=$1 file=$2 out
  if out=$(clang-tidy -p build --quiet --warnings-as-errors='*' "$file" 2>/dev/null); then
    [ "$key" = - ] || : >"$cache/$key"
  else
    printf '%s\n' "$out" | grep -E "(warning|error):" >"$work/$(printf '%s' "$file" | tr / _)" || true
    echo "findings in $file" >>"$work/failed"
  fi
}
export -f check_one
export cache work
printf '%s\n' "${todo[@]+"${todo[@]}"}" | grep -v '^$' |
  xargs -r -P "$(nproc)" -L 1 bash -c 'check_one "$0" "$1"' || true
if [ -s "$work/failed" ]; then
  cat "$work"/* | grep -E "(warning|error):" | sort -u
  echo "tidy: findings above"
  exit 1
fi
echo "tidy: ${#files[@]} files clean (${#todo[@]} checked now, $((${#files[@]} - ${#todo[@]})) unchanged since found clean)"
