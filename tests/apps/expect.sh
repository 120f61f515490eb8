# The shared check of the command-line test scripts, sourced by them: expect CODE PATTERN --
# command... runs the command with its output in $work/out and $work/err, and counts a pass when
# it exits with CODE and PATTERN (an extended regular expression) matches its output, else a
# failure (printed with the first lines of its error output). Needs $work, $fails and $passes.
# expect_refused (below) checks a file every command must refuse.
expect() {
  local code="$1" pattern="$2"; shift 3
  "$@" >"$work/out" 2>"$work/err"; local rc=$?
  if [ "$rc" -ne "$code" ] || ! grep -qE -- "$pattern" "$work/out" "$work/err"; then
    echo "FAIL: [$*] exit $rc (want $code), pattern '$pattern'"; sed 's/^/  | /' "$work/err" | head -5
    fails=$((fails + 1))
  else
    passes=$((passes + 1))
  fi
}

# expect_refused NAME PATTERN: $work/NAME.gltf must be refused with exit 2 by `render` (its message
# "penumbra: error: FILE: PATTERN", and no $work/NAME.exr or .png left behind) and by `info`.
# Needs $bin besides what expect() needs.
expect_refused() {
  local name="$1" pattern="$2"
  rm -f "$work/$name.exr" "$work/$name.png"
  expect 2 "penumbra: error: $work/$name.gltf: $pattern" -- "$bin" render "$work/$name.gltf" -o "$work/$name.exr" --width 32 --spp 1
  if [ -e "$work/$name.exr" ] || [ -e "$work/$name.png" ]; then
    echo "FAIL: $name: a refused render left $work/$name.exr"; fails=$((fails + 1))
  fi
  expect 2 "$pattern" -- "$bin" info "$work/$name.gltf"
}
