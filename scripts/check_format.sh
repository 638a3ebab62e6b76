#!/usr/bin/env bash
# Checks that every C++ source in the repository is formatted by its .clang-format (Debian's
# clang-format 14): prints the files that are not and exits 1. `bash scripts/check_format.sh --fix`
# formats them in place.
set -euo pipefail
cd "$(dirname "$0")/.."
format=$(command -v clang-format-14 || command -v clang-format || true)
[ -n "$format" ] || { echo "check_format: clang-format is not installed (scripts/install-deps.sh)" >&2; exit 1; }
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  # Tracked files and new ones not yet added (not ignored): a file written but not yet staged is
  # checked before it is committed, not first by CI. Only the source folders (the same as below):
  # a build directory outside build/ holds CMake's own generated sources.
  mapfile -t files < <(git ls-files --cached --others --exclude-standard '*.h' '*.cpp' |
    grep -E '^(apps|bench|fuzz|include|python|src|tests|shaders)/')
else
  mapfile -t files < <(find apps bench fuzz include python src tests shaders \( -name '*.h' -o -name '*.cpp' \) | sort)
fi
if [ "${1:-}" = "--fix" ]; then
  "$format" -i "${files[@]}"
  exit 0
fi
# One clang-format for every file (a process per file took 42 s of the test run, this about 3):
# each difference is reported as "<file>:<line>:<column>: error: code should be clang-formatted".
status=0
report=$("$format" --dry-run -Werror "${files[@]}" 2>&1 >/dev/null) || status=$?
mapfile -t bad < <(printf '%s\n' "$report" | sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: .*/\1/p' | sort -u)
if [ "$status" -ne 0 ] && [ ${#bad[@]} -eq 0 ]; then
  printf 'check_format: %s failed:\n%s\n' "$format" "$report" >&2
  exit 1
fi
if [ ${#bad[@]} -gt 0 ]; then
  printf 'not formatted (clang-format -i, or bash scripts/check_format.sh --fix):\n'; printf '  %s\n' "${bad[@]}"
  exit 1
fi
echo "format: ${#files[@]} files formatted"
