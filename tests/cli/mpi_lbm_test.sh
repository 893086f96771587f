#!/usr/bin/env bash
# One LBM box decomposed across MPI ranks (mpirun on loopback, oversubscribed), against the same
# run in one process as the reference.
#
# Set-up: a random packing of 8 spheres at phi = 0.3 (seed 3) at d = 10, a 24^3 periodic box with
# sub-node gaps, flow along x; the ranks own slabs of z-planes balanced by fluid nodes, so that
# spheres cross the slab boundaries and their boundary links lie on two ranks.
# Reference: the single-process engine. The decomposed run performs the same arithmetic on every
# node: the halo exchange copies populations exactly, and only the order in which the ranks'
# partial sums (body forces, the interpolation's mass defect, the moments) are added changes, a
# relative rounding of order 1e-16 per sum. The steady state is a contraction, so these do not
# grow: F must agree to 1e-10 relative, and the step count (the same convergence decisions)
# exactly. One population lost or misplaced at an interface shifts F by orders of magnitude
# more, and a missing exchange breaks the momentum balance the convergence test demands.
#   1. Stokes flow (TRT, interpolated walls) on 2 and 4 ranks; Re = 20 (full equilibrium,
#      target-Re control) on 3 ranks (an uneven split); halfway bounce-back and float storage on
#      2 ranks;
#   2. the fields written from 3 ranks (gathered on rank 0) equal the single-process file, with
#      one XDMF file;
#   3. `mpirun -np 1` runs as one process: the same F bit for bit;
#   4. a checkpoint (a file per rank), stopped twice by --max-steps and resumed: the F of the
#      run that never stopped, bit for bit; files of 2 ranks are refused by 3;
#   5. bad input: more ranks than the box has pairs of z-planes: exit 2 on every rank, the message
#      once, nothing written; a run that does not converge on 2 ranks: exit 1, the diagnosis once,
#      no drag.
# Usage: mpi_lbm_test.sh DRAGLAB MPIRUN
set -u
draglab="$(realpath "$1")"
mpirun="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
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
field() {  # field JSON_FILE KEY
  /usr/bin/python3 -c "import json,sys; print(repr(json.load(open(sys.argv[1]))[sys.argv[2]]))" "$1" "$2"
}
same_f() {  # same_f A.json B.json: F within 1e-10 relative, the same steps, B on several ranks
  /usr/bin/python3 - "$1" "$2" <<'EOF'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
rel = abs(b["F"] / a["F"] - 1.0)
print(f"  F {a['F']!r} (1 process) vs {b['F']!r} ({b.get('ranks', 1)} ranks): {rel:.2e} relative; "
      f"steps {a['steps']} vs {b['steps']}")
sys.exit(0 if a["converged"] and b["converged"] and rel < 1e-10 and a["steps"] == b["steps"]
         and b.get("ranks", 1) > 1 else 1)
EOF
}

"$draglab" -q pack --phi 0.3 --n 8 --seed 3 --out p.h5 >/dev/null ||
  { echo "FAIL: packing"; exit 1; }
base=(lbm run --packing p.h5 --d 10 --threads 1)

# --- 1. the same F on 1, 2, 3 and 4 ranks --------------------------------------------------------
one() {  # one NAME ARGS...: the single-process reference
  "$draglab" -q --json "${base[@]}" "${@:2}" >"$1.json" 2>"$1.err" ||
    { echo "FAIL: reference run $1"; cat "$1.err"; fail=1; }
}
ranks() {  # ranks N NAME ARGS...
  run_mpi -np "$1" "$draglab" -q --json "${base[@]}" "${@:3}" >"$2.json" 2>"$2.err" ||
    { echo "FAIL: $2 on $1 ranks"; cat "$2.err"; fail=1; }
}
one stokes --re 0
ranks 2 stokes2 --re 0
ranks 4 stokes4 --re 0
check "Stokes, TRT + interpolated walls: 2 ranks give the single-process F" same_f stokes.json stokes2.json
check "Stokes, TRT + interpolated walls: 4 ranks give the single-process F" same_f stokes.json stokes4.json
one re20 --re 20
ranks 3 re20_3 --re 20
check "Re = 20 (target-Re control): 3 ranks give the single-process F" same_f re20.json re20_3.json
one bb --re 0 --boundary bb
ranks 2 bb2 --re 0 --boundary bb
check "halfway bounce-back: 2 ranks give the single-process F" same_f bb.json bb2.json
one float --re 5 --precision float
ranks 2 float2 --re 5 --precision float
check "float storage, Re = 5: 2 ranks give the single-process F" same_f float.json float2.json

