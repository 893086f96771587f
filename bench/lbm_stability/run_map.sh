#!/usr/bin/env bash
# The stability map of the finite-Re engine: for each packing (phi), Re, d and collision, one
# `draglab lbm run` with the engine's defaults (velocity plan, automatic wall) classified as
#   converged   steady drag reached
#   averaged    unsteady flow, F time-averaged to its standard error
#   diverged    numerical instability (the engine's diagnosis)
#   refused     refused before stepping (cell Reynolds number beyond the operator's limit)
#   unfinished  neither within --max-steps
# with kappa Re / d (estimated), tau, the wall, F, the steps and the wall time. Packings: random
# hard-sphere packings `draglab pack --phi P --n N --seed 1` (N = 27 at phi >= 0.5, else 16).
# Usage: bench/lbm_stability/run_map.sh [--phi "0.3 0.4 0.6"] [--re "10 30 100"] [--d "16"]
#        [--collision "trt rr"] [--max-steps N] [--jobs J] [--draglab BIN] [--out FILE]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
phis="0.3 0.4 0.6"
res="10 30 100"
ds="16"
collisions="trt"
max_steps=60000
jobs=2
draglab="$root/build/cli/draglab"
out=""
while [ $# -gt 0 ]; do
  case "$1" in
    --phi) phis="$2"; shift 2 ;;
    --re) res="$2"; shift 2 ;;
    --d) ds="$2"; shift 2 ;;
    --collision) collisions="$2"; shift 2 ;;
    --max-steps) max_steps="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --draglab) draglab="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    *) echo "usage: $0 [--phi LIST] [--re LIST] [--d LIST] [--collision LIST] [--max-steps N] [--jobs J] [--draglab BIN] [--out FILE]" >&2; exit 2 ;;
  esac
done
[ -x "$draglab" ] || { echo "error: no draglab at $draglab (build first)" >&2; exit 2; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for phi in $phis; do
  n=16
  if python3 -c "import sys; sys.exit(0 if float('$phi') >= 0.5 else 1)"; then n=27; fi
  "$draglab" pack --phi "$phi" --n "$n" --seed 1 --out "$work/p$phi.h5" >/dev/null 2>&1
done
cases=()
for phi in $phis; do for re in $res; do for d in $ds; do for c in $collisions; do
  cases+=("$phi $re $d $c")
done; done; done; done
run_case() {
  set -- $1
  local name="$work/r_$1_$2_$3_$4"
  "$draglab" lbm run --packing "$work/p$1.h5" --re "$2" --d "$3" --collision "$4" --threads 1 \
    --tolerance 1e-5 --max-steps "$max_steps" --json >"$name.json" 2>"$name.err" || true
}
export -f run_case
export draglab work max_steps
printf '%s\n' "${cases[@]}" | xargs -P "$jobs" -I{} bash -c 'run_case "{}"'
summary="$(python3 - "$work" $phis -- $res -- $ds -- $collisions <<'EOF'
import json, sys, os
work = sys.argv[1]
rest = sys.argv[2:]
groups, cur = [], []
for a in rest:
    if a == "--":
        groups.append(cur); cur = []
    else:
        cur.append(a)
groups.append(cur)
phis, res, ds, cols = groups
print("# phi  Re  d  collision  outcome  kappa_Re/d  tau  wall  F  +-  steps  wall_s  note")
for phi in phis:
    for re in res:
        for d in ds:
            for c in cols:
                base = os.path.join(work, f"r_{phi}_{re}_{d}_{c}")
                err = open(base + ".err").read() if os.path.exists(base + ".err") else ""
                try:
                    j = json.load(open(base + ".json"))
                except Exception:
                    j = None
                if j is None:
                    outcome = "refused" if "cell Reynolds number" in err else "error"
                    note = err.strip().splitlines()[-1][:160] if err.strip() else ""
                    print(f"{phi} {re} {d} {c} {outcome} - - - - - - - {note}")
                    continue
                diag = j.get("diagnosis") or ""
                if j.get("converged"):
                    outcome = "averaged" if j.get("unsteady") else "converged"
                elif "instability" in diag:
                    outcome = "diverged"
                else:
                    outcome = "unfinished"
                F = j.get("F")
                se = j.get("F_time_error") if j.get("unsteady") else (j.get("error_estimate") or 0) * (F or 0)
                fmt = lambda v, f: (f % v) if isinstance(v, (int, float)) else "-"
                print(f"{phi} {re} {d} {c} {outcome} {fmt(j.get('cell_reynolds'), '%.1f')} "
                      f"{fmt(j.get('tau'), '%.5f')} {j.get('wall', '-')} {fmt(F, '%.4f')} "
                      f"{fmt(se, '%.3g')} {j.get('steps')} {fmt(j.get('wall_s'), '%.1f')} {diag[:120]}")
EOF
)"
header="# Stability map of the finite-Re engine (bench/lbm_stability/run_map.sh).
# Command: bench/lbm_stability/run_map.sh --phi \"$phis\" --re \"$res\" --d \"$ds\" --collision \"$collisions\" --max-steps $max_steps
# Input: draglab pack --phi P --n N --seed 1 (N = 27 at phi >= 0.5, else 16); lbm run defaults, tolerance 1e-5, 1 thread per run, $jobs at once.
# Code: git $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown) ($("$draglab" --version 2>/dev/null | head -1)). Machine: $(lscpu 2>/dev/null | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores.
# Measured $(date -u +%Y-%m-%d).
# F +-: the time-averaging standard error (averaged) or the engine's error estimate (converged)."
if [ -n "$out" ]; then
  printf '%s\n%s\n' "$header" "$summary" >"$out"
fi
printf '%s\n%s\n' "$header" "$summary"
