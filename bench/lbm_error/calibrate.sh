#!/usr/bin/env bash
# Calibration of the engine's error_estimate against measured d sweeps: for each case (an array
# or packing at a Re), `draglab lbm run` at every d of the sweep with the engine's defaults, then
# the true error of each run against the reference of its case -- the Richardson value of the two
# finest d (order 2, the interpolated wall's), or the finest d where the sequence is not
# monotone -- beside the run's error_estimate, and how often the true error exceeds it. The
# Richardson value needs the two finest d of the sweep; where one of them has no result, the finest
# result is the reference.
# Packings: `draglab pack --phi P --n N --seed 1`. Runs one case at a time, `--jobs` runs at once.
# --work DIR keeps the runs there, and a run whose result is there already is not run again.
# Usage: bench/lbm_error/calibrate.sh [--cases "sc:0.125:10 sc:0.125:100 pack:0.3:16:10"]
#        [--d "12 16 24 32"] [--jobs J] [--draglab BIN] [--out FILE] [--work DIR]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cases="sc:0.125:10 sc:0.125:100 pack:0.3:16:10"
ds="12 16 24 32"
jobs=2
draglab="$root/build/cli/draglab"
out=""
work=""
while [ $# -gt 0 ]; do
  case "$1" in
    --cases) cases="$2"; shift 2 ;;
    --d) ds="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --draglab) draglab="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    *) echo "usage: $0 [--cases LIST] [--d LIST] [--jobs J] [--draglab BIN] [--out FILE] [--work DIR]" >&2; exit 2 ;;
  esac
done
[ -x "$draglab" ] || { echo "error: no draglab at $draglab (build first)" >&2; exit 2; }
if [ -n "$work" ]; then
  mkdir -p "$work"
else
  work="$(mktemp -d)"
  trap 'rm -rf "$work"' EXIT
fi
runs=()
for c in $cases; do
  IFS=: read -r kind phi a b <<<"$c"
  if [ "$kind" = pack ] && [ ! -s "$work/p_${phi}_$a.h5" ]; then
    "$draglab" pack --phi "$phi" --n "$a" --seed 1 --out "$work/p_${phi}_$a.h5" >/dev/null 2>&1
  fi
  for d in $ds; do runs+=("$c $d"); done
done
run_one() {
  set -- $1
  IFS=: read -r kind phi a b <<<"$1"
  local name="$work/r_${1//:/_}_$2"
  [ -s "$name.json" ] && return 0
  if [ "$kind" = sc ]; then
    "$draglab" lbm run --array sc --phi "$phi" --re "$a" --d "$2" --threads 1 --json \
      >"$name.json" 2>"$name.err" || true
  else
    "$draglab" lbm run --packing "$work/p_${phi}_$a.h5" --re "$b" --d "$2" --threads 1 --json \
      >"$name.json" 2>"$name.err" || true
  fi
}
export -f run_one
export draglab work
printf '%s\n' "${runs[@]}" | xargs -P "$jobs" -I{} bash -c 'run_one "{}"'
table="$(python3 - "$work" "$ds" $cases <<'PY'
import json, os, sys
work, ds, cases = sys.argv[1], [float(x) for x in sys.argv[2].split()], sys.argv[3:]
total = exceed = 0
print("# case  d  F  error_estimate  reference  true_error  exceeds  (reference: R = Richardson of the two finest d, order 2; f = finest d)")
for c in cases:
    pts = []
    for d in ds:
        f = os.path.join(work, f"r_{c.replace(':', '_')}_{d:g}.json")
        try:
            j = json.load(open(f))
        except Exception:
            j = None
        if j and j.get("converged") and j.get("F") is not None:
            pts.append((d, j["F"], j["error_estimate"], j.get("d", d)))
        else:
            err = open(f[:-5] + ".err").read().strip().splitlines()
            print(f"{c:<18} {d:4g}  not measured: {(err[-1] if err else '?')[:100]}")
    if len(pts) < 2:
        continue
    (d1, f1, _, x1), (d2, f2, _, x2) = pts[-2], pts[-1]
    monotone = all((pts[k + 1][1] - pts[k][1]) * (f2 - f1) >= 0 for k in range(len(pts) - 1))
    if monotone and len(ds) >= 2 and (d1, d2) == (ds[-2], ds[-1]):
        ref = f2 + (f2 - f1) / ((x2 / x1) ** 2 - 1.0)
        tag = "R"
    else:
        ref, tag = f2, "f"
    for d, F, est, x in pts:
        if tag == "f" and d == pts[-1][0]:
            continue
        true = F / ref - 1.0
        over = abs(true) > est
        total += 1
        exceed += over
        print(f"{c:<18} {d:4g}  {F:10.5f}  {100 * est:6.2f} %  {ref:10.5f} {tag}  {100 * true:+7.2f} %  {'EXCEEDS' if over else 'within'}")
print(f"# the true error exceeded error_estimate in {exceed} of {total} runs")
PY
)"
echo "$table"
if [ -n "$out" ]; then
  {
    echo "# bench/lbm_error/calibrate.sh --cases \"$cases\" --d \"$ds\""
    echo "# code: $(git -C "$root" rev-parse --short HEAD)$(git -C "$root" diff --quiet || echo '+modified'); machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(date -u +%Y-%m-%d)"
    echo "$table"
  } >"$out"
fi
