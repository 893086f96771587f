#!/usr/bin/env bash
# The three recipes at the top of docs/adapters.md, run as they are written there: each
# `<!-- recipe: NAME -->` block, in an empty folder, against a fresh `cmake --install` of this
# build ($PREFIX, PATH and PKG_CONFIG_PATH set as the page says). After each, the test checks
# what the recipe promises:
#   openfoam   the case ran to its end with the stored law (skipped, saying so, without
#              OpenFOAM or the source its plugin compiles against);
#   mfix       usr_drag.o, compiled against the Fortran module, linked into the MFiX stand-in
#              harness of tests/bindings returns gidaspow@1 as MFiX expects it (exported
#              DRAGLAB_LAW/DRAGLAB_DB);
#   c-fortran  both programs print bvk2007@1's F(0.4, 100) = 30.741553 (the value
#              tests/install prints for the same law and point).
# Usage: adapter_recipes_test.sh SOURCE_DIR BUILD_DIR
set -u
src="$(realpath "$1")"
build="$(realpath "$2")"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail=0
check() {  # check DESCRIPTION COMMAND...
  if "${@:2}"; then echo "ok: $1"; else echo "FAIL: $1"; fail=1; fi
}
recipe() {  # recipe NAME: the shell block after <!-- recipe: NAME --> in docs/adapters.md
  /usr/bin/python3 - "$src/docs/adapters.md" "$1" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
m = re.search(r"<!-- recipe: %s -->\n```sh\n(.*?)\n```" % re.escape(sys.argv[2]), text, re.S)
sys.exit("no recipe '%s' in docs/adapters.md" % sys.argv[2]) if not m else print(m.group(1))
PY
}
export PREFIX="$work/prefix"
cmake --install "$build" --prefix "$PREFIX" >/dev/null || { echo "FAIL: cmake --install"; exit 1; }
export PATH="$PREFIX/bin:$PATH" PKG_CONFIG_PATH="$PREFIX/lib/pkgconfig"
run_recipe() {  # run_recipe NAME: in $work/NAME, output in $work/NAME.log
  mkdir -p "$work/$1"
  recipe "$1" >"$work/$1.sh" || return 1
  (cd "$work/$1" && bash -euo pipefail "$work/$1.sh") >"$work/$1.log" 2>&1
  local code=$?
  [ "$code" = 0 ] || { echo "--- recipe $1 failed (exit $code):"; tail -20 "$work/$1.log"; }
  return "$code"
}

# --- C and Fortran -------------------------------------------------------------------------------
check "recipe c-fortran runs" run_recipe c-fortran
check "c-fortran: the C solver prints bvk2007@1's F(0.4, 100)" \
  grep -q '^C: F(0.4, 100) = 30.741553$' "$work/c-fortran.log"
check "c-fortran: the Fortran solver prints the same" \
  grep -q '^Fortran: F(0.4, 100) =  *30.741553$' "$work/c-fortran.log"

# --- MFiX ----------------------------------------------------------------------------------------
# MFiX's own error_manager module, which MFiX's build puts in the module path: the stand-in.
mkdir -p "$work/mfix"
(cd "$work/mfix" && gfortran -c "$src/tests/bindings/mfix_usr_drag_test.f90" -o harness.o \
  $(pkg-config --cflags draglab-fortran)) >"$work/harness.log" 2>&1 ||
  { echo "FAIL: the MFiX stand-in does not compile"; cat "$work/harness.log"; exit 1; }
check "recipe mfix runs" run_recipe mfix
check "mfix: usr_drag.o built" test -f "$work/mfix/usr_drag.o"
# The recipe's exports, as the MFiX run would see them.
mfix_env="$(grep '^export DRAGLAB_' "$work/mfix.sh" | sed 's/^export //')"
(cd "$work/mfix" && gfortran harness.o usr_drag.o -o mfix_solver $(pkg-config --libs draglab-fortran) \
  -Wl,-rpath,"$(pkg-config --variable=libdir draglab)" &&
  env $(eval echo "$mfix_env") ./mfix_solver "$work/mfix/draglab.db") >"$work/mfix_run.log" 2>&1
check "mfix: the solver linked as the recipe says returns gidaspow@1 as MFiX expects" \
  grep -q '^all 28 cells agree$' "$work/mfix_run.log"

# --- OpenFOAM ------------------------------------------------------------------------------------
if command -v twoPhaseEulerFoam >/dev/null &&
   [ -d /usr/share/doc/openfoam-examples/examples/multiphase/twoPhaseEulerFoam ] &&
   { [ -n "${DRAGLAB_OPENFOAM_SRC:-}" ] || ls -d "$HOME"/.cache/draglab/openfoam-src/openfoam-OpenFOAM-v1912* >/dev/null 2>&1; }; then
  check "recipe openfoam runs" run_recipe openfoam
  check "openfoam: the case ran to its end with the stored law" \
    bash -c "grep -q 'draglab drag model: law gidaspow@1' '$work/openfoam.log' &&
             grep -q '^End' '$work/openfoam/bed/log.twoPhaseEulerFoam'"
else
  echo "skipped: recipe openfoam (OpenFOAM v1912 or its source not installed: scripts/setup.sh --with-openfoam)"
fi
exit "$fail"
