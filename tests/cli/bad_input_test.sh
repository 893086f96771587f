#!/usr/bin/env bash
# The bad-input matrix: every case of tests/cli/bad_input_matrix.txt runs the draglab command line
# against a seeded database and fixtures in a temporary directory, and must
#   - exit with the code the case gives (2 bad input, 1 run-time failure),
#   - print a message on stderr that matches the case's pattern (it names the field or file),
#   - leave the database's content unchanged (its SQL dump) and write no file outside the inputs.
# Matrix lines, fields separated by ' | ': SURFACE | EXIT | ERE PATTERN (case-insensitive, on stderr) | COMMAND (bash, run in
# $work with $D = draglab on the fixture database, $DL = draglab alone, $in = inputs, $o = an
# output folder). Fixture writers usable in a command (each prints the written path):
#   csv_with ROW COL=VALUE...        the fixture dataset CSV with fields of data row ROW changed
#   csv_lines TEXT                   a CSV file with exactly TEXT (printf escapes)
#   toml_with SRC TABLE.KEY=VALUE... a copy of TOML file SRC with keys replaced (VALUE '-' drops
#                                    the key, TABLE.+KEY=VALUE adds one; tests/support/toml_edit.sh)
# Usage: bad_input_test.sh DRAGLAB MATRIX DATA_DIR
set -u
draglab="$(realpath "$1")"
matrix="$(realpath "$2")"
data="$(realpath "$3")"
. "$(dirname "$0")/../support/toml_edit.sh"
work="$(mktemp -d)"
trap 'chmod -R u+w "$work" 2>/dev/null; rm -rf "$work"' EXIT
cd "$work" || exit 1
in="$work/in"
o="$work/o"
mkdir -p "$in" "$o"
export DRAGLAB_DB="$work/default.db"
DB="$work/fixture.db"
DL="$draglab"
D="$draglab --db $DB"

# --- fixtures ---------------------------------------------------------------------------------
grep -v '^#' "$data/datasets/quick/quick.csv" >"$in/good.csv"
cp "$data/campaigns/quick.toml" "$in/spec.toml"
# The quick spec's extension, where its relative path points from $in.
mkdir -p "$work/datasets/standard"
cp "$data/datasets/standard/standard.csv" "$work/datasets/standard/standard.csv"
cp "$data/scenes/dpm_bubble_quick.toml" "$in/dpm.toml"
cp "$data/scenes/dbm_tiny.toml" "$in/dbm.toml"
cp "$data/scenes/dpm_tiny.toml" "$in/dpm_tiny.toml"
cp "$data/scenes/tfm_bubble.toml" "$in/tfm.toml"
# A committed part of the standard dataset: its spec, another part's spec and its units.
cp "$data/campaigns/standard/standard_re100.toml" "$in/part.toml"
cp "$data/campaigns/standard/standard_low.toml" "$in/part_low.toml"
cp "$data/datasets/standard/standard_re100.csv" "$in/part_units.csv"
# A damaged packing that crashes libhdf5 itself (fuzz/regressions/README.md).
cp "$data/../fuzz/regressions/libhdf5_global_heap_read.h5" "$in/crashes_libhdf5.h5"
$D dataset import "$in/good.csv" >/dev/null 2>&1 || { echo "fixture: import failed"; exit 1; }
$D pack --phi 0.2 --n 8 --seed 3 --out "$in/p.h5" >/dev/null 2>&1 || { echo "fixture: pack"; exit 1; }
$D fit --data "$in/good.csv" --form wen_yu --cv 0 --no-global --publish draft_law >/dev/null 2>&1 ||
  { echo "fixture: fit --publish failed"; exit 1; }
# A dataset larger than the -shm file SQLite needs (32 kB), for the disk-full cases.
awk 'BEGIN { print "phi,re,F,F_uncertainty"; for (i = 0; i < 1200; ++i)
             printf "%.4f,%d,%.6f,0.1\n", 0.05 + 0.0005 * (i % 1000), int(i / 1000), 2 + i / 100 }' \
  >"$in/big.csv"
