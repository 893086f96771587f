#!/usr/bin/env bash
# The engine's packing path against a peer list-based kernel, side by side in one run: RRZE
# lbm-benchmark-kernels (github.com/RRZE-HPC/lbm-benchmark-kernels, GPLv3; build it outside this
# repository, e.g. `make CONFIG=linux-gcc ISA=avx` in its src/) runs `list-aa-pv-soa` (fluid-only
# list, AA pattern, partial vectorization, TRT, double) on its `blocks-8` geometry (100^3), and
# `draglab lbm bench` measures, on the same geometry and in the same repetition, the engine's
# interpolated-wall path (link pass included) and halfway bounce-back, besides its random sphere
# packing (phi 0.4 unless --phi) and all-fluid box, and the regularized operator (rr) on the
# packing (with TRT's wall correction) and the all-fluid box. Repetitions are interleaved (engine, peer, engine, ...)
# so that a slow phase of this shared machine hits both alike; medians are reported.
# --same-packing also runs the peer on the engine's own packing (the sphere count `lbm
# bench` chose, `pack` with the same seed, `pack voxelize --raw` at d 16): the same fluid nodes,
# the peer with halfway bounce-back. The peer reads no geometry file as released: it needs a
# `-geometry file:PATH` type (one byte per node, nonzero = obstacle, x fastest; periodic in all
# directions) added to GeoCreateByStr in its src/Geometry.c (docs/scaling.md, section 4).
# --phi P (0.4 unless given) sets the packing's solid fraction for both (`lbm bench --phi`).
# Usage: bench/lbm_peer/run_peer.sh --peer PATH/lbmbenchk-linux-gcc-release-dp [--threads T]
#        [--repeat N] [--iterations I] [--draglab BIN] [--out FILE] [--same-packing] [--phi P]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
peer=""
threads=2
repeat=5
iterations=200
draglab="$root/build/cli/draglab"
out=""
same_packing=0
phi=0.4
while [ $# -gt 0 ]; do
  case "$1" in
    --peer) peer="$2"; shift 2 ;;
    --threads) threads="$2"; shift 2 ;;
    --repeat) repeat="$2"; shift 2 ;;
    --iterations) iterations="$2"; shift 2 ;;
    --draglab) draglab="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --same-packing) same_packing=1; shift ;;
    --phi) phi="$2"; shift 2 ;;
    *) echo "usage: $0 --peer BIN [--threads T] [--repeat N] [--iterations I] [--draglab BIN] [--out FILE] [--same-packing] [--phi P]" >&2; exit 2 ;;
  esac
