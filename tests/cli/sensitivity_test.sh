#!/usr/bin/env bash
# End-to-end test of `draglab sensitivity` and `draglab sensitivity --work-precision`
# (docs/scenes.md, "Sensitivity and work-precision").
#
# Set-up: the tiny DPM scene data/scenes/dpm_tiny.toml with the keys write_scene replaces (a
# deeper bed, a longer jet and run, softer springs, two laws): 3 x 9 x 0.75 cm box, 4 x 12 gas
# cells of 7.5 mm, 2.5 mm glass beads (479 particles, a 3 cm bed at eps_mf = 0.42), a 10 m/s jet
# through a 7.5 mm slot from 0.01 s for 0.03 s, D read 0.05 s after injection (at 0.06 s),
# 0.065 s simulated (the run's duration is rounded to whole gas steps: on the 6 x 18 grid a
# 0.06 s run ends 4.5e-5 s short of t_ref, without its sample). The springs are softer than the
# shipped scenes' (k_n = 1000 N/m: contact time 3.2e-4 s, 2.6 x fewer DEM steps; the deepest
# overlap under the bed's weight is ~1e-3 d and ~0.06 d at 1 m/s impacts) to keep the whole test
# near 40 s. Laws gidaspow@1 and vdh2004@1, packing seeds 5, 6.
# References:
#  a. The JSON is consistent with itself: per law the mean is the mean of the per-run D and the
#     uncertainty is sqrt((s/sqrt(n))^2 + h^2), s the sample standard deviation of the runs and h
#     = max(dx, dy) of the grid, both recomputed here from the per-run values (1e-12 relative:
#     the same arithmetic in double). Seeds 5 and 6 were chosen because gidaspow@1 gives two
#     different D on them (measured 2.39 and 2.54 cm), so the standard-error part is not zero
#     there; on a 4 x 12 grid D moves in whole cells and many seeds give the same value.
#  b. Determinism: gidaspow@1 on the seed-6 packing (settled once, shared by both laws) gives
#     exactly the D and step counts of `draglab scene run` of the same scene with seed = 6 (same
#     settling, same coupled run; the DEM is independent of the thread count, so the numbers are
#     bitwise equal). Its D differs from seed 5's, so a wrong seed would be caught.
#  c. The figures are PNGs (signature), of plausible pixel size (IHDR: 300-6000 px each way) and
#     file size (10 kB - 5 MB); the data hold a snapshot per law with one layer per particle.
#  d. Work-precision on 4x12 and 6x18: two rows, "finest as reference" (two grids cannot give a
#     Richardson estimate), the 6x18 row is the reference (error null) and the other's error is
#     |D - D_ref|; wall times and step counts are positive; the finer grid takes more gas steps.
#  e. A run only reads the database (checksum unchanged); bad input exits 2 before any run and
#     leaves no output folder behind.
#  f. A model with headline numbers (data/scenes/dbm_tiny.toml, the DBM, 5 s runs of about a
#     second): --uncertainty both on one law gives its four headline numbers, each the mean of the
#     two seeds on the 6x15x6 grid with uncertainty sqrt(SE^2 + E^2) recomputed from the per-run
#     values (1e-12 relative); no figure; the table shows the numbers; --beside and --cfl are
#     refused (exit 2), the latter naming --dt; work-precision with --dt takes the finest
#     configuration as the reference of the headline differences.
set -u
draglab="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
db="$work/sens.db"
src="$(cd "$(dirname "$0")/../.." && pwd)"
. "$(dirname "$0")/harness.sh"
. "$src/tests/support/toml_edit.sh"

write_scene() {  # write_scene FILE SEED: data/scenes/dpm_tiny.toml with the keys of the set-up
  toml_edit "$src/data/scenes/dpm_tiny.toml" 'scene.name="sens_tiny"' scene.seed="$2" \
    particles.bed_height_mf_m=0.03 jet.duration_s=0.03 time.duration_s=0.065 time.t_ref_s=0.05 \
    dem.spring_stiffness_n_m=1000.0 'drag.laws=["gidaspow@1", "vdh2004@1"]' >"$1"
}
write_scene "$work/tiny.toml" 5
write_scene "$work/tiny_seed6.toml" 6

