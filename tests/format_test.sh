#!/usr/bin/env bash
# Fails when a tracked C++ file differs from what the project's .clang-format makes of it.
# Usage: format_test.sh SRC [CLANG_FORMAT]. Fix with: clang-format -i $(git ls-files '*.h' '*.cpp')
set -u
src="$1"; cf="${2:-clang-format}"
cd "$src" || exit 1
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files '*.h' '*.cpp')
else
  mapfile -t files < <(find apps benchmarks fuzz io render renderer tests -name '*.h' -o -name '*.cpp')
fi
# One clang-format process checks every file; each violation is reported as
# "FILE:LINE:COL: error: code should be clang-formatted".
report=$("$cf" --style=file --dry-run --Werror "${files[@]}" 2>&1)
status=$?
mapfile -t bad < <(printf '%s\n' "$report" | sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: .*clang-format.*/\1/p' | sort -u)
for f in "${bad[@]}"; do echo "not formatted: $f"; done
if [ "$status" -ne 0 ] && [ "${#bad[@]}" -eq 0 ]; then
  echo "clang-format failed:"; printf '%s\n' "$report" | head -5
fi
echo "format: ${#files[@]} files, ${#bad[@]} not formatted"
[ "$status" -eq 0 ] && [ "${#bad[@]}" -eq 0 ] && [ "${#files[@]}" -gt 0 ]