done
[ -x "$peer" ] || { echo "error: --peer must name the built RRZE lbmbenchk binary" >&2; exit 2; }
[ -x "$draglab" ] || { echo "error: no draglab at $draglab (build first)" >&2; exit 2; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
peer_run() {  # peer_run DIMS GEOMETRY ITERATIONS OUTFILE
  (cd "$work" && OMP_NUM_THREADS="$threads" "$peer" -dims "$1" -geometry "$2" -kernel list-aa-pv-soa \
    -iterations "$3" -t "$threads" 2>&1) | awk '/^P:/ {print $2}' >>"$4"
}
for r in $(seq 1 "$repeat"); do
  echo "repetition $r of $repeat" >&2
  "$draglab" lbm bench --threads "$threads" --repeat 1 --phi "$phi" --json 2>/dev/null >"$work/engine_$r.json"
  # (in the scratch folder: the peer writes its own output files where it runs)
  peer_run 100x100x100 blocks-8 "$iterations" "$work/peer.txt"
  if [ "$same_packing" = 1 ]; then
    if [ "$r" = 1 ]; then
      spheres="$(python3 -c 'import json,sys; t=open(sys.argv[1]).read(); print(json.JSONDecoder().raw_decode(t[t.index("{"):])[0]["packing_spheres"])' "$work/engine_1.json")"
      "$draglab" -q pack --phi "$phi" --n "$spheres" --seed 1 --out "$work/packing.h5" >/dev/null
      edge="$("$draglab" -q pack voxelize "$work/packing.h5" --resolution 16 --raw "$work/packing.raw" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["dims"][0])')"
    fi
    peer_run "${edge}x${edge}x${edge}" "file:$work/packing.raw" "$(( (iterations + 1) / 2 ))" "$work/peer_packing.txt"
  fi
done
table="$(python3 - "$work" "$repeat" "$same_packing" "$phi" <<'PY'
import json, statistics, sys
work, repeat, same_packing, phi = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "1", sys.argv[4]
peer = [float(x) for x in open(f"{work}/peer.txt").read().split()]
def load(path):
    text = open(path).read()
    return json.JSONDecoder().raw_decode(text[text.index("{"):])[0]
runs = [load(f"{work}/engine_{r}.json") for r in range(1, repeat + 1)]
def med(key): return statistics.median(r[key] for r in runs)
p = statistics.median(peer)
rows = [
    ("peer list-aa-pv-soa, blocks-8", p, max(peer)),
    ("engine, blocks-8, interpolated path", med("mflups_blocks"), max(r["mflups_blocks"] for r in runs)),
    ("engine, blocks-8, halfway bounce-back", med("mflups_blocks_bb"), max(r["mflups_blocks_bb"] for r in runs)),
    (f"engine, phi {phi} packing d 16, interpolated path", med("mflups_fluid_packing"), max(r["mflups_fluid_packing"] for r in runs)),
    (f"engine, phi {phi} packing d 16, halfway bounce-back", med("mflups_fluid_packing_bb"), max(r["mflups_fluid_packing_bb"] for r in runs)),
    ("engine, all-fluid box", med("mflups"), max(r["mflups"] for r in runs)),
    (f"engine rr, phi {phi} packing d 16, TRT's wall", med("mflups_fluid_packing_rr"), max(r["mflups_fluid_packing_rr"] for r in runs)),
    ("engine rr, all-fluid box", med("mflups_rr"), max(r["mflups_rr"] for r in runs)),
]
print(f"# {len(peer)} interleaved repetitions, {runs[0]['threads']} threads; bandwidth (in-place update) median {med('bandwidth_gbs'):.1f} GB/s")
print("# kernel / geometry                                   MFLUPS median  best  ratio to peer (medians)")
for name, m, b in rows:
    print(f"{name:<52} {m:8.1f} {b:8.1f}  {m / p:6.2f}")
if same_packing:
    pp = [float(x) for x in open(f"{work}/peer_packing.txt").read().split()]
    q = statistics.median(pp)
    print(f"# the same phi {phi} packing ({runs[0]['packing_spheres']} spheres, d 16) for both; ratio to the peer on it")
    print(f"{'peer list-aa-pv-soa, phi ' + phi + ' packing d 16, bounce-back':<52} {q:8.1f} {max(pp):8.1f}  {1.0:6.2f}")
    for name, m, b in rows:
        if "packing" in name:
            print(f"{name:<52} {m:8.1f} {b:8.1f}  {m / q:6.2f}")
PY
)"
echo "$table"
if [ -n "$out" ]; then
  {
    echo "# bench/lbm_peer/run_peer.sh --threads $threads --repeat $repeat --iterations $iterations$([ "$same_packing" = 1 ] && echo ' --same-packing') --phi $phi"
    echo "# code: $(git -C "$root" rev-parse --short HEAD)$(git -C "$root" diff --quiet || echo '+modified'); peer: RRZE lbm-benchmark-kernels $(git -C "$(dirname "$peer")/.." rev-parse --short HEAD 2>/dev/null || echo '?'), list-aa-pv-soa, double$([ "$same_packing" = 1 ] && echo ', its src/Geometry.c given the file geometry type')"
    echo "# machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(date -u +%Y-%m-%d)"
    echo "$table"
  } >"$out"
fi
