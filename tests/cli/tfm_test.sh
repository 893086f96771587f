#!/usr/bin/env bash
# End-to-end test of the two-fluid model through the command line (docs/tfm.md): the tiny TFM
# scene tests/cli/data/tfm_tiny.toml (6 x 20 cells, well under a second per run) through
# `scene check`, `scene run` (stored result, JSON naming the model and its conservation),
# `regress register|run` (exactly as on DPM scenes: the baseline is reused, a new law version is
# compared), `sensitivity` (two grids, the figures) and the bad input of the [tfm] table, each
# exiting 2 with the field named and nothing stored.
set -u
draglab="$1"
src="$(cd "$(dirname "$0")/../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
db="$work/tfm.db"
scene="$src/tests/cli/data/tfm_tiny.toml"
. "$(dirname "$0")/harness.sh"

results() {
  "$py" -c '
import sqlite3, sys
c = sqlite3.connect("file:" + sys.argv[1] + "?mode=ro", uri=True)
print(c.execute("SELECT count(*) FROM consumer_results").fetchone()[0])
' "$db"
}

check "scene check" 0 "$draglab" --db "$db" scene check "$scene"
ok "check names the two-fluid model" grep -q "solver tfm" "$work/out"
ok "check reports the model's own settings" grep -q "two-fluid: .* closures, .*solids pressure explicit" "$work/out"
check "scene check --json" 0 "$draglab" --db "$db" scene check "$scene" --json
pycheck "check JSON: the TFM's step control, no DEM contact time" '
import json, sys
r = json.load(open(sys.argv[1] + "/out"))
assert r["solver"] == "tfm" and r["cfl"] > 0 and r["dt_max_s"] > 0, r
assert "contact_time_s" not in r, r
'
# The shipped two-fluid scenes, the OpenFOAM benchmark's included, stay valid.
for shipped in "$src/data/scenes/tfm_bubble.toml" "$src/data/scenes/tfm_kuipers_jet.toml" \
               "$src/bench/openfoam/fluidised_bed.toml"; do
  check "scene check $(basename "$shipped")" 0 "$draglab" --db "$db" scene check "$shipped"
done
check "scene run" 0 "$draglab" --db "$db" scene run "$scene" --json
pycheck "run result: model, bubble, conservation" '
import json, sys
r = json.load(open(sys.argv[1] + "/out"))
assert r["model"] == "tfm" and r["solver"] == "tfm", r["model"]
assert r["bubble_at_t_ref"] and r["bubble_diameter_m"] > 0.01, r["bubble_diameter_m"]
assert abs(r["relative_solids_mass_change"]) < 1e-12, r["relative_solids_mass_change"]
assert r["max_relative_gas_mass_imbalance"] < 1e-12
assert r["max_solids_fraction"] <= r["closures"]["packing_limit"] + 1e-12
assert r["steps"] > 0 and r["dt_min_s"] > 0 and r["steps_by_limit"]
assert r["result_id"] is not None
'

# Field files (HDF5 + XDMF) every 20 ms: the two phases' fields, eps + phi = 1, one group per
# output time; particles are refused (a continuum has none).
sed "s|^range_policy = \"clamp\"|range_policy = \"clamp\"\n\n[outputs]\nfields = true\ninterval_s = 0.02\ndirectory = \"$work/fields\"|" "$scene" >"$work/fields.toml"
check "scene run with fields" 0 "$draglab" --db "$db" scene run "$work/fields.toml" --no-store --json
pycheck "field files" '
import glob, json, sys
import h5py, numpy as np
work = sys.argv[1]
r = json.load(open(work + "/out"))
assert any(f.endswith(".h5") for f in r["output_files"]) and any(f.endswith(".xmf") for f in r["output_files"]), r["output_files"]
with h5py.File(glob.glob(work + "/fields/*.h5")[0], "r") as f:
    groups = sorted(k for k in f.keys() if k.startswith("t"))
    assert len(groups) == 4, groups
    g = f[groups[-1]]
    for name in ("eps", "phi", "p", "u_x", "u_z", "v_x", "v_z", "theta", "beta"):
        assert g[name].shape == (1, 20, 6), (name, g[name].shape)
    assert np.allclose(g["eps"][...] + g["phi"][...], 1.0, atol=1e-15)
    assert (g["theta"][...] >= 0).all()
xmf = open(glob.glob(work + "/fields/*.xmf")[0]).read()
assert xmf.count("Name=\"theta\"") == 4, xmf.count("theta")
'
sed 's/^range_policy = "clamp"/range_policy = "clamp"\n\n[outputs]\nparticles = true/' "$scene" >"$work/particles.toml"
check "particles output refused" 2 "$draglab" --db "$db" scene run "$work/particles.toml" --no-store
ok "particles output named" grep -q "\[outputs\] particles" "$work/err"

