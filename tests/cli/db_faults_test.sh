#!/usr/bin/env bash
# Database faults (issue: hardening round 3, faults). An LD_PRELOAD shim (tests/support/
# wal_faults.c) acts on writes to SQLite's write-ahead log, where every change is written first:
#  - a full disk (ENOSPC from the first write, or after N of them) during a law publish, a
#    campaign's commits and a bed model's result store: exit 1 naming the cause, `db check`
#    clean, nothing of the failed change stored, and the same command without the fault completes
#    (the campaign resumes to all its units);
#  - SIGKILL of `scene run` in the middle of storing its result (the shim stalls the first log
#    write), then the same command again: exactly one result stored (its id is 1), `db check`
#    clean.
# Usage: db_faults_test.sh DRAGLAB SHIM_SO CAMPAIGN_SPEC SCENE QUICK_CSV
set -u
draglab="$(realpath "$1")"
shim="$(realpath "$2")"
spec="$(realpath "$3")"
scene="$(realpath "$4")"
csv="$(realpath "$5")"
work="$(mktemp -d)"
trap '[ -n "${KEEP:-}" ] || rm -rf "$work"' EXIT
cd "$work" || exit 1
fail=0
check() {  # check DESCRIPTION COMMAND...
  if "${@:2}"; then echo "ok: $1"; else echo "FAIL: $1"; fail=1; fi
}
D() { "$draglab" --db "$db" "$@"; }
faulty() {  # faulty KIND WRITES COMMAND...: the command with the shim
  LD_PRELOAD="$shim" DRAGLAB_TEST_WAL_FAULT="$1" DRAGLAB_TEST_WAL_WRITES="$2" \
    DRAGLAB_TEST_WAL_STALLED="$work/stalled" "${@:3}"
}
db_clean() { D db check 2>&1 | grep -q "problems *: 0"; }
names_full_disk() { grep -q "disk is full.*free space and run again.*nothing of it is stored" "$1"; }

# A database with a draft law (a fit of the shipped quick dataset).
db="$work/base.db"
D dataset import "$csv" >/dev/null 2>&1 || { echo "FAIL: import"; exit 1; }
id="$(D dataset list 2>/dev/null | grep -o '[0-9a-f]\{12\}' | head -1)"
D fit --dataset "$id" --publish faultfit >/dev/null 2>&1 || { echo "FAIL: fit"; exit 1; }

# 1. law publish on a full disk.
cp base.db publish.db; db="$work/publish.db"
faulty full 0 "$draglab" --db "$db" law publish faultfit@1 >p.out 2>p.err
code=$?
check "publish, full disk: exit 1 (got $code)" test "$code" = 1
check "publish, full disk: the cause named" names_full_disk p.err
check "publish, full disk: db check clean" db_clean
check "publish, full disk: the law is still a draft" \
  bash -c "'$draglab' --db '$db' law list 2>/dev/null | grep -q 'faultfit .* draft'"
check "publish without the fault: published" D law publish faultfit@1

# 2. campaign commits on a full disk (after 40 log writes: the campaign and some units stored).
cp base.db campaign.db; db="$work/campaign.db"
faulty full 40 "$draglab" --db "$db" campaign run "$spec" >c.out 2>c.err
code=$?
check "campaign, full disk: exit 1 (got $code)" test "$code" = 1
check "campaign, full disk: the cause named" names_full_disk c.err
check "campaign, full disk: db check clean" db_clean
done_units="$(D campaign status 2>/dev/null | awk '$2 == "tiny" {print $4}')"
check "campaign, full disk: not every unit stored (done: $done_units)" test "${done_units:-9}" -lt 9
D campaign run "$spec" --resume >r.out 2>r.err
check "campaign resumed without the fault: exit 0" test $? = 0
check "campaign resumed: 9 of 9 units, no duplicate" \
  bash -c "'$draglab' --db '$db' campaign status 2>/dev/null | awk '\$2 == \"tiny\" && \$3 == 9 && \$4 == 9 && \$5 == 0 {ok=1} END {exit !ok}'"
check "campaign resumed: db check clean" db_clean

# 3. a bed model's result store on a full disk.
cp base.db scene.db; db="$work/scene.db"
faulty full 0 "$draglab" --db "$db" scene run "$scene" >s.out 2>s.err
code=$?
check "scene store, full disk: exit 1 (got $code)" test "$code" = 1
check "scene store, full disk: the cause named" names_full_disk s.err
check "scene store, full disk: db check clean" db_clean
D scene run "$scene" >s2.out 2>s2.err
check "scene rerun without the fault: stored as result 1" grep -q "stored as consumer result 1$" s2.out

# 4. SIGKILL in the middle of the result store, then the same command again.
cp base.db killed.db; db="$work/killed.db"
rm -f "$work/stalled"
LD_PRELOAD="$shim" DRAGLAB_TEST_WAL_FAULT=stall DRAGLAB_TEST_WAL_STALLED="$work/stalled" \
  "$draglab" --db "$db" scene run "$scene" >k.out 2>k.err &
pid=$!  # draglab itself, not a subshell
for _ in $(seq 1 600); do [ -e "$work/stalled" ] && break; sleep 0.1; done
check "kill: the store was reached" test -e "$work/stalled"
kill -KILL "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
check "kill: db check clean" db_clean
D scene run "$scene" >k2.out 2>k2.err
check "kill, then the same command: one result stored (id 1)" \
  grep -q "stored as consumer result 1$" k2.out
check "kill, then rerun: db check clean" db_clean
exit $fail
