#!/usr/bin/env bash
# The bidisperse campaign of issue 36 (data/campaigns/bidisperse/, nine specs: size ratio
# {1.5, 2, 4} x small-sphere share {0.25, 0.5, 0.75}), run into one database, cheapest first, then
# each campaign's per-species table exported into one CSV with a provenance header; mono.toml, the
# monodisperse F(phi) the species are divided by, is run first and exported beside it.
#
#   scripts/bidisperse_campaign.sh [--specs DIR] [--db FILE] [--jobs N] [--out-dir DIR]
#                                  [--draglab BIN]
#
# --specs: the folder of the specs (default data/campaigns/bidisperse, Stokes flow, the
# monodisperse reference and nine mixtures; data/campaigns/bidisperse_re: three of them at Re 10
# and 30).
#
# writes DIR/species.csv, DIR/units.csv (each unit's error estimate) and DIR/mono.csv (default
# DIR: data/datasets/bidisperse).
#
# A killed run continues where it stopped (each campaign resumes; finished ones are skipped).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
db="bidisperse.db"
jobs=2
out_dir="$root/data/datasets/bidisperse"
draglab="$root/build/cli/draglab"
spec_dir="$root/data/campaigns/bidisperse"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --specs) spec_dir="$2"; shift 2 ;;
    --db) db="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --out-dir) out_dir="$2"; shift 2 ;;
    --draglab) draglab="$2"; shift 2 ;;
    *) echo "bidisperse_campaign.sh: unknown option '$1' (--specs, --db, --jobs, --out-dir, --draglab)" >&2; exit 2 ;;
  esac
done
# mono first, then the mixtures cheapest first (the larger the ratio and the smaller the large
# spheres' share, the more spheres per box); a folder may hold a subset.
specs=()
for s in mono r1.5_xs0.75 r1.5_xs0.5 r1.5_xs0.25 r2_xs0.75 r2_xs0.5 r2_xs0.25 r4_xs0.75 r4_xs0.5 \
  r4_xs0.25; do
  [[ -f "$spec_dir/$s.toml" ]] && specs+=("$s")
done
name_of() { sed -n 's/^name = "\(.*\)"$/\1/p' "$spec_dir/$1.toml"; }
for s in "${specs[@]}"; do
  spec="$spec_dir/$s.toml"
  name="$(name_of "$s")"
  if "$draglab" campaign status "$name" --db "$db" --json 2>/dev/null | grep -q '"units_pending": 0'; then
    continue
  fi
  resume=()
  "$draglab" campaign status "$name" --db "$db" >/dev/null 2>&1 && resume=(--resume)
  "$draglab" campaign run "$spec" --db "$db" --jobs "$jobs" --threads-per-unit 1 "${resume[@]}"
done
mkdir -p "$out_dir"
# Stokes flow, or the target Re of the specs (the flow the exported data were measured in).
flow="$(grep -h '^re = ' "$spec_dir"/*.toml | sort -u | sed 's/^re = //' | tr '\n' ' ')"
[[ "$flow" == "[0] " || -z "$flow" ]] && flow="Stokes" || flow="Re ${flow% }"
provenance() {
  echo "# $1 (issue 36): scripts/bidisperse_campaign.sh --db $(basename "$db")"
  echo "# specs: $(basename "$spec_dir")/*.toml (sha256 of their concatenation: $(cat "$spec_dir"/*.toml | sha256sum | cut -c1-16))"
  echo "# code: $("$draglab" --version); machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
}
{
  provenance "bidisperse per-species drag ($flow)"
  echo "# columns: campaign, size_ratio, x_small (asked), then campaign export --species: y = d_i/<d> (Sauter), x = volume share, F_i = F_d,i/(3 pi mu d_i U) (drag-only, own diameter), F = mixture F (van der Hoef 2005)"
  header_done=0
  for s in "${specs[@]}"; do
    [[ $s == mono ]] && continue
    name="$(name_of "$s")"
    r="${s#r}"; r="${r%%_*}"; xs="${s##*xs}"
    csv="$("$draglab" campaign export "$name" --db "$db" --species 2>/dev/null)" || continue
    if [[ $header_done == 0 ]]; then echo "campaign,size_ratio,x_small,$(head -1 <<<"$csv")"; header_done=1; fi
    tail -n +2 <<<"$csv" | sed "s/^/$name,$r,$xs,/"
  done
} > "$out_dir/species.csv"
{
  provenance "the engine's error estimate of every unit of the bidisperse campaign"
  echo "campaign,id,error_estimate"
  for s in "${specs[@]}"; do
    "$draglab" campaign export "$(name_of "$s")" --db "$db" --csv 2>/dev/null |
      /usr/bin/python3 -c 'import csv, sys
for r in csv.DictReader(sys.stdin):
    print("%s,%s,%s" % (sys.argv[1], r["id"], r["error_estimate"]))' "$(name_of "$s")" || true
  done
} > "$out_dir/units.csv"
{
  provenance "monodisperse F(phi) ($flow) of the bidisperse campaign's reference"
  echo "# columns: those of campaign export $(name_of mono) --csv that the reduction reads"
  "$draglab" campaign export "$(name_of mono)" --db "$db" --csv 2>/dev/null |
    /usr/bin/python3 -c 'import csv, sys
keep = ["id", "phi", "re_target", "realization", "resolution", "status", "F", "error_estimate", "steps", "wall_s"]
print(",".join(keep))
for r in csv.DictReader(sys.stdin):
    print(",".join(r[k] for k in keep))'
} > "$out_dir/mono.csv"
echo "wrote $out_dir/species.csv ($(grep -vc '^#' "$out_dir/species.csv") lines), units.csv and mono.csv"
