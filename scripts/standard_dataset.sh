#!/usr/bin/env bash
# The standard dataset of issue 33 from its parts (data/campaigns/standard/PART.toml, one campaign
# each; docs/campaigns.md, "The standard dataset"): every committed part's units
# (data/datasets/standard/PART.csv) imported into one database; with --run, those parts run or
# resumed there (their unfinished units), each exported again with its provenance and the plan's
# prediction made just before; then the dataset built from every part that has a finished unit and
# exported to data/datasets/standard/standard.csv.
#
#   scripts/standard_dataset.sh [--db FILE] [--run PART]... [--jobs N] [--draglab BIN]
#                               [--run-with BIN] [--allow-mixed-code]
#
# --db: the database (default standard.db; parts already in it are not imported again).
# --run PART: run this part (repeatable; in the order given). Its units are exported to
#   data/datasets/standard/PART.csv when the run ends, also when it ends early (SIGTERM or a
#   failure), so that what finished is kept.
# --draglab BIN: the draglab that imports, exports and builds (default build/cli/draglab).
# --run-with BIN: the draglab that runs the parts (default the --draglab one), e.g. the build of
#   the commit that ran the other parts. The code version of each unit is recorded, and a dataset
#   of parts run by different versions needs --allow-mixed-code (recorded in the dataset's method).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
db="standard.db"
jobs=2
draglab="$root/build/cli/draglab"
runner=""
mixed=()
run=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --db) db="$2"; shift 2 ;;
    --run) run+=("$2"); shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --draglab) draglab="$2"; shift 2 ;;
    --run-with) runner="$2"; shift 2 ;;
    --allow-mixed-code) mixed=(--allow-mixed-code); shift ;;
    *) echo "standard_dataset.sh: unknown option '$1' (--db, --run, --jobs, --draglab, --run-with, --allow-mixed-code)" >&2
       exit 2 ;;
  esac
done
runner="${runner:-$draglab}"
specs="$root/data/campaigns/standard"
units="$root/data/datasets/standard"
for part in "${run[@]}"; do
  [[ -f "$specs/$part.toml" ]] || { echo "standard_dataset.sh: no part '$part' ($specs/$part.toml)" >&2; exit 2; }
done
dl() { "$draglab" --db "$db" "$@"; }
has_campaign() { dl --json campaign status "$1" >/dev/null 2>&1; }

# 1. The committed parts, into the database.
for spec in "$specs"/*.toml; do
  part="$(basename "$spec" .toml)"
  if [[ -f "$units/$part.csv" ]] && ! has_campaign "$part"; then
    dl campaign import "$spec" "$units/$part.csv"
  fi
done

# 2. The parts to run: the plan's prediction, the run, the export (also after an early end).
for part in "${run[@]}"; do
  spec="$specs/$part.toml"
  predicted="$("$runner" --json campaign plan "$spec" --jobs "$jobs" 2>/dev/null |
    /usr/bin/python3 -c 'import json,sys; t=sys.stdin.read(); p=json.JSONDecoder().raw_decode(t[t.index("{"):])[0]; print("%.0f core-seconds, %.1f min on %d workers" % (p["core_seconds"], p["wall_seconds"] / 60, p["jobs"]))')"
  echo "standard_dataset.sh: $part: predicted $predicted" >&2
  command="draglab --db standard.db campaign run data/campaigns/standard/$part.toml --resume --jobs $jobs --threads-per-unit 1 --checkpoint-interval 300"
  rc=0
  "$runner" --db "$db" campaign run "$spec" --resume --jobs "$jobs" --threads-per-unit 1 --checkpoint-interval 300 || rc=$?
  dl campaign export "$part" --csv --provenance \
    --note "Command: $command (this run's units; earlier units came back with campaign import)" \
    --note "Predicted by draglab campaign plan --jobs $jobs just before this run: $predicted (every unit of the part)" \
    --note "Run of $(date -u +%FT%TZ): exit code $rc" \
    --out "$units/$part.csv"
  [[ $rc -eq 0 || $rc -eq 1 ]] || exit "$rc"
done

# 3. The dataset of every part with a finished unit.
parts=()
for spec in "$specs"/*.toml; do
  part="$(basename "$spec" .toml)"
  has_campaign "$part" || continue
  done_units="$(dl --json campaign status "$part" | /usr/bin/python3 -c 'import json,sys; t=sys.stdin.read(); print(json.JSONDecoder().raw_decode(t[t.index("{"):])[0]["units_done"])')"
  [[ "$done_units" -gt 0 ]] && parts+=("$part")
done
id="$(dl --json dataset build "${parts[@]}" --name standard "${mixed[@]}" |
  /usr/bin/python3 -c 'import json,sys; t=sys.stdin.read(); print(json.JSONDecoder().raw_decode(t[t.index("{"):])[0]["id"])')"
{
  echo "# The standard dataset (issue 33): one point per (phi, Re) from the parts in this folder"
  build="dataset build ${parts[*]} --name standard${mixed[*]:+ ${mixed[*]}}"
  listed="$(printf '%s.csv, ' "${parts[@]}")"
  echo "# Command: scripts/standard_dataset.sh (draglab --db standard.db $build, then draglab dataset export $id)"
  echo "# Parts: the campaigns of data/campaigns/standard/ with the same names (their units: ${listed%, })"
  dl dataset export "$id"
} > "$units/standard.csv.tmp"
mv "$units/standard.csv.tmp" "$units/standard.csv"
echo "standard_dataset.sh: dataset $id from ${parts[*]} -> $units/standard.csv" >&2
