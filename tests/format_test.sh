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
bad=0
for f in "${files[@]}"; do
  if ! "$cf" --style=file --dry-run --Werror "$f" >/dev/null 2>&1; then
    echo "not formatted: $f"
    bad=$((bad + 1))
  fi
done
echo "format: ${#files[@]} files, $bad not formatted"
[ "$bad" -eq 0 ] && [ "${#files[@]}" -gt 0 ]
