# Shared helpers of the command-line tests (sourced, not run). Each test sets $work (a temporary
# directory) before using them and ends with `finish NAME`.
#   check NAME EXPECTED_EXIT CMD...   runs CMD (stdout -> $work/out, stderr -> $work/err) and
#                                     checks its exit code
#   ok NAME CMD...                    passes if CMD succeeds
#   pycheck NAME PYTHON_SOURCE        runs the source with Debian's python (argv[1] = $work)
py=/usr/bin/python3
failures=0
passed=0
check() {
  local name="$1" expected="$2"
  shift 2
  "$@" >"$work/out" 2>"$work/err"
  local rc=$?
  if [ "$rc" -ne "$expected" ]; then
    echo "FAIL $name: exit $rc, expected $expected"
    sed 's/^/  stderr: /' "$work/err" | tail -8
    failures=$((failures + 1))
  else
    passed=$((passed + 1))
  fi
}
ok() {
  local name="$1"
  shift
  if "$@"; then passed=$((passed + 1)); else
    echo "FAIL $name"
    failures=$((failures + 1))
  fi
}
pycheck() {
  if "$py" -c "$2" "$work"; then passed=$((passed + 1)); else
    echo "FAIL $1"
    failures=$((failures + 1))
  fi
}
finish() {
  echo "$1: $passed passed, $failures failed"
  [ "$failures" -eq 0 ]
}
