#!/usr/bin/env bash
# Parallel efficiency of `draglab campaign run` across MPI ranks, against one process on the same
# cores, measured side by side: each repeat runs, interleaved and each in a fresh database,
#   threads : draglab campaign run SPEC --jobs 1 --threads-per-unit C   (one process, C threads)
#   workers : draglab campaign run SPEC --jobs C --threads-per-unit 1   (one process, C workers)
#   ranks   : mpirun -np C+1 draglab campaign run SPEC --threads-per-unit 1 (rank 0 + C workers)
# and prints the median wall times and efficiency = t(threads) / t(ranks) (the issue's measure:
# C local ranks against one rank with C threads), plus t(workers) / t(ranks) (what MPI costs
# against the single-process runner doing the same split). C = the machine's cores.
# Usage: bench/campaign_mpi/run_efficiency.sh [--repeat N] [--draglab BIN] [--out FILE]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
repeat=3
draglab="$root/build/cli/draglab"
out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --repeat) repeat="$2"; shift 2 ;;
    --draglab) draglab="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    *) echo "usage: $0 [--repeat N] [--draglab BIN] [--out FILE]" >&2; exit 2 ;;
  esac
done
[ -x "$draglab" ] || { echo "error: no draglab at $draglab (build first)" >&2; exit 2; }
command -v mpirun >/dev/null || { echo "error: mpirun not found (libopenmpi-dev openmpi-bin)" >&2; exit 2; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
cores="$(nproc)"
spec="$here/spec.toml"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

seconds() {  # seconds COMMAND...: wall time of the command, which must succeed
  local start end
  start=$(date +%s.%N)
  "$@" >"$work/last.out" 2>"$work/last.err" || { cat "$work/last.err" >&2; exit 1; }
  end=$(date +%s.%N)
  echo "$end - $start" | bc -l
}
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }

t_threads=() t_workers=() t_ranks=()
for i in $(seq 1 "$repeat"); do
  t_threads+=("$(seconds "$draglab" -q --db "$work/t$i.db" campaign run "$spec" --jobs 1 --threads-per-unit "$cores")")
  t_workers+=("$(seconds "$draglab" -q --db "$work/w$i.db" campaign run "$spec" --jobs "$cores" --threads-per-unit 1)")
  t_ranks+=("$(seconds mpirun -np $((cores + 1)) "$draglab" -q --db "$work/r$i.db" campaign run "$spec" --threads-per-unit 1)")
  echo "repeat $i: threads ${t_threads[-1]} s, workers ${t_workers[-1]} s, ranks ${t_ranks[-1]} s" >&2
done
mt="$(median "${t_threads[@]}")" mw="$(median "${t_workers[@]}")" mr="$(median "${t_ranks[@]}")"
report="$(printf 'cores %d, %d repeats, medians: threads %.2f s, workers %.2f s, ranks %.2f s\nefficiency of %d ranks against 1 rank x %d threads: %.1f %%\nranks against %d single-process workers: %.1f %%\n' \
  "$cores" "$repeat" "$mt" "$mw" "$mr" "$cores" "$cores" "$(echo "100 * $mt / $mr" | bc -l)" \
  "$cores" "$(echo "100 * $mw / $mr" | bc -l)")"
echo "$report"
if [ -n "$out" ]; then
  {
    echo "# Parallel efficiency of draglab campaign run across MPI ranks (bench/campaign_mpi)."
    echo "# Command: bench/campaign_mpi/run_efficiency.sh --repeat $repeat --out $(basename "$out")"
    echo "# Spec: bench/campaign_mpi/spec.toml (sha256 $(sha256sum "$spec" | cut -c1-16)...)"
    echo "# Code: draglab $("$draglab" --version | awk '{print $2}') (git $(git -C "$root" describe --always --dirty 2>/dev/null || echo unknown)). Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $cores vCPU, $(mpirun --version | head -1)."
    echo "# Measured $(date -u +%Y-%m-%d), interleaved, each run in a fresh database."
    echo "# Per repeat (seconds): threads workers ranks"
    for i in $(seq 0 $((repeat - 1))); do echo "${t_threads[$i]} ${t_workers[$i]} ${t_ranks[$i]}"; done
    echo "$report" | sed 's/^/# /'
  } >"$out"
fi