have_matplotlib=1
"$py" -c 'import matplotlib' >/dev/null 2>&1 || have_matplotlib=0
figure_flag=""
[ "$have_matplotlib" -eq 1 ] || figure_flag="--no-figure"

check "seed db" 0 "$draglab" --db "$db" law list
db_sum_before="$(md5sum <"$db")"

# Bad input: exit 2, nothing run, no output folder.
sens=("$draglab" -q --db "$db" sensitivity "$work/tiny.toml")
wp=("${sens[@]}" --work-precision --law gidaspow@1)
check "unknown law" 2 "${sens[@]}" --laws gidaspow@1,nosuchlaw@1 --out "$work/bad1"
ok "message names the law" grep -q "nosuchlaw" "$work/err"
check "unknown uncertainty method" 2 "${sens[@]}" --uncertainty bootstrap --out "$work/bad2"
ok "message names the choices" grep -q "realizations, grids or both" "$work/err"
check "one realization" 2 "${sens[@]}" --realizations 1 --out "$work/bad3"
check "bad grid string" 2 "${wp[@]}" --grids 4by12 --out "$work/bad4"
ok "message names --grids" grep -q -- "--grids" "$work/err"
check "grid finer than a particle" 2 "${wp[@]}" --grids 4x12,20x60 --out "$work/bad5"
ok "message names [grid]" grep -q "\[grid\]" "$work/err"
check "contact steps below the stability limit" 2 "${wp[@]}" --contact-steps 10 --out "$work/bad6"
check "a CFL on a dpm scene" 2 "${wp[@]}" --cfl 0.2 --out "$work/bad6b"
ok "the message points to --contact-steps" grep -q -- "use --contact-steps" "$work/err"
check "work-precision without a law" 2 "${sens[@]}" --work-precision --out "$work/bad7"
check "--grids without --work-precision" 2 "${sens[@]}" --grids 4x12 --out "$work/bad8"
check "missing scene file" 2 "$draglab" -q --db "$db" sensitivity "$work/none.toml" --out "$work/bad9"
ok "bad input wrote no output folder" bash -c "! ls -d '$work'/bad* 2>/dev/null"

# Two laws x two realizations.
check "sensitivity --json" 0 "$draglab" --db "$db" sensitivity "$work/tiny.toml" \
  --laws gidaspow@1,vdh2004@1 --out "$work/sens" --json $figure_flag