# --- 2. fields gathered on rank 0 ----------------------------------------------------------------
"$draglab" -q "${base[@]}" --re 0 --fields f1.h5 >/dev/null 2>f1.err || { cat f1.err; fail=1; }
run_mpi -np 3 "$draglab" -q "${base[@]}" --re 0 --fields f3.h5 >f3.out 2>f3.err ||
  { cat f3.err; fail=1; }
for set in velocity density solid; do
  # Velocities are stored in float: 1e-6 relative is float's rounding of equal doubles.
  check "fields from 3 ranks: /fields/$set equals the single-process file" \
    h5diff --relative=1e-6 f1.h5 f3.h5 "/fields/$set" "/fields/$set"
done
check "fields from 3 ranks: one XDMF file naming the gathered HDF5 file" \
  bash -c '[ "$(ls *.xmf | wc -l)" = 2 ] && grep -q "f3.h5:/fields/velocity" f3.xmf'

# --- 3. mpirun -np 1 ----------------------------------------------------------------------------
run_mpi -np 1 "$draglab" -q --json "${base[@]}" --re 0 >np1.json 2>np1.err || { cat np1.err; fail=1; }
f_one="$(field stokes.json F)"
f_np1="$(field np1.json F)"
check "mpirun -np 1: the single-process F bit for bit ($f_one, $f_np1)" \
  test -n "$f_one" -a "$f_one" = "$f_np1"

# --- 4. a checkpoint per rank: stopped twice, then resumed to the bits of the run that never stopped
steps2="$(field stokes2.json steps)"
run_mpi -np 2 "$draglab" -q --json "${base[@]}" --re 0 --checkpoint ck --max-steps $((steps2 / 3)) \
  >ck1.json 2>ck1.err
code=$?
check "checkpoint on 2 ranks: stopped by --max-steps, exit 1 (got $code), one file per rank" \
  bash -c "[ $code = 1 ] && [ -s ck.rank0of2 ] && [ -s ck.rank1of2 ]"
run_mpi -np 2 "$draglab" -q --json "${base[@]}" --re 0 --checkpoint ck \
  --max-steps $((2 * steps2 / 3 + 1)) >ck2.json 2>ck2.err
run_mpi -np 2 "$draglab" -q --json "${base[@]}" --re 0 --checkpoint ck >ck3.json 2>ck3.err ||
  { cat ck3.err; fail=1; }
f_ref="$(field stokes2.json F)"
f_ck="$(field ck3.json F)"
check "checkpoint on 2 ranks: resumed twice, the uninterrupted F bit for bit ($f_ref, $f_ck)" \
  test -n "$f_ck" -a "$f_ck" = "$f_ref" -a "$(field ck3.json steps)" = "$steps2"
check "checkpoint on 2 ranks: resumed from the second stop, the files removed at the end" \
  bash -c "[ \"\$(/usr/bin/python3 -c 'import json; print(json.load(open(\"ck3.json\"))[\"resumed_from_step\"] > 0)')\" = True ] && ! ls ck.rank* 2>/dev/null"
run_mpi -np 2 "$draglab" -q --json "${base[@]}" --re 0 --checkpoint ck --max-steps 40 >/dev/null 2>&1
run_mpi -np 3 "$draglab" -q "${base[@]}" --re 0 --checkpoint ck >ck4.out 2>ck4.err
code=$?
check "checkpoint of 2 ranks read by 3: exit 2 (got $code), its files left, no result" \
  bash -c "[ $code = 2 ] && [ -s ck.rank0of2 ] && [ ! -s ck4.out ] && grep -q 'another number of ranks' ck4.err"

# --- 5. bad input and failures ------------------------------------------------------------------
# d = 4: a 10-plane box, room for 5 ranks of 2 planes.
run_mpi -np 6 "$draglab" -q lbm run --packing p.h5 --d 4 --re 0 --threads 1 --fields no.h5 \
  >many.out 2>many.err
code=$?
check "6 ranks for a 10-plane box: exit 2 (got $code)" test "$code" = 2
check "6 ranks for a 10-plane box: the limit named once" \
  bash -c '[ "$(grep -c "z-planes, fewer than 2 per rank for 6 ranks; use at most 5 ranks" many.err)" = 1 ]'
check "6 ranks for a 10-plane box: nothing written" bash -c '[ ! -e no.h5 ] && [ ! -s many.out ]'
run_mpi -np 2 "$draglab" -q "${base[@]}" --re 0 --max-steps 20 >short.out 2>short.err
code=$?
check "not converged on 2 ranks: exit 1 (got $code)" test "$code" = 1
check "not converged on 2 ranks: the diagnosis once, no drag" \
  bash -c '[ "$(grep -c "not converged after max_steps = 20" short.err)" = 1 ] &&
           grep -q "NOT CONVERGED" short.out && ! grep -q "^F " short.out'

[ "$fail" = 0 ] && echo "all MPI LBM checks passed"
exit "$fail"
