#!/usr/bin/env bash
# Every file in the corpus's invalid/ folder through `penumbra render`, each under a time and
# memory limit. Asserts per file: no signal, no timeout, exit 0 or 2; on 2 a message on stderr
# and no output file (EXR or PNG) left behind.
# Usage: hostile_test.sh PENUMBRA_BINARY WORK_DIR   (corpus from $PENUMBRA_CORPUS or
# $PENUMBRA_CORPUS_DEFAULT). Under sanitizers (PENUMBRA_SANITIZED=1) the address-space limit
# is left out (ASan reserves terabytes of virtual memory); --max-memory still applies.
set -u
bin="$1"
work="$2"
corpus="${PENUMBRA_CORPUS:-${PENUMBRA_CORPUS_DEFAULT:-}}"
if [ -z "$corpus" ] || [ ! -d "$corpus/invalid" ]; then
  echo "PENUMBRA_SKIP_ALL: corpus not found (set PENUMBRA_CORPUS)"
  exit 0
fi
time_limit="${HOSTILE_TIME_LIMIT:-60}"
vmem_kib="${HOSTILE_VMEM_KIB:-4194304}"   # 4 GiB of address space per render
rm -rf "$work"
mkdir -p "$work"
fails=0
count=0
while IFS= read -r -d '' f; do
  count=$((count + 1))
  out="$work/out.exr"
  rm -f "$work"/out.* "$work/stderr"
  if [ "${PENUMBRA_SANITIZED:-0}" = 1 ]; then
    timeout -s KILL "$time_limit" "$bin" render "$f" -o "$out" --width 48 --height 32 --spp 1 --max-memory 1G \
      >/dev/null 2>"$work/stderr"
  else
    ( ulimit -v "$vmem_kib"; exec timeout -s KILL "$time_limit" "$bin" render "$f" -o "$out" --width 48 --height 32 \
      --spp 1 --max-memory 1G ) >/dev/null 2>"$work/stderr"
  fi
  code=$?
  why=""
  if [ "$code" -ne 0 ] && [ "$code" -ne 2 ]; then
    why="exit $code (signal, timeout or internal error)"
  elif [ "$code" -eq 2 ] && [ ! -s "$work/stderr" ]; then
    why="exit 2 without a message"
  elif [ "$code" -eq 2 ] && compgen -G "$work/out.*" >/dev/null; then
    why="exit 2 but an output file was written"
  elif grep -q "ERROR: AddressSanitizer\|runtime error:" "$work/stderr"; then
    why="sanitizer report"
  fi
  if [ -n "$why" ]; then
    fails=$((fails + 1))
    echo "FAIL: $f: $why"
    head -5 "$work/stderr"
  fi
done < <(find "$corpus/invalid" -type f \( -name '*.gltf' -o -name '*.glb' \) -print0 | sort -z)
echo "hostile input: $count files, $fails failures"
[ "$count" -gt 0 ] && [ "$fails" -eq 0 ]