cp "$work/out" "$work/sens_stdout.json"
ok "stdout is JSON only" "$py" -c "import json, sys; json.load(open(sys.argv[1]))" "$work/sens_stdout.json"
pycheck "sensitivity data: fields, mean and uncertainty recomputed" '
import json, math, sys
w = sys.argv[1]
s = json.load(open(w + "/sens/sensitivity.json"))
out = json.load(open(w + "/sens_stdout.json"))
assert s["format"] == "draglab_sensitivity" and s["version"] == 1, s["format"]
assert s["uncertainty"]["method"] == "realizations", s["uncertainty"]
assert [p["seed"] for p in s["packings"]] == [5, 6], s["packings"]
assert all(p["particles"] == 479 and p["settle_wall_s"] > 0 for p in s["packings"]), s["packings"]
assert [l["law"] for l in s["laws"]] == ["gidaspow@1", "vdh2004@1"]
h = max(0.03 / 4, 0.09 / 12)
for law, printed in zip(s["laws"], out["laws"]):
    for key in ("umf_m_s", "background_m_s", "background", "d_mean_m", "d_estimate_m",
                "uncertainty_m", "spread_m", "boundary_m", "bubbles_found", "runs", "wall_s"):
        assert key in law, key
        assert printed[key] == law[key], (key, printed[key], law[key])
    assert "snapshot" not in printed  # stdout leaves the bulky snapshots to the file
    runs = law["runs"]
    assert [r["seed"] for r in runs] == [5, 6], runs
    d = [r["bubble_diameter_m"] for r in runs]
    assert all(r["bubble_found"] == (r["bubble_diameter_m"] > 0) for r in runs), runs
    assert all(r["reached_t_ref"] for r in runs), runs
    assert all(r["wall_s"] > 0 and r["gas_steps"] > 0 and r["dem_steps"] > r["gas_steps"] for r in runs)
    assert all(abs(r["cell_size_m"] - h) < 1e-15 for r in runs), runs
    # Each run carries its bubble time series; the sample nearest t_ref holds its D.
    for r in runs:
        ts = r["series"]
        t = ts["t_s"]
        assert len(t) >= 3 and all(b > a for a, b in zip(t, t[1:])), t
        assert all(len(ts[k]) == len(t) for k in ("bubble_diameter_m", "bubble_centroid_m", "bed_height_m"))
        i = min(range(len(t)), key=lambda k: abs(t[k] - s["t_ref_s"]))
        assert ts["bubble_diameter_m"][i] == r["bubble_diameter_m"], (ts["bubble_diameter_m"][i], r)
    n = len(d)
    mean = sum(d) / n
    se = math.sqrt(sum((x - mean) ** 2 for x in d) / (n - 1) / n)
    assert se == 0 or abs(se - abs(d[0] - d[1]) / 2) < 1e-12 * se
    total = math.sqrt(se ** 2 + h ** 2)
    assert abs(law["d_mean_m"] - mean) <= 1e-12 * max(mean, 1e-300), (law["d_mean_m"], mean)
    assert law["d_estimate_m"] == law["d_mean_m"]
    assert abs(law["uncertainty_m"] - total) <= 1e-12 * total, (law["uncertainty_m"], total)
    assert abs(law["boundary_m"] - h) < 1e-15
    assert abs(sum(r["wall_s"] for r in runs) - law["wall_s"]) < 1e-9
    # Each law at its own U_mf (umf background): vdh2004 above gidaspow (1.650 vs 1.336 m/s).
    assert law["background"] == "umf" and law["background_m_s"] == law["umf_m_s"]
    snap = law["snapshot"]
    assert snap is not None and law["has_snapshot"]
    assert len(snap["x"]) == len(snap["y"]) == len(snap["layer"]) == len(snap["diameter"]) == 479
    assert set(snap["layer"]) == set(range(snap["layers"])), set(snap["layer"])
    f = snap["void_fraction"]
    assert f["nx"] == 4 and f["ny"] == 12 and len(f["values"]) == 48
    assert all(0 < e <= 1 for e in f["values"])
    assert snap["bubble"]["found"] == runs[0]["bubble_found"]
    if runs[0]["bubble_found"]:
        assert abs(snap["bubble"]["diameter_m"] - runs[0]["bubble_diameter_m"]) < 1e-15
umf = {l["law"]: l["umf_m_s"] for l in s["laws"]}
assert abs(umf["gidaspow@1"] - 1.336) < 0.001 and abs(umf["vdh2004@1"] - 1.650) < 0.001, umf
'
ok "sensitivity only read the database" test "$(md5sum <"$db")" = "$db_sum_before"

# Determinism: the same law and seed through `scene run`.
check "scene run gidaspow@1 seed 6" 0 "$draglab" -q --db "$db" scene run "$work/tiny_seed6.toml" \
  --law gidaspow@1 --json
cp "$work/out" "$work/run_seed6.json"
pycheck "sensitivity run == scene run (same law, same seed)" '
import json, sys
w = sys.argv[1]
s = json.load(open(w + "/sens/sensitivity.json"))
r = json.load(open(w + "/run_seed6.json"))
run = [l for l in s["laws"] if l["law"] == "gidaspow@1"][0]["runs"][1]
assert run["seed"] == 6
expected = r["bubble_diameter_m"] if r["bubble_diameter_m"] is not None else 0.0
assert run["bubble_diameter_m"] == expected, (run["bubble_diameter_m"], expected)
assert run["gas_steps"] == r["gas_steps"] and run["dem_steps"] == r["dem_steps"], (run, r)
# One run: its uncertainty is the boundary bound, one cell, the same h the sensitivity uses.
if r["bubble_diameter_m"] is not None:
    assert r["numerical_uncertainty"] == run["cell_size_m"], (r["numerical_uncertainty"], run)
else:
    assert r["numerical_uncertainty"] is None, r
