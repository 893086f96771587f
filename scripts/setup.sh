#!/usr/bin/env bash
# Installs the Debian 12 packages draglab needs (only those missing), then configures and builds
# draglab in Release into build/. Idempotent; non-interactive; works as root, uses sudo otherwise.
#
#   scripts/setup.sh            # install what is missing, configure, build
#   scripts/setup.sh --no-build # install only
#   scripts/setup.sh --with-openfoam  # also OpenFOAM v1912 (openfoam, openfoam-examples) and the
#                                     # source of Debian's openfoam package, whose headers the
#                                     # drag-model plugin compiles against (adapters/openfoam),
#                                     # into ~/.cache/draglab/openfoam-src
#
# DRAGLAB_BUILD_DIR: another build directory. DRAGLAB_SANITIZE=1: build with ASan + UBSan
# (-DDRAGLAB_SANITIZE=ON, RelWithDebInfo) into build-sanitize/ unless DRAGLAB_BUILD_DIR says.
# DRAGLAB_BUILD_TARGET: build only this target (e.g. input_tests) instead of everything.
# DRAGLAB_EXTRA_PACKAGES: more Debian packages to install the same way (scripts/fuzz.sh: clang).
set -euo pipefail

build=1 openfoam=0
for arg in "$@"; do
  case "$arg" in
    --no-build) build=0 ;;
    --with-openfoam) openfoam=1 ;;
    *) echo "setup: unknown option '$arg' (--no-build, --with-openfoam)" >&2; exit 2 ;;
  esac
done
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
sanitize="${DRAGLAB_SANITIZE:-0}"
if [ "$sanitize" = 1 ]; then
  build_dir="${DRAGLAB_BUILD_DIR:-$here/build-sanitize}"
  cmake_args=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DDRAGLAB_SANITIZE=ON)
else
  build_dir="${DRAGLAB_BUILD_DIR:-$here/build}"
  cmake_args=(-DCMAKE_BUILD_TYPE=Release)
fi

# Why each package is here: see README.md, section "Dependencies".
packages=(
  cmake g++ make pkg-config         # build
  gfortran                          # Fortran module and its test program
  libsqlite3-dev sqlite3            # law database (sqlite3 shell: immutability tests)
  libssl-dev                        # SHA-256 content hashes (OpenSSL libcrypto)
  nlohmann-json3-dev                # JSON output and records
  libceres-dev libeigen3-dev        # automatic derivatives (Jet), fitting
  libnlopt-dev                      # global and minimax fits (fitter/)
  libtomlplusplus-dev               # campaign specs (TOML)
  python3-matplotlib                # draglab report: PNG figures (Debian's /usr/bin/python3)
  libcli11-dev libfmt-dev           # command line
  libhdf5-dev hdf5-tools            # packing and field files (h5dump: format tests)
  libgtest-dev                      # test suite
  python3-h5py                      # tests: packing files open in h5py
  gnuplot-nox                       # draglab lbm convergence --plot (PNG, no X11)
  python3                           # Python bindings test (Debian's /usr/bin/python3)
  python3-pip python3-numpy         # pip install ./drag_db/python into a venv (install test)
  libopenmpi-dev openmpi-bin        # campaigns across ranks and nodes (mpirun, srun): mpi/
)

# shellcheck disable=SC2206  # a space-separated list of package names
packages+=(${DRAGLAB_EXTRA_PACKAGES:-})
# OpenFOAM v1912 for the drag-model plugin, its test and the side-by-side benchmarks.
[ "$openfoam" = 1 ] && packages+=(openfoam openfoam-examples bzip2)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "setup: installing missing Debian packages: ${missing[*]}" >&2
  if [ "$(id -u)" -eq 0 ]; then
    sudo=(env DEBIAN_FRONTEND=noninteractive)
  elif command -v sudo >/dev/null; then
    sudo=(sudo env DEBIAN_FRONTEND=noninteractive)  # sudo resets the environment
  else
    echo "setup: missing packages (${missing[*]}) and neither root nor sudo: install them" \
         "as an administrator (apt-get install ${missing[*]}) and run again" >&2
    exit 1
  fi
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if [ "$openfoam" = 1 ]; then
  # Debian ships OpenFOAM's libraries without its headers; the plugin compiles against the
  # source of the same package version, fetched from Debian's archive as a source package.
  cache="${HOME}/.cache/draglab/openfoam-src"
  version="$(dpkg-query -W -f='${Version}' openfoam)"
  upstream="${version%-*}"
  if [ -z "$(ls -d "$cache"/openfoam-OpenFOAM-v* 2>/dev/null)" ]; then
    echo "setup: fetching the source of Debian's openfoam $version into $cache" >&2
    mkdir -p "$cache/lists/partial"
    list="$cache/deb-src.sources"
    printf 'Types: deb-src\nURIs: http://deb.debian.org/debian\nSuites: bookworm\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' >"$list"
    apt_src=(-o Dir::Etc::SourceList=/dev/null -o Dir::Etc::SourceParts=/dev/null
             -o Dir::Etc::sourcelist="$list" -o Dir::State::Lists="$cache/lists")
    apt-get "${apt_src[@]}" update -qq
    (cd "$cache" && apt-get "${apt_src[@]}" source --download-only -qq "openfoam=$version")
    tar -xjf "$cache"/openfoam_"${upstream}".orig.tar.bz2 -C "$cache"
    rm -rf "$cache/lists" "$cache"/openfoam_*.tar.* "$cache"/openfoam_*.dsc
  fi
fi

[ "$build" = 0 ] && exit 0

jobs="$(nproc 2>/dev/null || echo 2)"
if [ "$sanitize" != 1 ] && [ -f "$build_dir/CMakeCache.txt" ] &&
   grep -q '^DRAGLAB_SANITIZE:BOOL=ON' "$build_dir/CMakeCache.txt"; then
  cmake_args+=(-DDRAGLAB_SANITIZE=OFF)  # a sanitizer build directory reused for a plain build
fi
cmake -S "$here" -B "$build_dir" "${cmake_args[@]}" >/dev/null
target_args=()
[ -n "${DRAGLAB_BUILD_TARGET:-}" ] && target_args=(--target "$DRAGLAB_BUILD_TARGET")
# A built tree says nothing: the "Built target" lines of an up-to-date build are dropped, what
# is compiled and every error still stream through.
cmake --build "$build_dir" -j "$jobs" "${target_args[@]}" 2>&1 |
  { grep --line-buffered -v -E '^\[ *[0-9]+%\] Built target |^Consolidate compiler generated' || true; }
