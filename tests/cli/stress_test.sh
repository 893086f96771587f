#!/usr/bin/env bash
# Readers beside a writer on one database: a campaign runs (committing each finished unit, one
# write transaction per unit) while 8 processes evaluate a law and list datasets and laws in a
# loop for SECONDS. Every reader call must succeed (no SQLITE_BUSY or "database is locked"
# failure) and return the right value: bvk2007 at phi 0.4, Re 100 is F = 30.7416 (6 significant
# figures, data/law_check_values.csv), the law list keeps the 15 literature laws. Then the
# campaign is stopped with SIGTERM (it must have committed units meanwhile) and the database
# must pass `db check`.
# Usage: stress_test.sh DRAGLAB SPEC SECONDS
set -u
draglab="$(realpath "$1")"
spec="$(realpath "$2")"
seconds="${3:-60}"
work="$(mktemp -d)"
trap 'kill $(jobs -p) 2>/dev/null; rm -rf "$work"' EXIT
db="$work/stress.db"
D=("$draglab" --db "$db" -q)

"${D[@]}" law list >/dev/null || { echo "FAIL: database creation"; exit 1; }
# The writer: a campaign (one thread per unit), started first so that readers meet its commits.
"${D[@]}" campaign run "$spec" --jobs 1 >"$work/campaign.out" 2>"$work/campaign.err" &
campaign_pid=$!

reader() {  # reader ID: loops until the deadline, counts calls and failures in $work/reader_ID
  local id="$1" deadline="$2" calls=0 failures=0 out
  while [ "$(date +%s)" -lt "$deadline" ]; do
    if ! out="$("${D[@]}" --json law eval bvk2007 --phi 0.4 --re 100 2>"$work/err_$id")"; then
      failures=$((failures + 1))
      echo "reader $id: law eval failed: $(tail -1 "$work/err_$id")"
    elif ! /usr/bin/python3 -c 'import json,sys; F=json.loads(sys.argv[1])["F"]; sys.exit(0 if abs(F-30.7416)/30.7416 < 2e-6 else 1)' "$out"; then
      failures=$((failures + 1))
      echo "reader $id: wrong F: $out"
    fi
    if ! out="$("${D[@]}" --json law list 2>"$work/err_$id")"; then
      failures=$((failures + 1))
      echo "reader $id: law list failed: $(tail -1 "$work/err_$id")"
    elif ! /usr/bin/python3 -c 'import json,sys; j=json.loads(sys.argv[1]); sys.exit(0 if len(j) >= 15 else 1)' "$out"; then
      failures=$((failures + 1))
      echo "reader $id: law list lost laws"
    fi
    if ! "${D[@]}" --json dataset list >/dev/null 2>"$work/err_$id"; then
      failures=$((failures + 1))
      echo "reader $id: dataset list failed: $(tail -1 "$work/err_$id")"
    fi
    if ! "${D[@]}" --json campaign status >/dev/null 2>"$work/err_$id"; then
      failures=$((failures + 1))
      echo "reader $id: campaign status failed: $(tail -1 "$work/err_$id")"
    fi
    calls=$((calls + 4))
  done
  echo "$calls $failures" >"$work/reader_$id"
}

deadline=$(($(date +%s) + seconds))
reader_pids=()
for id in 1 2 3 4 5 6 7 8; do
  reader "$id" "$deadline" &
  reader_pids+=($!)
done
wait "${reader_pids[@]}"  # the readers only: the campaign runs on

calls=0
failures=0
for id in 1 2 3 4 5 6 7 8; do
  read -r c f <"$work/reader_$id"
  calls=$((calls + c))
  failures=$((failures + f))
done
name="$(sed -n 's/^name = "\(.*\)"/\1/p' "$spec" | head -1)"
units_done="$("${D[@]}" --json campaign status "$name" 2>/dev/null |
  /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin).get("units_done", -1))' 2>/dev/null)"
echo "stress: $seconds s, 8 readers: $calls calls, $failures failed; campaign units committed meanwhile: ${units_done:-?}"

status=0
[ "$failures" -eq 0 ] || status=1
if kill -0 "$campaign_pid" 2>/dev/null; then
  kill -TERM "$campaign_pid"
  wait "$campaign_pid" 2>/dev/null
else
  wait "$campaign_pid"
  rc=$?
  [ "$rc" -eq 0 ] || { echo "FAIL: the campaign failed (exit $rc)"; tail -5 "$work/campaign.err"; status=1; }
fi
if ! "${D[@]}" db check >"$work/check.out" 2>&1; then
  echo "FAIL: db check after the stress run"
  cat "$work/check.out"
  status=1
fi
if [ "${units_done:-0}" -lt 1 ]; then
  echo "FAIL: no campaign unit was committed while the readers ran"
  status=1
fi
[ "$status" -eq 0 ] && echo "stress: passed"
exit "$status"
