#!/usr/bin/env bash
# The draglab drag model inside a real OpenFOAM v1912 run (twoPhaseEulerFoam, Debian's openfoam).
#
# Set-up: OpenFOAM's laminar/fluidisedBed tutorial (Debian's openfoam-examples), shortened to
# END_TIME simulated seconds, run with:
#   A. OpenFOAM's own GidaspowErgunWenYu (the reference);
#   B. `type draglab; law "gidaspow@1";` with `compareWith { type GidaspowErgunWenYu; }`: the
#      plugin evaluates OpenFOAM's model on the same fields at every call and logs the largest
#      relative difference of CdRe (K = alpha_d 0.75 CdRe rho nu / d^2 has the same factors for
#      both, so this is K's difference);
#   C. `law bvk2007@1` (unquoted, as OpenFOAM users write words; rangePolicy clamp: its box
#      starts at phi = 0.1, the freeboard is particle-free): the law changes the answer;
#   D. bad input: bvk2007@1 with rangePolicy error, an unknown law, a missing database.
# References and tolerances: gidaspow@1 and OpenFOAM's GidaspowErgunWenYu are the same formula
# (Ergun below alpha_air = 0.8, Wen-Yu above, superficial Re = alpha_air |U_r| d / nu), so K
# must agree to round-off: 1e-10 relative on every call (the arithmetic differs in order only,
# 1e-16 per operation). The runs are then the same to the solver's own round-off: the bed
# pressure drop (area-averaged p at the inlet minus the outlet, every step) within 1e-6
# relative over the run, with the linear solvers converged to 1e-12 in both. "The run" is the
# first 20 steps (0.004 s): the start-up of the bed amplifies any round-off difference by about
# a decade every 2 steps after the first ten (measured: 7e-14 at step 1, 5e-13 at step 10,
# 6e-8 at step 20, 9e-6 at step 50, docs/adapters.md), as it would between two runs of OpenFOAM
# alone on different core counts. A bad input stops the run with OpenFOAM's FatalError naming the law,
# the cell and the box, never a NaN.
# Skipped (exit 77) when OpenFOAM, its tutorial or the OpenFOAM source the plugin compiles
# against is missing: scripts/setup.sh --with-openfoam installs all three.
# Usage: openfoam_plugin_test.sh DRAGLAB_SOURCE DRAGLAB_BUILD [END_TIME]
set -u
root="$(realpath "$1")"
build="$(realpath "$2")"
end_time="${3:-0.004}"
tutorial=/usr/share/doc/openfoam-examples/examples/multiphase/twoPhaseEulerFoam/laminar/fluidisedBed
src="${DRAGLAB_OPENFOAM_SRC:-$(ls -d "$HOME"/.cache/draglab/openfoam-src/openfoam-OpenFOAM-v1912* 2>/dev/null | head -1)}"
skip() { echo "SKIPPED: $* (scripts/setup.sh --with-openfoam installs it)"; exit 77; }
command -v twoPhaseEulerFoam >/dev/null || skip "OpenFOAM v1912 (twoPhaseEulerFoam) not installed"
[ -d "$tutorial" ] || skip "the fluidisedBed tutorial (openfoam-examples) not installed"
[ -d "$src/src/OpenFOAM" ] || skip "no OpenFOAM v1912 source at $src"
py=/usr/bin/python3
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export WM_PROJECT_DIR=/usr/share/openfoam FOAM_ETC=/usr/share/openfoam/etc
fail=0
check() {  # check DESCRIPTION COMMAND...
  if "${@:2}"; then echo "ok: $1"; else echo "FAIL: $1"; fail=1; fi
}

"$root/adapters/openfoam/build.sh" --openfoam-src "$src" --draglab-build "$build" \
  --out "$build/openfoam" >"$work/build.log" 2>&1 ||
  { echo "FAIL: the plugin does not build"; cat "$work/build.log"; exit 1; }
plugin="$build/openfoam/libdraglabDragModels.so"