# Bad input: exit 2 naming the field, nothing stored.
before="$(results)"
sed 's/^solver = "tfm"/solver = "tfmx"/' "$scene" >"$work/bad_solver.toml"
check "unknown solver" 2 "$draglab" --db "$db" scene run "$work/bad_solver.toml"
ok "unknown solver named" grep -q "tfmx" "$work/err"
awk '/^\[tfm\]/{skip=1; next} /^\[/{skip=0} !skip' "$scene" >"$work/no_tfm.toml"
check "missing [tfm]" 2 "$draglab" --db "$db" scene run "$work/no_tfm.toml"
ok "missing [tfm] named" grep -q "\[tfm\] table is missing" "$work/err"
sed 's/^closures = "nieuwland"/closures = "nieuwland"\nrestitution = 1.2/' "$scene" >"$work/bad_e.toml"
check "restitution out of range" 2 "$draglab" --db "$db" scene run "$work/bad_e.toml"
ok "restitution named" grep -q "\[tfm\] restitution" "$work/err"
sed 's/^packing_limit = 0.64/packing_limit = 0.57/' "$scene" >"$work/bad_packing.toml"
check "packing limit below the bed" 2 "$draglab" --db "$db" scene run "$work/bad_packing.toml"
ok "packing limit named" grep -q "\[tfm\] packing_limit" "$work/err"
sed 's/^closures = "nieuwland"/closures = "nieuwland"\ntheta_initial_m2_s2 = -0.1/' "$scene" >"$work/bad_theta.toml"
check "negative theta" 2 "$draglab" --db "$db" scene run "$work/bad_theta.toml"
ok "theta named" grep -q "\[tfm\] theta_initial_m2_s2" "$work/err"
sed 's/^t_ref_s = 0.05/t_ref_s = 0.05\ngas_dt_s = 0.002/' "$scene" >"$work/bad_dt.toml"
check "time step above the stability limit" 2 "$draglab" --db "$db" scene run "$work/bad_dt.toml"
ok "time step named" grep -q "gas_dt_s" "$work/err"
ok "nothing stored by bad input" [ "$(results)" = "$before" ]

# regress on a TFM scene, exactly as on a DPM scene.
check "regress register" 0 "$draglab" --db "$db" regress register "$scene" --law ergun@1 --json
check "regress run" 0 "$draglab" --db "$db" regress --law ergun@1 --json
pycheck "regress: ergun@1 ok on the tfm scene, its stored result reused" '
import json, sys
r = json.load(open(sys.argv[1] + "/out"))
e = [x for x in r["entries"] if x["law"] == "ergun@1"]
assert e and e[0]["outcome"] == "ok" and not e[0]["ran"], r
assert r["runs"] == 0, r["runs"]
'

# sensitivity: two grids (a continuum model has no packing realizations), figures.
check "sensitivity" 0 "$draglab" --db "$db" sensitivity "$scene" --laws ergun@1,vdh2004@1 --out "$work/sens" --json
pycheck "sensitivity: two grids per law" '
import json, sys
r = json.load(open(sys.argv[1] + "/out"))
assert r["uncertainty"]["method"] == "grids", r["uncertainty"]
for law in r["laws"]:
    assert len(law["runs"]) == 2 and law["uncertainty_m"] > 0, law
'
if "$py" -c 'import matplotlib' 2>/dev/null; then
  ok "fig4.png written" [ -s "$work/sens/fig4.png" ]
  ok "bubble_series.png written" [ -s "$work/sens/bubble_series.png" ]
  check "sensitivity --beside" 0 "$draglab" --db "$db" sensitivity "$scene" --laws ergun@1 --out "$work/sens2" --beside "$work/sens/sensitivity.json"
  ok "fig5.png written" [ -s "$work/sens2/fig5.png" ]
fi
check "--realizations on a deterministic model" 2 "$draglab" --db "$db" sensitivity "$scene" --realizations 4
ok "the message says why" grep -q "deterministic" "$work/err"
check "--beside a missing file" 2 "$draglab" --db "$db" sensitivity "$scene" --beside "$work/none.json"
check "work-precision contact steps on a tfm scene" 2 "$draglab" --db "$db" sensitivity "$scene" --work-precision --law ergun@1 --grids 6x20,9x30 --contact-steps 20,40
check "work-precision a CFL above 0.5" 2 "$draglab" --db "$db" sensitivity "$scene" --work-precision --law ergun@1 --cfl 0.3,0.7
ok "the CFL message names the field" grep -q "\[tfm\] cfl" "$work/err"
check "work-precision" 0 "$draglab" --db "$db" sensitivity "$scene" --work-precision --law ergun@1 --grids 6x20,9x30 --cfl 0.3,0.15 --out "$work/wp" --json
pycheck "work-precision rows: grids x CFL, the smaller CFL taking more steps" '
import json, sys
r = json.load(open(sys.argv[1] + "/out"))
assert r["time_resolution_name"] == "cfl", r["time_resolution_name"]
rows = r["rows"]
assert [(x["cells_x"], x["cfl"]) for x in rows] == [(6, 0.3), (6, 0.15), (9, 0.3), (9, 0.15)], rows
assert all(x["wall_s"] >= 0 and x["gas_steps"] > 0 and x["dem_steps"] == 0 for x in rows), rows
for coarse, fine in ((rows[0], rows[1]), (rows[2], rows[3])):
    assert fine["gas_steps"] > 1.5 * coarse["gas_steps"], (coarse, fine)
ref = [x for x in rows if x["is_reference"]]
assert len(ref) == 1 and ref[0]["cells_x"] == 9 and ref[0]["cfl"] == 0.15, ref
'
finish cli.tfm
