#!/usr/bin/env bash
# Strong and weak scaling of one LBM box decomposed across MPI ranks (`mpirun -np R draglab lbm
# run`), against the single-process engine on the same cores, measured side by side: each repeat
# runs, interleaved, on a random packing of 54 spheres at phi = 0.4 (TRT, interpolated walls,
# Stokes flow, double), a fixed number of steps each (the stepping rate, MFLUPS, excludes the
# set-up):
#   threads : 1 process x C threads,        box E^3        (the strong-scaling reference)
#   ranks   : mpirun -np C, 1 thread each,  box E^3        (strong: the same box on C ranks)
#   single  : 1 process x 1 thread,         box (E^3/C)^(1/3) (weak: one rank's share alone)
# and prints the medians and
#   strong efficiency = MFLUPS(ranks) / MFLUPS(threads)   (C ranks against 1 rank x C threads)
#   weak efficiency   = MFLUPS(ranks) / (C MFLUPS(single)) (the same nodes per rank).
# C = the machine's cores, E = 256 by default (--edge). The runs stop at --steps without
# converging, so each exits 1 by design; its JSON still carries the measured MFLUPS.
# Usage: bench/lbm_mpi/run_scaling.sh [--repeat N] [--edge E] [--steps S] [--draglab BIN] [--out FILE]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
repeat=3
edge=256
steps=40
draglab="$root/build/cli/draglab"
out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --repeat) repeat="$2"; shift 2 ;;
    --edge) edge="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    --draglab) draglab="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    *) echo "usage: $0 [--repeat N] [--edge E] [--steps S] [--draglab BIN] [--out FILE]" >&2; exit 2 ;;
  esac
done
[ -x "$draglab" ] || { echo "error: no draglab at $draglab (build first)" >&2; exit 2; }
command -v mpirun >/dev/null || { echo "error: mpirun not found (libopenmpi-dev openmpi-bin)" >&2; exit 2; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none
cores="$(nproc)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
py=/usr/bin/python3

"$draglab" -q pack --phi 0.4 --n 54 --seed 1 --out "$work/p.h5" >/dev/null
# Resolutions that give a box of `edge` nodes, and one of edge^3 / cores nodes.
box="$("$py" -c "import math; print((54 * math.pi / 6 / 0.4) ** (1 / 3))")"
d_full="$("$py" -c "print($edge / $box)")"
d_share="$("$py" -c "print($edge / $cores ** (1 / 3) / $box)")"

mflups() {  # mflups OUT.json COMMAND...: the run's MFLUPS (it stops at --steps, exit 1 expected)
  local json="$1"
  shift
  "$@" >"$json" 2>"$work/last.err" || true
  "$py" -c "import json,sys; j=json.load(open(sys.argv[1])); assert j['steps'] == $steps, j; print(j['mflups'], j['fluid_nodes'])" "$json" ||
    { cat "$work/last.err" >&2; exit 1; }
}
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }

common=(lbm run --packing "$work/p.h5" --re 0 --max-steps "$steps")
m_threads=() m_ranks=() m_single=()
for i in $(seq 1 "$repeat"); do
  read -r a fluid_full < <(mflups "$work/t.json" "$draglab" -q --json "${common[@]}" --d "$d_full" --threads "$cores")
  read -r b _ < <(mflups "$work/r.json" mpirun -np "$cores" "$draglab" -q --json "${common[@]}" --d "$d_full" --threads 1)
  read -r c fluid_share < <(mflups "$work/s.json" "$draglab" -q --json "${common[@]}" --d "$d_share" --threads 1)
  m_threads+=("$a") m_ranks+=("$b") m_single+=("$c")
  echo "repeat $i: threads $a, ranks $b, single $c MFLUPS" >&2
done
mt="$(median "${m_threads[@]}")" mr="$(median "${m_ranks[@]}")" ms="$(median "${m_single[@]}")"
report="$(printf 'cores %d, box %d^3 (%d fluid nodes; one share %d), %d steps, %d repeats, medians: threads %.2f, ranks %.2f, single %.2f MFLUPS\nstrong: %d ranks x 1 thread against 1 rank x %d threads: %.1f %%\nweak: %d ranks against %d x one rank on its share alone: %.1f %%\n' \
  "$cores" "$edge" "$fluid_full" "$fluid_share" "$steps" "$repeat" "$mt" "$mr" "$ms" \
  "$cores" "$cores" "$(echo "100 * $mr / $mt" | bc -l)" \
  "$cores" "$cores" "$(echo "100 * $mr / ($cores * $ms)" | bc -l)")"
echo "$report"
if [ -n "$out" ]; then
  {
    echo "# Strong and weak scaling of one LBM box across MPI ranks (bench/lbm_mpi)."
    echo "# Command: bench/lbm_mpi/run_scaling.sh --repeat $repeat --edge $edge --steps $steps --out $(basename "$out")"
    echo "# Input: draglab pack --phi 0.4 --n 54 --seed 1; d = $d_full (box $edge^3) and $d_share (1/$cores of the nodes); TRT + ibb, Stokes, double."
    echo "# Code: draglab $("$draglab" --version | awk '{print $2}') (git $(git -C "$root" describe --always --dirty 2>/dev/null || echo unknown)). Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $cores vCPU, $(mpirun --version | head -1)."
    echo "# Measured $(date -u +%Y-%m-%d), interleaved."
    echo "# Per repeat (MFLUPS): threads ranks single"
    for i in $(seq 0 $((repeat - 1))); do echo "${m_threads[$i]} ${m_ranks[$i]} ${m_single[$i]}"; done
    echo "$report" | sed 's/^/# /'
  } >"$out"
fi