make_case() {  # make_case DIR DRAG_ENTRIES (the body of the (particles in air) dictionary)
  local dir="$1"
  cp -r "$tutorial" "$dir" && chmod -R u+w "$dir" && gunzip -f "$dir"/0/*.gz 2>/dev/null
  [ -f "$dir/0/alpha.particles" ] || cp "$dir/0/alpha.particles.orig" "$dir/0/alpha.particles"
  "$py" - "$dir" "$end_time" "$plugin" "$2" <<'PY' || return 1
import re, sys
case, end, plugin, drag = sys.argv[1:5]
def edit(path, fn):
    text = open(path).read()
    new = fn(text)
    if new == text:
        sys.exit("openfoam_plugin_test: could not edit " + path + " (tutorial changed?)")
    open(path, "w").write(new)
edit(case + "/system/controlDict", lambda s: re.sub(
    r"functions\n\{.*\n\}\n",
    "functions\n{\n"
    "    pInlet\n    {\n        type surfaceFieldValue; libs (fieldFunctionObjects);\n"
    "        writeControl timeStep; writeInterval 1; log false; writeFields false;\n"
    "        regionType patch; name inlet; operation areaAverage; fields (p);\n    }\n"
    "    pOutlet\n    {\n        $pInlet;\n        name outlet;\n    }\n}\n"
    "libs (\"" + plugin + "\");\n",
    s.replace("endTime         2;", "endTime         %s;" % end)
     .replace("writeInterval   0.01;", "writeInterval   %s;" % end)
     .replace("writePrecision  6;", "writePrecision  16;"), flags=re.S))
# Linear solvers to 1e-12 (the tutorial stops U at 1e-5): two runs whose K differ by round-off
# then differ by round-off, not by a solver iteration more or less.
edit(case + "/system/fvSolution", lambda s: re.sub(r"tolerance( +)[0-9.e-]+;", r"tolerance\g<1>1e-12;", s))
original = "        type            GidaspowErgunWenYu;\n        residualRe      1e-3;"
if drag != original:
    edit(case + "/constant/phaseProperties", lambda s: s.replace(original, drag, 1))
PY
  (cd "$dir" && blockMesh >log.blockMesh 2>&1 && setFields >log.setFields 2>&1) || return 1
  "$build/cli/draglab" -q --db "$dir/constant/draglab.db" law list >/dev/null
}
run_case() {  # run_case DIR: twoPhaseEulerFoam's exit status, its log in DIR/log.run
  (cd "$1" && timeout -s KILL 600 twoPhaseEulerFoam >log.run 2>&1)
}
dp_history() {  # dp_history DIR: "time dp" per step
  paste "$1/postProcessing/pInlet/0/surfaceFieldValue.dat" \
    "$1/postProcessing/pOutlet/0/surfaceFieldValue.dat" | awk '!/^#/ {printf "%s %.17g\n", $1, $2 - $4}'
}

# --- A and B: OpenFOAM's model, and gidaspow@1 through the plugin ------------------------------
make_case "$work/A" "        type            GidaspowErgunWenYu;
        residualRe      1e-3;" || { echo "FAIL: case A"; exit 1; }
run_case "$work/A"
check "A (OpenFOAM's GidaspowErgunWenYu) runs" test $? -eq 0
make_case "$work/B" '        type            draglab;
        law             "gidaspow@1";
        database        "constant/draglab.db";
        rangePolicy     error;
        compareWith
        {
            type            GidaspowErgunWenYu;
            residualRe      1e-3;
            swarmCorrection { type none; }
        }
        residualRe      1e-3;' || { echo "FAIL: case B"; exit 1; }
run_case "$work/B"
check "B (draglab gidaspow@1) runs" test $? -eq 0
check "B: the plugin announces the law, its hash and the database" \
  grep -q 'draglab drag model: law gidaspow@1 (form gidaspow, hash' "$work/B/log.run"
worst="$(sed -n 's/^draglab compare: CdRe max relative difference \([^ ]*\) over cells.*, \([^ ]*\) over boundary faces.*/\1\n\2/p' "$work/B/log.run" |
  sort -g | tail -1)"
