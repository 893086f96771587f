#!/usr/bin/env bash
# install_test.sh BUILD_DIR SOURCE_DIR: cmake --install into a temp prefix, then build and run an
# outside program (1) with pkg-config, (2) with find_package(draglab) (which also names the
# installed adapters), (3) a Fortran program; (4) MFiX's usr_drag from the installed adapters,
# built as an MFiX project would (pkg-config draglab-fortran) into the harness of
# tests/bindings; (5) the Python binding pip-installed into a fresh virtual environment (no
# network: Debian's setuptools and numpy), finding the installed libdraglab through pkg-config,
# evaluating a law over a numpy array.
set -euo pipefail
build="$1"; src="$2"
work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >/dev/null
export PKG_CONFIG_PATH="$work/prefix/lib/pkgconfig:$work/prefix/lib/x86_64-linux-gnu/pkgconfig"
pkg-config --exists draglab
cc "$src/outside_solver.c" -o "$work/via_pkgconfig" $(pkg-config --cflags --libs draglab) -lm
"$work/via_pkgconfig" "$work/a.db"

mkdir -p "$work/outside"
cp "$src/outside_solver.c" "$work/outside/"
cp "$src/CMakeLists.outside.txt" "$work/outside/CMakeLists.txt"
cmake -S "$work/outside" -B "$work/outside/build" -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/outside/build" >/dev/null
LD_LIBRARY_PATH="$work/prefix/lib:$work/prefix/lib/x86_64-linux-gnu" \
  "$work/outside/build/outside_solver" "$work/b.db"

# A Fortran solver through the draglab-fortran pkg-config file (module draglab_mod).
if command -v gfortran >/dev/null; then
  gfortran "$src/outside_solver.f90" -o "$work/via_pkgconfig_f" \
    $(pkg-config --cflags --libs draglab-fortran)
  "$work/via_pkgconfig_f" "$work/c.db"
fi
# MFiX's usr_drag as installed, built against the installed Fortran module.
adapters="$work/prefix/share/draglab/adapters"
[ -f "$adapters/mfix/usr_drag_draglab.f" ] && [ -x "$adapters/openfoam/build.sh" ] &&
  [ -f "$adapters/openfoam/draglabDragModel/draglab.C" ] ||
  { echo "install: the adapters are not installed under $adapters"; exit 1; }
passed=4
if command -v gfortran >/dev/null; then
  # The harness first: it holds the stand-in for MFiX's error_manager module.
  gfortran -ffree-form -J "$work" "$src/../bindings/mfix_usr_drag_test.f90" \
    "$adapters/mfix/usr_drag_draglab.f" -o "$work/mfix_usr_drag" \
    $(pkg-config --cflags --libs draglab-fortran)
  DRAGLAB_LAW=gidaspow@1 DRAGLAB_DB="$work/d.db" LD_LIBRARY_PATH="$work/prefix/lib" \
    "$work/mfix_usr_drag" "$work/d.db"
  passed=$((passed + 1))
fi

# The Python binding as a pip package in a fresh virtual environment.
py=/usr/bin/python3
if "$py" -c "import venv, numpy, setuptools, pip" 2>/dev/null; then
  "$py" -m venv --without-pip --system-site-packages "$work/venv"
  cp -r "$src/../../drag_db/python" "$work/python-src"  # pip builds in the source folder
  SETUPTOOLS_USE_DISTUTILS=stdlib "$work/venv/bin/python" -m pip install -q --no-build-isolation \
    --no-index --no-deps "$work/python-src"
  (cd "$work" && env -u DRAGLAB_LIBRARY -u PYTHONPATH "$work/venv/bin/python" - "$work/prefix" "$work/e.db" <<'PY'
import sys
import numpy as np
import draglab
prefix, db_path = sys.argv[1:3]
assert draglab.__file__.startswith(sys.prefix), draglab.__file__      # the venv's copy
assert draglab.library_path.startswith(prefix), draglab.library_path  # found by pkg-config
with draglab.Database(db_path) as db:
    law = db.load("bvk2007@1")
    phi = np.array([0.1, 0.3, 0.5]); re = np.array([0.0, 10.0, 100.0])
    F = law.F_array(phi, re)
    assert isinstance(F, np.ndarray) and F.dtype == np.float64, type(F)
    assert all(abs(F[i] - law.F(phi[i], re[i])) <= 1e-15 * F[i] for i in range(3)), F
print("python: pip-installed draglab %s, libdraglab %s, F = %s" % (draglab.version(),
      draglab.library_path, F))
PY
  )
  passed=$((passed + 1))
else
  echo "install: python check skipped: $py lacks venv, numpy, setuptools or pip"
fi
echo "install: $passed passed, 0 failed"
