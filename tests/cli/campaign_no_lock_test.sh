#!/usr/bin/env bash
# A campaign database on a filesystem that cannot take locks (simulated: an LD_PRELOAD shim makes
# flock fail with ENOLCK, as some network filesystems do): `campaign run` in one process and on
# 3 MPI ranks exits 2 naming the lock and the errno, and writes nothing (no database, no lock or
# probe file left).
# Usage: campaign_no_lock_test.sh DRAGLAB SPEC NO_FLOCK_SO [MPIRUN]
set -u
draglab="$(realpath "$1")"
spec="$(realpath "$2")"
shim="$(realpath "$3")"
mpirun="${4:-}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
fail=0
check() {  # check DESCRIPTION COMMAND...
  if "${@:2}"; then echo "ok: $1"; else echo "FAIL: $1"; fail=1; fi
}
LD_PRELOAD="$shim" "$draglab" --db "$work/one.db" campaign run "$spec" >one.out 2>one.err
code=$?
check "one process: exit 2 (got $code)" test "$code" = 2
check "one process: the lock and the errno named" \
  grep -q "cannot lock '.*one.db.campaign-probe-.*': No locks available: the database's filesystem does not support locks" one.err
check "one process: nothing written" test -z "$(ls -A "$work" | grep -v '\.out$\|\.err$')"
if [ -n "$mpirun" ]; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  export OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_btl_vader_single_copy_mechanism=none
  # Only rank 0 touches the database; the shim goes to every rank all the same.
  timeout -s KILL 300 "$mpirun" -np 3 -x LD_PRELOAD="$shim" "$draglab" --db "$work/ranks.db" \
    campaign run "$spec" >ranks.out 2>ranks.err
  code=$?
  check "3 ranks: exit 2 on every rank, none left waiting (got $code)" test "$code" = 2
  check "3 ranks: the lock named once" test "$(grep -c "cannot lock '.*ranks.db" ranks.err)" = 1
  check "3 ranks: nothing written" test -z "$(ls -A "$work" | grep -v '\.out$\|\.err$')"
fi
exit "$fail"