assert "sensitivity" in r["numerical_uncertainty_method"], r
'

# `scene run` stores its result (scene text, law content hash, metrics) unless --no-store.
export SENSITIVITY_TEST_DB="$db"
pycheck "scene run stored one consumer result with its metrics" '
import json, os, sqlite3, sys
w, db = sys.argv[1], os.environ["SENSITIVITY_TEST_DB"]
r = json.load(open(w + "/run_seed6.json"))
assert isinstance(r["result_id"], int) and r["result_id"] > 0, r["result_id"]
con = sqlite3.connect(db)
rows = con.execute("SELECT law_name, law_version, metrics_json FROM consumer_results WHERE id = ?",
                   (r["result_id"],)).fetchall()
assert len(rows) == 1 and rows[0][:2] == ("gidaspow", 1), rows
m = json.loads(rows[0][2])
expected = r["bubble_diameter_m"]
assert m["bubble_diameter_m"] == expected and abs(m["umf_m_s"] - r["umf_m_s"]) < 1e-15, (m, r)
'
db_sum_before_nostore="$(md5sum <"$db")"
check "scene run --no-store" 0 "$draglab" -q --db "$db" scene run "$work/tiny_seed6.toml" \
  --law gidaspow@1 --json --no-store
ok "--no-store left the database unchanged" test "$(md5sum <"$db")" = "$db_sum_before_nostore"
pycheck "--no-store reports no result id" '
import json, sys
assert json.load(open(sys.argv[1] + "/out"))["result_id"] is None
'

