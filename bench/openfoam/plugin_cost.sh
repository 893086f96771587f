#!/usr/bin/env bash
# Cost of the draglab drag model inside OpenFOAM v1912 against OpenFOAM's own, measured in the
# same run: the plugin's compareWith mode evaluates OpenFOAM's GidaspowErgunWenYu on the same
# fields right after gidaspow@1 at every call of twoPhaseEulerFoam, timing both (steady clock
# around each CdRe()), over every cell and boundary face of the laminar/fluidisedBed tutorial.
# Each repeat is one run of --steps steps; the script reports the medians of the per-run times
# per cell or face, and their ratio, with K's largest relative difference as the check that both
# computed the same thing.
# Needs OpenFOAM v1912 and the source its plugin compiles against (scripts/setup.sh
# --with-openfoam) and a built draglab.
# Usage: bench/openfoam/plugin_cost.sh [--repeat N] [--steps S] [--build-dir DIR] [--out FILE]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
repeat=3 steps=100 build="$root/build" out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --repeat) repeat="${2:?}"; shift 2 ;;
    --steps) steps="${2:?}"; shift 2 ;;
    --build-dir) build="${2:?}"; shift 2 ;;
    --out) out="${2:?}"; shift 2 ;;
    *) echo "usage: $0 [--repeat N] [--steps S] [--build-dir DIR] [--out FILE]" >&2; exit 2 ;;
  esac
done
tutorial=/usr/share/doc/openfoam-examples/examples/multiphase/twoPhaseEulerFoam/laminar/fluidisedBed
command -v twoPhaseEulerFoam >/dev/null && [ -d "$tutorial" ] ||
  { echo "plugin_cost: OpenFOAM v1912 not installed (scripts/setup.sh --with-openfoam)" >&2; exit 2; }
export WM_PROJECT_DIR=/usr/share/openfoam FOAM_ETC=/usr/share/openfoam/etc
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$root/adapters/openfoam/build.sh" --draglab-build "$build" --out "$build/openfoam" >/dev/null
cp -r "$tutorial" "$work/case" && chmod -R u+w "$work/case" && gunzip -f "$work/case"/0/*.gz
cd "$work/case"
"$build/cli/draglab" -q --db constant/draglab.db law list >/dev/null
echo "libs (\"$build/openfoam/libdraglabDragModels.so\");" >>system/controlDict
foamDictionary constant/phaseProperties -entry drag -set '( (particles in air) { type draglab;
  law "gidaspow@1"; database "constant/draglab.db"; rangePolicy error;
  compareWith { type GidaspowErgunWenYu; residualRe 1e-3; swarmCorrection { type none; } }
  swarmCorrection { type none; } } )' >/dev/null
end="$(/usr/bin/python3 -c "print($steps * 2e-4)")"
foamDictionary system/controlDict -entry endTime -set "$end" >/dev/null
foamDictionary system/controlDict -entry writeInterval -set "$end" >/dev/null
blockMesh >/dev/null && setFields >/dev/null
ours=() theirs=() worst=()
for i in $(seq 1 "$repeat"); do
  rm -rf "$end" 0.0*[1-9]* 2>/dev/null || true
  twoPhaseEulerFoam >log.run 2>&1
  line="$(grep '^draglab compare:' log.run | tail -1)"
  ours+=("$(sed 's/.*draglab \([0-9.e+-]*\) ns.*/\1/' <<<"$line")")
  theirs+=("$(sed "s/.*OpenFOAM's \([0-9.e+-]*\) ns.*/\1/" <<<"$line")")
  worst+=("$(grep '^draglab compare:' log.run | sed 's/.*difference \([^ ]*\) over cells.*, \([^ ]*\) over boundary.*/\1\n\2/' | sort -g | tail -1)")
  evaluations="$(sed 's/.*(\([0-9.e+]*\) so far).*/\1/' <<<"$line")"
  echo "run $i: draglab ${ours[-1]} ns, OpenFOAM ${theirs[-1]} ns per cell or face ($evaluations evaluations), K differs by ${worst[-1]}" >&2
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
mo="$(median "${ours[@]}")" mt="$(median "${theirs[@]}")"
report="$(printf 'CdRe per cell or face, medians of %d runs of %d steps: draglab gidaspow@1 %.1f ns, OpenFOAM GidaspowErgunWenYu %.1f ns (draglab / OpenFOAM %.2f); K largest relative difference %s\n' \
  "$repeat" "$steps" "$mo" "$mt" "$(echo "$mo / $mt" | bc -l)" "$(printf '%s\n' "${worst[@]}" | sort -g | tail -1)")"
echo "$report"
if [ -n "$out" ]; then
  {
    echo "# Cost of the draglab drag model in OpenFOAM v1912 against its own (bench/openfoam/plugin_cost.sh)."
    echo "# Command: bench/openfoam/plugin_cost.sh --repeat $repeat --steps $steps --out $(basename "$out")"
    echo "# Case: $tutorial, linear solvers as shipped; both models timed in the same run (compareWith)."
    echo "# Code: draglab $("$build/cli/draglab" --version | awk '{print $2}') (git $(git -C "$root" describe --always --dirty 2>/dev/null || echo unknown)). Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) vCPU, OpenFOAM $(dpkg-query -W -f='${Version}' openfoam)."
    echo "# Measured $(date -u +%Y-%m-%d), machine otherwise idle."
    echo "# Per run (ns per cell or face): draglab OpenFOAM K-difference"
    for i in $(seq 0 $((repeat - 1))); do echo "${ours[$i]} ${theirs[$i]} ${worst[$i]}"; done
    echo "# $report"
  } >"$out"
fi