calls="$(grep -c '^draglab compare:' "$work/B/log.run")"
echo "  K (CdRe) of gidaspow@1 against OpenFOAM's GidaspowErgunWenYu: largest relative difference $worst over $calls calls"
check "K agrees with OpenFOAM's to 1e-10 on every call, the first included" \
  "$py" -c "import sys; sys.exit(0 if $calls > 0 and float('$worst') <= 1e-10 else 1)"
timing="$(grep '^draglab compare:' "$work/B/log.run" | tail -1 | sed 's/.*time per cell or face: //')"
echo "  cost of CdRe per cell or face (same run): $timing"
dp_history "$work/A" >"$work/A.dp"
dp_history "$work/B" >"$work/B.dp"
dp_rel="$("$py" - "$work/A.dp" "$work/B.dp" <<'PY'
import sys
a = [tuple(map(float, l.split())) for l in open(sys.argv[1])]
b = [tuple(map(float, l.split())) for l in open(sys.argv[2])]
if not a or len(a) != len(b) or any(x[0] != y[0] for x, y in zip(a, b)):
    print("mismatch"); sys.exit()
print(max(abs(y[1] / x[1] - 1) for x, y in zip(a, b)))
PY
)"
echo "  bed pressure drop, B against A: largest relative difference $dp_rel over the run"
check "the pressure-drop history agrees with OpenFOAM's own model to 1e-6" \
  "$py" -c "import sys; sys.exit(0 if '$dp_rel' != 'mismatch' and float('$dp_rel') <= 1e-6 else 1)"

# --- C: another law changes the answer -----------------------------------------------------------
make_case "$work/C" '        type            draglab;
        law             bvk2007@1;
        database        "constant/draglab.db";
        rangePolicy     clamp;
        residualRe      1e-3;' || { echo "FAIL: case C"; exit 1; }
run_case "$work/C"
check "C (bvk2007@1, rangePolicy clamp) runs" test $? -eq 0
dp_history "$work/C" >"$work/C.dp"
change="$("$py" - "$work/A.dp" "$work/C.dp" <<'PY'
import sys
a = [tuple(map(float, l.split())) for l in open(sys.argv[1])]
c = [tuple(map(float, l.split())) for l in open(sys.argv[2])]
print(max(abs(y[1] / x[1] - 1) for x, y in zip(a, c)) if a and len(a) == len(c) else "mismatch")
PY
)"
echo "  bed pressure drop with bvk2007@1 against GidaspowErgunWenYu: largest relative change $change"
check "bvk2007@1 changes the pressure-drop history (by more than 1e-4)" \
  "$py" -c "import sys; sys.exit(0 if '$change' != 'mismatch' and float('$change') > 1e-4 else 1)"

# --- D: bad input ---------------------------------------------------------------------------------
bad_case() {  # bad_case NAME DRAG_ENTRIES PATTERN DESCRIPTION
  make_case "$work/$1" "$2" || { echo "FAIL: case $1"; fail=1; return; }
  run_case "$work/$1"
  local code=$?
  check "$4: the run stops (exit $code)" test "$code" -ne 0
  check "$4: FatalError names it" grep -q "$3" "$work/$1/log.run"
  check "$4: no NaN written" bash -c "! grep -rqi 'nan' '$work/$1'/0.* 2>/dev/null"
}
bad_case D1 '        type            draglab;
        law             "bvk2007@1";
        database        "constant/draglab.db";
        rangePolicy     error;
        residualRe      1e-3;' \
  "draglab: the law bvk2007@1 cannot be evaluated at cell [0-9]* (alpha.particles = .*validity box is phi in \[0.1, 0.6\]" \
  "bvk2007@1 with rangePolicy error in the particle-free freeboard"
bad_case D2 '        type            draglab;
        law             "nosuchlaw@1";
        database        "constant/draglab.db";
        residualRe      1e-3;' "draglab: cannot load the law nosuchlaw@1" "an unknown law"
bad_case D3 '        type            draglab;
        law             "gidaspow@1";
        database        "constant/missing.db";
        residualRe      1e-3;' "draglab: no database .*constant/missing.db" "a missing database"

exit "$fail"
