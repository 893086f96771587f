#!/usr/bin/env bash
# End-to-end test of `draglab scene umf` and `draglab scene check` on the shipped scenes.
# Reference: U_mf of the seed's particles at eps_mf = 0.42 from consumers.md section 2.1 (copied
# in data/umf_reference.csv): Ergun 1.34, Koch-Hill 1.49, Beetstra 1.46 m/s (3 digits, +-0.006);
# ~35 100 particles in the seed bed. Bad input (unknown file, bad scene, unknown law, a law whose
# validity box the bed leaves) exits 2.
set -u
draglab="$1"
src="$(cd "$(dirname "$0")/../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
db="$work/scene.db"
. "$(dirname "$0")/harness.sh"

check "scene umf --json" 0 "$draglab" --db "$db" scene umf "$src/data/scenes/dpm_bubble.toml" --json
cp "$work/out" "$work/umf.json"
pycheck "U_mf per law matches the reference notes" '
import json, sys
r = json.load(open(sys.argv[1] + "/umf.json"))
got = {row["law"]: row for row in r["laws"]}
for law in ("gidaspow@1", "ergun@1", "hill_koch_ladd@1", "vdh2004@1", "bvk2007@1"):
    assert law in got, law
for law, umf in (("ergun@1", 1.34), ("hill_koch_ladd@1", 1.49), ("bvk2007@1", 1.46)):
    assert abs(got[law]["umf_m_s"] - umf) < 0.006, (law, got[law])
    assert got[law]["eps_mf"] == 0.42
    assert abs(got[law]["re_mf"] - got[law]["umf_m_s"] * 1.2 * 2.5e-3 / 1.8e-5) < 1e-6 * got[law]["re_mf"]
'
check "scene umf --law table" 0 "$draglab" --db "$db" scene umf "$src/data/scenes/dpm_bubble_quick.toml" --law ergun@1
ok "table names the law" grep -q "ergun@1" "$work/out"
check "scene check --json" 0 "$draglab" --db "$db" scene check "$src/data/scenes/dpm_bubble.toml" --json
cp "$work/out" "$work/check.json"
pycheck "derived numbers of the seed scene" '
import json, sys
r = json.load(open(sys.argv[1] + "/check.json"))
assert abs(r["particle_count"] - 35100) < 60, r["particle_count"]
assert abs(r["contact_time_s"] - 1.21e-4) < 0.006e-4, r["contact_time_s"]
assert r["recommended_dem_dt_s"] <= r["contact_time_s"] / 20 * (1 + 1e-12)
# Davidson-Harrison leakage size D* = q/(pi U_mf) of the 13 m/s x 1 cm jet (consumers.md 2.3):
# 2.5 cm (vdh2004, U_mf 1.65 m/s) to 3.1 cm (Ergun, 1.34 m/s); the jet was chosen from measured
# DPM bubbles (docs/dpm.md), which D* underestimates 2.5-3x.
import math
for row in r["laws"]:
    assert abs(row["leakage_bubble_diameter_m"] - 0.13 / (math.pi * row["umf_m_s"])) < 1e-9, row
    assert 0.024 <= row["leakage_bubble_diameter_m"] <= 0.032, row
    assert row["recommended_gas_dt_s"] > 0
'
check "scene check table" 0 "$draglab" --db "$db" scene check "$src/data/scenes/dpm_bubble_quick.toml"

# Bad input: exit 2 with the field named.
check "missing scene file" 2 "$draglab" --db "$db" scene check "$work/none.toml"
sed 's/^slot_width_m = 0.01/slot_width_m = 0.2/' "$src/data/scenes/dpm_bubble.toml" >"$work/wide_jet.toml"
check "jet wider than the bed" 2 "$draglab" --db "$db" scene check "$work/wide_jet.toml"
ok "message names slot_width_m" grep -q "slot_width_m" "$work/err"
sed 's/^density_kg_m3 = 2526.0/density_kg_m3 = -2526.0/' "$src/data/scenes/dpm_bubble.toml" >"$work/neg.toml"
check "negative density" 2 "$draglab" --db "$db" scene umf "$work/neg.toml"
ok "message names density_kg_m3" grep -q "density_kg_m3" "$work/err"
sed 's/^bed_height_mf_m = 0.22/bed_height_mf_m = 0.5/' "$src/data/scenes/dpm_bubble.toml" >"$work/tall.toml"
check "bed that does not fit" 2 "$draglab" --db "$db" scene check "$work/tall.toml"
printf '[scene]\nname = "x"\ncolour = "red"\n' >"$work/unknown.toml"
check "unknown key" 2 "$draglab" --db "$db" scene check "$work/unknown.toml"
ok "message names the key" grep -q "colour" "$work/err"
check "unknown law" 2 "$draglab" --db "$db" scene umf "$src/data/scenes/dpm_bubble.toml" --law nosuchlaw@1
check "law outside its validity box" 2 "$draglab" --db "$db" scene umf "$src/data/scenes/dpm_bubble.toml" --law wen_yu@1
ok "message names the validity range" grep -q "validity" "$work/err"
sed 's/^dem_dt_s = 0.0/dem_dt_s = 1e-4/' "$src/data/scenes/dpm_bubble.toml" >"$work/dt.toml"
check "DEM step above the stability limit" 2 "$draglab" --db "$db" scene check "$work/dt.toml"
check "missing scene argument" 2 "$draglab" --db "$db" scene umf
finish "cli.scene"
