#!/usr/bin/env bash
# install_test.sh BUILD_DIR SOURCE_DIR: cmake --install into a temp prefix, then build and run an
# outside program (1) with pkg-config, (2) with find_package(draglab).
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
echo "install: 3 passed, 0 failed"