png_check='
import struct, sys
path = sys.argv[1] + "/" + sys.argv[2]
data = open(path, "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
assert data[12:16] == b"IHDR"
width, height = struct.unpack(">II", data[16:24])
assert 300 <= width <= 6000 and 300 <= height <= 6000, (width, height)
assert 10e3 <= len(data) <= 5e6, len(data)
'
if [ "$have_matplotlib" -eq 1 ]; then
  ok "fig4.png is a plausible PNG" "$py" -c "$png_check" "$work" sens/fig4.png
  ok "bubble_series.png is a plausible PNG" "$py" -c "$png_check" "$work" sens/bubble_series.png
  ok "stdout names the figure" grep -q '"figure": ".*fig4.png"' "$work/sens_stdout.json"
else
  echo "note: /usr/bin/python3 has no matplotlib; figures not checked"
fi

# Work-precision: two grids, one DEM step; the table on stdout, the numbers from the data file.
check "work-precision table" 0 "$draglab" --db "$db" sensitivity "$work/tiny.toml" \
  --work-precision --law gidaspow@1 --grids 4x12,6x18 --contact-steps 20 --out "$work/wp" $figure_flag
ok "table states the reference" grep -q "finest as reference" "$work/out"
ok "table has both grids" bash -c "grep -q ' 4x12 ' '$work/out' && grep -q ' 6x18 ' '$work/out'"
pycheck "work-precision rows and reference" '
import json, sys
w = sys.argv[1]
j = json.load(open(w + "/wp/work_precision.json"))
assert j["format"] == "draglab_work_precision" and j["law"] == "gidaspow@1"
rows = j["rows"]
assert [(r["cells_x"], r["cells_y"], r["contact_steps"]) for r in rows] == [(4, 12, 20), (6, 18, 20)], rows
assert j["reference_method"] == "finest as reference", j["reference_method"]
assert not rows[0]["is_reference"] and rows[1]["is_reference"] and rows[1]["error_m"] is None
assert j["reference_diameter_m"] == rows[1]["bubble_diameter_m"]
d0, d1 = rows[0]["bubble_diameter_m"], rows[1]["bubble_diameter_m"]
assert abs(rows[0]["error_m"] - abs(d0 - d1)) < 1e-15, (rows[0]["error_m"], d0, d1)
assert abs(rows[0]["cell_size_m"] - 0.0075) < 1e-15 and abs(rows[1]["cell_size_m"] - 0.005) < 1e-15
assert all(r["wall_s"] > 0 and r["dem_steps"] > 0 and r["reached_t_ref"] for r in rows), rows
assert rows[1]["gas_steps"] > rows[0]["gas_steps"], rows
'
if [ "$have_matplotlib" -eq 1 ]; then
  ok "work_precision.png is a plausible PNG" "$py" -c "$png_check" "$work" wp/work_precision.png
fi
# A model with headline numbers: the DBM (reference f).
dbm=("$draglab" -q --db "$db" sensitivity "$src/data/scenes/dbm_tiny.toml" --duration 5)
check "dbm: --cfl on a dbm scene" 2 "${dbm[@]}" --work-precision --law gidaspow@1 --cfl 0.3 --out "$work/badd1"
ok "the message points to --dt" grep -q -- "use --dt" "$work/err"
check "dbm: a grid with no depth cells" 2 "${dbm[@]}" --work-precision --law gidaspow@1 --grids 4x10x0 --out "$work/badd2"
ok "message names --grids" grep -q -- "--grids" "$work/err"
check "dbm sensitivity both --json" 0 "${dbm[@]}" --laws gidaspow@1 --uncertainty both --out "$work/dbm" --json
pycheck "dbm: headline numbers with their uncertainty, no figure" '
import json, math, statistics, sys
w = sys.argv[1]
out = json.load(open(w + "/out"))
s = json.load(open(w + "/dbm/sensitivity.json"))
assert out["figure"] is None, out["figure"]
assert s["uncertainty"]["method"] == "both" and s["uncertainty"]["grids"] == [[4, 10, 4], [6, 15, 6]], s["uncertainty"]
names = ["holdup", "mean_diameter_at_0.3_m", "mean_diameter_at_0.7_m", "circulation_upflow_m_s"]
assert s["headline_names"] == names, s["headline_names"]
law = s["laws"][0]
runs = law["runs"]
assert [(r["seed"], r["cells_z"]) for r in runs] == [(1, 4), (1, 6), (2, 4), (2, 6)], runs
r = runs[0]["cell_size_m"] / runs[1]["cell_size_m"]
for h in law["headline"]:
    fine = [x["headline"][h["name"]] for x in runs[1::2]]
    coarse = [x["headline"][h["name"]] for x in runs[0::2]]
    assert h["per_run"] == [x["headline"][h["name"]] for x in runs], h
    se = statistics.stdev(fine) / math.sqrt(len(fine))
    grid = abs(statistics.mean(fine) - statistics.mean(coarse)) / (r - 1)
    for got, want in ((h["estimate"], statistics.mean(fine)), (h["spread"], se), (h["grid"], grid),
                      (h["uncertainty"], math.hypot(se, grid))):
        assert abs(got - want) <= 1e-12 * abs(h["estimate"]), (h["name"], got, want)
    assert math.isfinite(h["uncertainty"])
assert law["headline"][0]["uncertainty"] > 0, law["headline"][0]
'
check "dbm sensitivity table" 0 "${dbm[@]}" --laws gidaspow@1,bvk2007@1 --out "$work/dbm2"
ok "the table shows the hold-up" grep -q "holdup .* +- " "$work/out"
ok "and the circulation" grep -q "circulation_upflow_m_s" "$work/out"
ok "no figure for a headline model" bash -c "! ls '$work'/dbm2/*.png 2>/dev/null"
check "dbm: --beside refused" 2 "${dbm[@]}" --laws gidaspow@1 --out "$work/dbm3" --beside "$work/dbm/sensitivity.json"
check "dbm work-precision" 0 "${dbm[@]}" --work-precision --law gidaspow@1 --grids 4x10 --dt 1e-2,5e-3 --out "$work/dbmwp" --json
pycheck "dbm work-precision: the finest step is the reference" '
import json, sys
j = json.load(open(sys.argv[1] + "/out"))
assert j["time_resolution_name"] == "dt_s" and j["reference_method"] == "finest as reference", j
rows = j["rows"]
assert [(r["cells_z"], r["dt_s"], r["is_reference"]) for r in rows] == [(4, 0.01, False), (4, 0.005, True)], rows
for name, ref in j["reference_headline"].items():
    assert rows[1]["headline_difference"][name] is None
    assert abs(rows[0]["headline_difference"][name] - (rows[0]["headline"][name] - ref)) < 1e-15
'
finish "cli.sensitivity"