$D dataset import "$in/big.csv" >/dev/null 2>&1 || { echo "fixture: big import failed"; exit 1; }
printf 'not an hdf5 file\n' >"$in/text.h5"
head -c 3000 "$in/p.h5" >"$in/truncated.h5"
printf 'hello\n' >"$in/notdb.db"
: >"$in/empty.csv"
: >"$in/empty.toml"
mkdir -p "$in/adir"
dataset_id="$($D --json dataset list | /usr/bin/python3 -c 'import json,sys; print([d["id"] for d in json.load(sys.stdin) if d["name"] == "good"][0])')"
big_dataset_id="$($D --json dataset list | /usr/bin/python3 -c 'import json,sys; print([d["id"] for d in json.load(sys.stdin) if d["name"] == "big"][0])')"

csv_with() {  # csv_with ROW COL=VALUE...
  local row="$1"
  shift
  local out
  out="$(mktemp "$in/case_XXXXXX.csv")"
  awk -F, -v OFS=, -v row="$row" -v edits="$*" '
    NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; n = split(edits, e, " ");
              for (k = 1; k <= n; ++k) { eq = index(e[k], "="); name[k] = substr(e[k], 1, eq - 1);
                                         value[k] = substr(e[k], eq + 1) } print; next }
    NR - 1 == row { for (k = 1; k <= n; ++k) $(col[name[k]]) = value[k] }
    { print }' "$in/good.csv" >"$out"
  echo "$out"
}
csv_lines() {
  local out
  out="$(mktemp "$in/case_XXXXXX.csv")"
  printf "$1" >"$out"
  echo "$out"
}
toml_with() {  # toml_with SRC TABLE.KEY=VALUE...: the edits of tests/support/toml_edit.sh
  local out
  out="$(mktemp "$in/case_XXXXXX.toml")"
  # An edit that finds nothing names a file that is not there: the case then fails on its
  # pattern instead of passing on the unedited fixture.
  toml_edit "$@" >"$out" || out="$in/toml_edit_failed.toml"
  echo "$out"
}

export D DL DB in o dataset_id big_dataset_id
export -f csv_with csv_lines toml_edit toml_with

# The state a failed command must not change: the fixture database's content and the files
# outside the inputs (SQLite's own side files excepted).
state() {
  {
    sqlite3 "$DB" .dump 2>&1
    find "$work" -path "$in" -prune -o -type f -print | grep -v -e '-wal$' -e '-shm$' -e '-journal$' \
      -e "^$work/out$" -e "^$work/err$" | sort
  } | sha256sum
}

failures=0
passed=0
declare -A per_surface
line_no=0
while IFS= read -r line; do
  line_no=$((line_no + 1))
  case "$line" in '' | '#'*) continue ;; esac
  # Fields are separated by ' | ' (a pattern's own alternatives have no spaces around '|').
  surface="${line%% | *}"
  rest="${line#* | }"
  expected="${rest%% | *}"
  rest="${rest#* | }"
  pattern="${rest%% | *}"
  command="${rest#* | }"
  before="$(state)"
  # A bad input must be refused before any work: a case that runs longer has been accepted.
  timeout 30 bash -c "$command" >"$work/out" 2>"$work/err" </dev/null
  rc=$?
  after="$(state)"
  problem=""
  [ "$rc" -eq "$expected" ] || problem="exit $rc, expected $expected"
  grep -Eqi -- "$pattern" "$work/err" || problem="${problem:+$problem; }stderr does not match /$pattern/"
  [ "$before" = "$after" ] || problem="${problem:+$problem; }the database or the output files changed"
  if [ -n "$problem" ]; then
    echo "FAIL line $line_no [$surface] $command: $problem"
    sed 's/^/  stderr: /' "$work/err" | tail -4
    failures=$((failures + 1))
  else
    passed=$((passed + 1))
  fi
  per_surface[$surface]=$((${per_surface[$surface]:-0} + 1))
done <"$matrix"

for s in $(printf '%s\n' "${!per_surface[@]}" | sort); do echo "  $s: ${per_surface[$s]} cases"; done
echo "bad-input matrix: $passed passed, $failures failed"
[ "$failures" -eq 0 ] && [ "$passed" -ge 150 ]
