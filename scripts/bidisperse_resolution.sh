#!/usr/bin/env bash
# How many lattice units the small spheres of a bidisperse packing need (issue 36): one packing
# per (size ratio, phi) at x_S = 0.5, the small spheres at 6, 8, 12 and 16 lattice units (Stokes
# flow unless --re); each size class's F_i and the engine's error estimate, against the finest.
#
#   scripts/bidisperse_resolution.sh [--re RE] [--cases "RATIO:PHI:SPHERES ..."]
#                                    [--d-small "6 8 12 16"] [--draglab BIN] [--work DIR] > table.txt
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
draglab="$root/build/cli/draglab"
work="$(mktemp -d)"
re=0
cases="2:0.3:64 2:0.6:64 4:0.3:200 4:0.6:200"
d_small="6 8 12 16"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --re) re="$2"; shift 2 ;;
    --cases) cases="$2"; shift 2 ;;
    --d-small) d_small="$2"; shift 2 ;;
    --draglab) draglab="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    *) echo "bidisperse_resolution.sh: unknown option '$1' (--re, --cases, --d-small, --draglab, --work)" >&2; exit 2 ;;
  esac
done
mkdir -p "$work"
echo "# scripts/bidisperse_resolution.sh: $("$draglab" --version), $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
echo "# ratio phi spheres d_small d(<d>) F F_small F_large err_estimate steps wall_s collision"
echo "# one packing per case (--seed 36), x_S = 0.5, Re $re, --collision auto"
for case in $cases; do
  IFS=: read -r ratio phi n <<<"$case"
  pack="$work/r${ratio}_phi${phi}.h5"
  "$draglab" pack --phi "$phi" --n "$n" --dist bi --size-ratio "$ratio" --large-fraction 0.5 \
    --seed 36 --out "$pack" >/dev/null
  # Sauter mean over the small diameter, from the packing's counts.
  sauter=$(/usr/bin/python3 -c "
r=$ratio; s=0.5; n=$n; x=s/(r**3*(1-s)+s); nl=round(x*n); ns=n-nl
print((nl*r**3+ns)/(nl*r*r+ns))")
  for ds in $d_small; do
    d=$(/usr/bin/python3 -c "print(round($ds*$sauter, 4))")
    out="$work/r${ratio}_phi${phi}_ds${ds}.json"
    "$draglab" lbm run --packing "$pack" --d "$d" --re "$re" --threads 2 --json > "$out" 2>/dev/null || true
    /usr/bin/python3 - "$out" "$ratio" "$phi" "$n" "$ds" "$d" <<'PY'
import json, sys
path, ratio, phi, n, ds, d = sys.argv[1:]
try:
    r = json.load(open(path))
except Exception:
    print(ratio, phi, n, ds, d, "failed")
    sys.exit(0)
sp = sorted(r.get("species", []), key=lambda s: s["diameter_over_sauter"])
fs = [s["F"] for s in sp]
print(ratio, phi, n, ds, d, "%.5f" % r["F"], " ".join("%.5f" % f for f in fs),
      "%.4f" % r.get("error_estimate", float("nan")), r.get("steps", 0), "%.1f" % r.get("wall_s", 0),
      r.get("collision", "?"))
PY
  done
done
