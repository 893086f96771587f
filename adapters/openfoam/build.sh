#!/usr/bin/env bash
# Builds libdraglabDragModels.so, the draglab drag model for OpenFOAM v1912's twoPhaseEulerFoam
# (Debian's openfoam package), outside draglab's own build.
#
# Debian ships OpenFOAM's libraries but not its headers: they come from Debian's source package
# of the same version (scripts/setup.sh --with-openfoam puts it in ~/.cache/draglab/openfoam-src,
# or give --openfoam-src). The plugin is compiled as OpenFOAM's own wmake would (its linux64Gcc
# rules: -std=c++11, double precision, 32-bit labels, -DNoRepository), with per-library
# include folders made like wmakeLnInclude's (links, in the output folder: the source tree is
# not touched), and linked against Debian's /usr/lib/lib*.so and draglab's C ABI (libdraglab).
#
# Usage: adapters/openfoam/build.sh [--openfoam-src DIR] [--draglab-build DIR] [--out DIR]
#   --openfoam-src   the unpacked OpenFOAM v1912 source       [$DRAGLAB_OPENFOAM_SRC or the one
#                    scripts/setup.sh --with-openfoam put in ~/.cache/draglab/openfoam-src]
#   --draglab-build  draglab's build folder (libdraglab)      [build]
#   --draglab-prefix an installed draglab (cmake --install): its include/ and lib/ instead
#                    [the prefix this script is installed under, share/draglab/adapters/openfoam]
#   --out            where the library goes                    [DRAGLAB_BUILD/openfoam, or
#                    ./draglab-openfoam for an installed draglab]
# Exit: 0 built, 2 bad input (a folder missing, OpenFOAM not installed), 1 compile failure.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
src="${DRAGLAB_OPENFOAM_SRC:-$(ls -d "$HOME"/.cache/draglab/openfoam-src/openfoam-OpenFOAM-v1912* 2>/dev/null | head -1)}"
build="$root/build"
prefix=""
# Installed as PREFIX/share/draglab/adapters/openfoam: build against that installation.
[ -d "$root/drag_db" ] || prefix="$(cd "$here/../../../.." && pwd)"
out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --openfoam-src) src="${2:?}"; shift 2 ;;
    --draglab-build) build="${2:?}"; prefix=""; shift 2 ;;
    --draglab-prefix) prefix="${2:?}"; shift 2 ;;
    --out) out="${2:?}"; shift 2 ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) echo "build.sh: unknown option '$1' (--help)" >&2; exit 2 ;;
  esac
done
if [ -n "$prefix" ]; then out="${out:-$PWD/draglab-openfoam}"; else out="${out:-$build/openfoam}"; fi
fail() { echo "build.sh: $*" >&2; exit 2; }
[ -f /usr/lib/libOpenFOAM.so ] && [ -f /usr/lib/libcompressibleEulerianInterfacialModels.so ] ||
  fail "OpenFOAM v1912 is not installed (scripts/setup.sh --with-openfoam, or apt-get install openfoam)"
[ -f "$src/src/OpenFOAM/db/IOobject/IOobject.H" ] ||
  fail "no OpenFOAM v1912 source at $src (scripts/setup.sh --with-openfoam fetches Debian's)"
if [ -n "$prefix" ]; then
  lib="$(ls "$prefix"/lib/libdraglab.so* "$prefix"/lib/*/libdraglab.so* 2>/dev/null | head -1 || true)"
  [ -n "$lib" ] || fail "no libdraglab under $prefix/lib (--draglab-prefix)"
  draglab_includes=(-I"$prefix/include")
else
  lib="$(ls "$build"/drag_db/libdraglab.so* 2>/dev/null | head -1 || true)"
  [ -n "$lib" ] || fail "no libdraglab in $build/drag_db: build draglab first (./run.sh or scripts/setup.sh)"
  draglab_includes=(-I"$root/drag_db/include" -I"$build/drag_db/include")
fi
app="$src/applications/solvers/multiphase/twoPhaseEulerFoam"

mkdir -p "$out/lnInclude"
# wmakeLnInclude's view of a library: every source and header of its tree in one folder.
ln_include() {  # ln_include NAME DIR
  local dest="$out/lnInclude/$1"
  if [ ! -d "$dest" ]; then
    mkdir -p "$dest.tmp"
    (cd "$2" && find -H . -name lnInclude -prune -o -name Make -prune -o -type f \
      \( -name '*.[CHh]' -o -name '*.[ch]xx' -o -name '*.[ch]pp' -o -name '*.type' \) -print) |
      while read -r f; do ln -s "$2/${f#./}" "$dest.tmp/" 2>/dev/null || true; done
    mv "$dest.tmp" "$dest"
  fi
  echo "-I$dest"
}
includes=(
  "$(ln_include OpenFOAM "$src/src/OpenFOAM")"
  "$(ln_include OSspecific "$src/src/OSspecific/POSIX")"
  "$(ln_include twoPhaseSystem "$app/twoPhaseSystem")"
  "$(ln_include interfacialModels "$app/interfacialModels")"
  "$(ln_include finiteVolume "$src/src/finiteVolume")"
  "$(ln_include meshTools "$src/src/meshTools")"
  "$(ln_include compressibleTransport "$src/src/transportModels/compressible")"
  "$(ln_include basicThermo "$src/src/thermophysicalModels/basic")"
  "-I$src/src/transportModels/incompressible/transportModel"
  "$(ln_include turbulenceModels "$src/src/TurbulenceModels/turbulenceModels")"
  "$(ln_include compressibleTurbulence "$src/src/TurbulenceModels/compressible")"
  "$(ln_include phaseCompressibleTurbulence "$src/src/TurbulenceModels/phaseCompressible")"
)
flags=(-std=c++11 -m64 -pthread -DOPENFOAM=1912 -DWM_DP -DWM_LABEL_SIZE=32 -O3 -DNoRepository
       -ftemplate-depth-100 -fPIC -Wall -Wno-unused-parameter -Wno-old-style-cast
       -Wno-deprecated-copy -Wno-class-memaccess)
g++ "${flags[@]}" "${includes[@]}" "${draglab_includes[@]}" \
  -c "$here/draglabDragModel/draglab.C" -o "$out/draglab.o" || exit 1
g++ -shared -o "$out/libdraglabDragModels.so" "$out/draglab.o" \
  -Xlinker --add-needed -Xlinker --no-as-needed \
  -L/usr/lib -lcompressibleEulerianInterfacialModels -lcompressibleTwoPhaseSystem \
  -lfiniteVolume -lmeshTools -lOpenFOAM \
  -L"$(dirname "$lib")" -ldraglab -Wl,-rpath,"$(dirname "$lib")" || exit 1
echo "built $out/libdraglabDragModels.so"
