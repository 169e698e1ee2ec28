#!/usr/bin/env bash
# Fails when a function in the libraries (core/ model/ servo/ sim/ controller/ app/
# experiments/) or the Python bindings (python/src/) is longer
# than 120 lines or has a cyclomatic complexity over 30, as Debian's pmccabe measures them.
# pmccabe cannot parse C++17 nested namespace definitions (`namespace a::b {`) nor a
# `noexcept` after a function's parameters, and silently skips the rest of such a file: each
# file is measured with its namespaces spelt out one by one and without `noexcept`, and a file
# pmccabe still cannot parse fails the check.
set -euo pipefail
cd "$(dirname "$0")/.."
max_lines=120 max_complexity=30
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
status=0
while IFS= read -r file; do
  sed -E 's/^namespace ([a-z_]+)::([a-z_]+) \{/namespace \1 { namespace \2 {/;
          s/^\}  \/\/ namespace [a-z_]+::[a-z_]+$/} }/; s/\<noexcept\>//g' "$file" > "$scratch/unit.cc"
  # Columns: modified complexity, complexity, statements, first line, lines, name.
  while read -r _ complexity _ _ lines name; do
    if [ "$lines" -gt $max_lines ] || [ "$complexity" -gt $max_complexity ]; then
      echo "${name/$scratch\/unit.cc/$file}: $lines lines, complexity $complexity" >&2
      status=1
    fi
  done < <(pmccabe "$scratch/unit.cc" 2>"$scratch/errors")
  if [ -s "$scratch/errors" ]; then
    echo "$file: pmccabe cannot parse it: $(head -n 1 "$scratch/errors")" >&2
    status=1
  fi
done < <(find core model servo sim controller app experiments python/src -name '*.cc' | sort)
if [ $status -ne 0 ]; then
  echo "check_complexity: split the functions above (at most $max_lines lines, complexity" \
       "$max_complexity)" >&2
fi
exit $status
