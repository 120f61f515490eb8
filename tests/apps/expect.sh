# The shared check of the command-line test scripts, sourced by them: expect CODE PATTERN --
# command... runs the command with its output in $work/out and $work/err, and counts a pass when
# it exits with CODE and PATTERN (an extended regular expression) matches its output, else a
# failure (printed with the first lines of its error output). Needs $work, $fails and $passes.
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
