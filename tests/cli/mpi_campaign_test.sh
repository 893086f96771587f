#!/usr/bin/env bash
# Campaigns across MPI ranks (mpirun on loopback, oversubscribed), against the single-process
# runner as the reference:
#   1. the same campaign on 1 process and on 3 ranks (rank 0 + 2 workers), one thread per unit
#      in both, gives the same dataset id (the same F for every unit, bit for bit);
#   2. a worker rank killed (SIGKILL) while it runs a unit, under `mpirun --enable-recovery`:
#      rank 0 presumes it dead after --worker-timeout, hands its unit to the other worker, and
#      the campaign completes with the reference dataset id, each unit once, `db check` clean;
#   3. the whole job killed (SIGKILL to mpirun and every rank) with units in flight, then
#      `--resume` on 3 ranks: complete, the reference dataset id, no duplicate, `db check` clean;
#   4. bad input: another command under several ranks, and a spec rank 0 cannot read: exit 2 on
#      every rank with a message, no rank left waiting, nothing written;
#   5. units on several ranks ([lbm] ranks_per_unit = 2) on 5 ranks (two groups of 2): every
#      unit's F equals the reference to 1e-10 relative (the decomposed box sums in another
#      order: round-off, see mpi_lbm_test.sh); ranks_per_unit larger than the job (on 3 ranks
#      and in one process) or not dividing its worker ranks (on 4): exit 2, named once, nothing
#      written.
# Usage: mpi_campaign_test.sh DRAGLAB SPEC MPIRUN
set -u
draglab="$(realpath "$1")"
spec_src="$(realpath "$2")"
mpirun="$3"
work="$(mktemp -d)"
pids_of() {  # pids_of TEXT: processes whose command line contains TEXT (no procps needed)
  local f p
  for f in /proc/[0-9]*/cmdline; do
    p="${f#/proc/}"
    p="${p%/cmdline}"
    [ "$p" = "$$" ] && continue
    tr '\0' ' ' <"$f" 2>/dev/null | grep -qF -- "$1" && echo "$p"
  done
}
pids_to_kill=()
cleanup() {
  for p in "${pids_to_kill[@]}"; do kill -9 -- "-$p" 2>/dev/null; done
  # mpirun's ranks have process groups of their own: whatever still names this test's folder.
  kill -9 $(pids_of "$work/") 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
cd "$work" || exit 1
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1  # CI machines run as root
export OMPI_MCA_rmaps_base_oversubscribe=1
# Containers often forbid the cross-process memory attach of Open MPI's single-copy transport.
export OMPI_MCA_btl_vader_single_copy_mechanism=none
# Every mpirun has a time limit: a rank left waiting fails the test instead of hanging it.
run_mpi() { timeout -s KILL 300 "$mpirun" "$@"; }
fail=0
check() {  # check DESCRIPTION COMMAND...
  if "${@:2}"; then echo "ok: $1"; else echo "FAIL: $1"; fail=1; fi
}
dataset_id() {  # dataset_id OUTPUT_FILE: the id printed by campaign run
  sed -n 's/^dataset *\([0-9a-f]*\) .*/\1/p' "$1" | head -1
}
units() {  # units DB STATUS
  sqlite3 "$1" "SELECT count(*) FROM campaign_units WHERE status = '$2'"
}
# Units of a few seconds on one thread, so that a kill lands inside one.
sed 's/^resolutions = .*/resolutions = [12]/' "$spec_src" >spec.toml

# --- 1. one process and three ranks ------------------------------------------------------------
"$draglab" --db one.db campaign run spec.toml --jobs 1 --threads-per-unit 1 >one.out 2>one.err ||
  { echo "FAIL: the single-process reference run"; cat one.err; exit 1; }
ref="$(dataset_id one.out)"
[ -n "$ref" ] || { echo "FAIL: no dataset id from the reference run"; cat one.out; exit 1; }
units_total="$(sqlite3 one.db 'SELECT count(*) FROM campaign_units')"
run_mpi -np 3 "$draglab" --db "$work/three.db" campaign run spec.toml --threads-per-unit 1 \
  >three.out 2>three.err
rc=$?
check "3 ranks: exit 0 (got $rc)" test "$rc" -eq 0
check "3 ranks: the reference dataset id $ref (got $(dataset_id three.out))" \
  test "$(dataset_id three.out)" = "$ref"
check "3 ranks: the two worker ranks are reported, with every unit between them" \
  test "$(awk '/^rank [12] / {n++; u += $4} END {print n "/" u}' three.out)" = "2/$units_total"
check "3 ranks: the session reports the parallel efficiency" grep -q "parallel efficiency" three.out

# --- 2. a worker killed mid-unit ---------------------------------------------------------------
setsid timeout -s KILL 300 "$mpirun" --enable-recovery -np 3 \
  "$draglab" --db "$work/kill.db" campaign run spec.toml \
  --threads-per-unit 1 --worker-timeout 5 >kill.out 2>kill.err &
job=$!
pids_to_kill+=("$job")
victim=""
# Polled while the job lives (it is killed at 300 s): on a loaded machine the ranks may take
# long to start, so no fixed wait shorter than the job's own limit.
for _ in $(seq 1 3000); do
  kill -0 "$job" 2>/dev/null || break
  # rank 2 holding a unit: its token ends in rank2
  running=$(sqlite3 "$work/kill.db" "SELECT count(*) FROM campaign_units WHERE status = 'running' AND \
claimed_by LIKE '%:rank2'" 2>/dev/null || echo 0)
  if [ "${running:-0}" -ge 1 ]; then
    for p in $(pids_of "draglab --db $work/kill.db"); do
      if tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx 'OMPI_COMM_WORLD_RANK=2'; then
        victim=$p
      fi
    done
    [ -n "$victim" ] && break
  fi
  sleep 0.1
done
check "a unit of rank 2 was caught running" test -n "$victim"
[ -n "$victim" ] && kill -9 "$victim"
wait "$job"
rc=$?
check "worker killed: the job ends with exit 0 (got $rc)" test "$rc" -eq 0
check "worker killed: every unit done" test "$(units "$work/kill.db" done)" -eq "$units_total"
check "worker killed: the dead rank is reported" grep -q "rank 2 silent .* presumed dead" kill.out
check "worker killed: the reference dataset id" test "$(dataset_id kill.out)" = "$ref"
check "worker killed: db check clean" "$draglab" --db "$work/kill.db" db check
if [ "$rc" -ne 0 ]; then tail -5 kill.err; fi

# --- 3. the whole job killed, then resumed -------------------------------------------------------
setsid timeout -s KILL 300 "$mpirun" -np 3 \
  "$draglab" --db "$work/whole.db" campaign run spec.toml --threads-per-unit 1 \
  >whole1.out 2>whole1.err &
job=$!
pids_to_kill+=("$job")
caught=0
job_pids=""
for _ in $(seq 1 600); do
  done_now=$(units "$work/whole.db" done 2>/dev/null || echo 0)
  running=$(units "$work/whole.db" running 2>/dev/null || echo 0)
  # The job's processes, found once its ranks work (scanning /proc takes a while on a loaded
  # machine: done at the moment of the kill, it let the units in flight finish first).
  if [ -z "$job_pids" ] && [ "${running:-0}" -ge 1 ]; then
    job_pids="$(pids_of "draglab --db $work/whole.db")"
  fi
  if [ -n "$job_pids" ] && [ "${done_now:-0}" -ge 1 ] && [ "${running:-0}" -ge 1 ]; then
    caught=1
    break
  fi
  sleep 0.1
done
check "the whole job was caught with units done and in flight" test "$caught" -eq 1
# mpirun puts each rank in a process group of its own: every process of the job is killed by
# name, at once, as a batch system ends a job (mpirun's command line names the database too).
kill -9 $job_pids 2>/dev/null
kill -9 $(pids_of "draglab --db $work/whole.db") 2>/dev/null
wait "$job" 2>/dev/null
for _ in $(seq 1 50); do
  [ -z "$(pids_of "draglab --db $work/whole.db")" ] && break
  sleep 0.1
done
check "the whole job is gone" test -z "$(pids_of "draglab --db $work/whole.db")"
check "units were left running by the kill" test "$(units "$work/whole.db" running)" -ge 1
run_mpi -np 3 "$draglab" --db "$work/whole.db" campaign run spec.toml --threads-per-unit 1 --resume \
  >whole2.out 2>whole2.err
rc=$?
check "resume on 3 ranks: exit 0 (got $rc)" test "$rc" -eq 0
check "resume: every unit done" test "$(units "$work/whole.db" done)" -eq "$units_total"
check "resume: no duplicate unit" test "$(sqlite3 "$work/whole.db" 'SELECT count(*) FROM campaign_units')" \
  -eq "$units_total"
check "resume: the reference dataset id" test "$(dataset_id whole2.out)" = "$ref"
check "resume: db check clean" "$draglab" --db "$work/whole.db" db check
if [ "$rc" -ne 0 ]; then tail -5 whole2.err; fi

# --- 4. bad input under several ranks -------------------------------------------------------------
run_mpi -np 2 "$draglab" --db "$work/other.db" law list >other.out 2>other.err
rc=$?
check "law list on 2 ranks: exit 2 (got $rc)" test "$rc" -eq 2
check "law list on 2 ranks: says only campaign run and lbm run run across ranks" \
  grep -q "only .draglab campaign run. and .draglab lbm run. run across" other.err
check "law list on 2 ranks: no database written" test ! -e "$work/other.db"

run_mpi -np 3 "$draglab" --db "$work/nospec.db" campaign run "$work/nosuch.toml" \
  >nospec.out 2>nospec.err
rc=$?
check "a spec rank 0 cannot read, on 3 ranks: exit 2, no rank left waiting (got $rc)" \
  test "$rc" -eq 2
check "a spec rank 0 cannot read: named once, by rank 0" \
  test "$(grep -c 'nosuch.toml' nospec.err)" -eq 1
check "a spec rank 0 cannot read: no database written" test ! -e "$work/nospec.db"

# --- 5. units on several ranks -------------------------------------------------------------------
sed 's/^resolutions = .*/resolutions = [12]\nranks_per_unit = 2/' "$spec_src" >spec2.toml
run_mpi -np 5 "$draglab" --db "$work/group.db" campaign run spec2.toml --threads-per-unit 1 \
  >group.out 2>group.err
rc=$?
check "ranks_per_unit = 2 on 5 ranks: exit 0 (got $rc)" test "$rc" -eq 0
check "ranks_per_unit = 2: every unit done" test "$(units "$work/group.db" done)" -eq "$units_total"
same_units=$(sqlite3 one.db "ATTACH '$work/group.db' AS g; SELECT count(*) FROM campaign_units a
  JOIN g.campaign_units b USING (phi_index, re_index, realization, resolution_index)
  WHERE a.status = 'done' AND b.status = 'done' AND abs(b.F / a.F - 1) < 1e-10")
check "ranks_per_unit = 2: every unit's F equals the reference to 1e-10 ($same_units of $units_total)" \
  test "$same_units" -eq "$units_total"
check "ranks_per_unit = 2: units ran on 2 ranks" \
  test "$(sqlite3 "$work/group.db" "SELECT count(*) FROM campaign_units WHERE json_extract(result_json, '\$.ranks') = 2")" -ge 1
check "ranks_per_unit = 2: the groups are reported (ranks 1-2, ranks 3-4)" \
  bash -c "grep -q '^ranks 1-2 ' group.out && grep -q '^ranks 3-4 ' group.out"
check "ranks_per_unit = 2: db check clean" "$draglab" --db "$work/group.db" db check

sed 's/^resolutions = .*/resolutions = [12]\nranks_per_unit = 3/' "$spec_src" >spec3.toml
run_mpi -np 3 "$draglab" --db "$work/big.db" campaign run spec3.toml >big.out 2>big.err
rc=$?
check "ranks_per_unit = 3 on 3 ranks: exit 2 (got $rc)" test "$rc" -eq 2
check "ranks_per_unit = 3 on 3 ranks: named once, with the job size it needs" \
  test "$(grep -c 'ranks_per_unit = 3 is larger than the job.*at least 4' big.err)" -eq 1
check "ranks_per_unit = 3 on 3 ranks: no database written" test ! -e "$work/big.db"
"$draglab" --db "$work/big1.db" campaign run spec3.toml >big1.out 2>big1.err
rc=$?
check "ranks_per_unit = 3 in one process: exit 2 (got $rc)" test "$rc" -eq 2
run_mpi -np 4 "$draglab" --db "$work/odd.db" campaign run spec2.toml >odd.out 2>odd.err
rc=$?
check "ranks_per_unit = 2 on 4 ranks (3 workers): exit 2 (got $rc)" test "$rc" -eq 2
check "ranks_per_unit = 2 on 4 ranks: named once, with the job sizes that work, nothing written" \
  bash -c "[ \"\$(grep -c 'ranks_per_unit = 2 does not divide the job.s 3 worker ranks.*-np 3 or -np 5' odd.err)\" = 1 ] && [ ! -e '$work/odd.db' ]"
check "ranks_per_unit = 3 in one process: named, no database written" \
  bash -c "grep -q 'ranks_per_unit = 3 is larger than the job' big1.err && [ ! -e '$work/big1.db' ]"

exit "$fail"
