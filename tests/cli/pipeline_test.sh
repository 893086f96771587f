#!/usr/bin/env bash
# End-to-end test of `draglab pipeline` (campaign -> dataset -> fit -> published law -> report) on
# a tiny campaign: 3 phi x 3 Re (0, 4, 10), one 8-sphere packing per phi, d = 8 (a few seconds).
# Checks: exit 0 and the JSON fields the issue asks for; 9 units done; the law is published
# (immutable) with the dataset in its provenance; the dataset's F values are the campaign's
# (Stokes F grows with phi, as every drag law says); re-running resumes (no new unit, same
# dataset id) and reuses the identical law version instead of adding one; a bad spec exits 2
# and writes nothing.
# The pipeline ends with the regression check of the law it published (--regress-scene): the
# tiny DPM scene of data/scenes/dpm_tiny.toml with a gas 100 times as viscous as air and
# eps_mf = 0.7, so that the bed at minimum fluidization (phi = 0.3, Re_mf ~ 1) lies inside the
# validity box of a law fitted to this campaign (phi 0.15-0.35, Re 0-10); one DPM run of ~2 s.
# The first run registers eq6_tiny@1 as the scene's baseline (exit 0), the re-run compares the
# same version with it from the stored result (ok, no run), --no-regress skips the check, and a
# baseline that eq6_tiny@1 does not match (below) makes the pipeline exit 1; a missing or invalid
# --regress-scene exits 2 before the campaign, writing nothing.
set -u
draglab="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
db="$work/p.db"
src="$(cd "$(dirname "$0")/../.." && pwd)"
. "$(dirname "$0")/harness.sh"
. "$src/tests/support/toml_edit.sh"
cp "$src/tests/support/data/tiny_campaign.toml" "$work/tiny.toml"

toml_edit "$src/data/scenes/dpm_tiny.toml" gas.viscosity_pa_s=1.8e-3 drag.eps_mf=0.7 \
  'scene.name="dpm_tiny_viscous"' >"$work/viscous.toml"

check "pipeline" 0 "$draglab" --db "$db" pipeline --spec "$work/tiny.toml" --out "$work/report" \
  --regress-scene "$work/viscous.toml" --json
cp "$work/out" "$work/first.json"
pycheck "pipeline ends with the check: baseline registered" '
import json, sys
r = json.load(open(sys.argv[1] + "/first.json"))
g = r["regress"]
assert g["baselines_registered"] == 1 and g["moved"] == 0 and g["failed"] == 0, g
e = g["entries"][0]
assert e["law"] == "eq6_tiny@1" and e["scene"] == "dpm_tiny_viscous", e
assert e["outcome"] == "baseline_registered" and e["ran"], e
assert 0 < e["metrics"]["umf_m_s"] < 1, e["metrics"]
'
pycheck "pipeline JSON" '
import json, os, sys
w = sys.argv[1]
r = json.load(open(w + "/first.json"))
for key in ("law", "version", "params", "ci95", "rms_rel_err", "max_rel_err", "dataset",
            "comparison", "units_total", "units_done", "wall_s"):
    assert key in r, key
assert r["law"] == "eq6_tiny" and r["version"] == 1, r
assert r["units_total"] == 9 and r["units_done"] == 9 and r["units_failed"] == 0, r
# Nine points at Re <= 10 do not determine all five C0/C1 coefficients: the fit says which and
# fits the largest determined subset, each interval narrower than its value.
s = r["selection"]
assert s["requested"] == ["k0", "k1", "c10", "c11", "c12"], s
assert s["performed"] and s["undetermined"] and s["least_separable"], s
assert set(r["ci95"]) == set(s["chosen"]) and 0 < len(s["chosen"]) < 5, (r["ci95"], s)
assert r["undetermined"] == [], r["undetermined"]
for k, (lo, hi) in r["ci95"].items():
    assert lo <= r["params"][k] <= hi, k
    assert (hi - lo) / 2 < abs(r["params"][k]), (k, lo, hi)
assert 0 <= r["rms_rel_err"] <= r["max_rel_err"] < 0.5, r
laws = [c["law"] for c in r["comparison"]]
assert any(l.startswith("vdh2004@1") for l in laws) and any(l.startswith("bvk2007@1") for l in laws)
assert os.path.exists(r["report"]) and r["report"].endswith("report.md"), r["report"]
'
check "law show" 0 "$draglab" --db "$db" law show eq6_tiny@1 --json
pycheck "published with provenance" '
import json, sys
w = sys.argv[1]
law = json.load(open(w + "/out")); first = json.load(open(w + "/first.json"))
text = json.dumps(law)
assert "published" in text and "fitted" in text and first["dataset"] in text, text[:600]
'
check "dataset show" 0 "$draglab" --db "$db" dataset show "$(
  "$py" -c 'import json,sys; print(json.load(open(sys.argv[1]))["dataset"])' "$work/first.json")" --json
pycheck "Stokes F grows with phi" '
import json, sys
d = json.load(open(sys.argv[1] + "/out"))
pts = d["points"] if "points" in d else d["dataset"]["points"]
stokes = sorted((p["phi"], p["F"]) for p in pts if p["re_target"] == 0)
assert len(stokes) == 3, stokes
assert stokes[0][1] < stokes[1][1] < stokes[2][1], stokes
'

check "pipeline again" 0 "$draglab" --db "$db" pipeline --spec "$work/tiny.toml" --out "$work/report" \
  --regress-scene "$work/viscous.toml" --json
pycheck "re-run resumes and reuses" '
import json, sys
w = sys.argv[1]
a = json.load(open(w + "/first.json")); b = json.load(open(w + "/out"))
assert b["version"] == 1 and b["dataset"] == a["dataset"], (a["version"], b["version"])
assert b["params"] == a["params"]
e = b["regress"]["entries"][0]
assert e["outcome"] == "ok" and not e["ran"] and e["baseline"] == "eq6_tiny@1", e
'
check "pipeline --no-regress" 0 "$draglab" --db "$db" pipeline --spec "$work/tiny.toml" --no-report --no-regress --json
pycheck "no check" '
import json, sys
assert json.load(open(sys.argv[1] + "/out"))["regress"] is None
'
check "still one version" 0 "$draglab" --db "$db" law list --json
pycheck "one eq6_tiny version" '
import json, sys
laws = json.load(open(sys.argv[1] + "/out"))
laws = laws["laws"] if isinstance(laws, dict) else laws
assert sum(1 for l in laws if l["name"] == "eq6_tiny") == 1
'

# A moved prediction makes the pipeline exit 1: a refit of only k0 (eq6_tiny@2, other
# coefficients as printed) becomes the scene's baseline with a U_mf tolerance of 0, so the
# re-run's eq6_tiny@1, whose U_mf differs, has moved.
dataset_id="$("$py" -c 'import json,sys; print(json.load(open(sys.argv[1]))["dataset"])' "$work/first.json")"

# Export to stdout (a pipe, not a file to rename over) and to a file carry the provenance header;
# re-importing either into a fresh database reproduces the dataset id.
check "dataset export to stdout" 0 "$draglab" --db "$db" dataset export "$dataset_id"
cp "$work/out" "$work/exported.csv"
check "dataset export --out" 0 "$draglab" --db "$db" dataset export "$dataset_id" --out "$work/file.csv"
ok "stdout and file exports agree" cmp -s "$work/exported.csv" "$work/file.csv"
ok "the export names the campaign spec hash" grep -q "^# campaign tiny (id 1), spec hash [0-9a-f]\{64\}" "$work/exported.csv"
ok "the export names the code version" grep -q "^# built .* by draglab " "$work/exported.csv"
check "dataset import into a fresh database" 0 "$draglab" --db "$work/fresh.db" dataset import "$work/exported.csv" --json
pycheck "re-import reproduces the dataset id" "
import json, sys
assert json.load(open(sys.argv[1] + '/out'))['id'] == '$dataset_id'
"
check "refit eq6_tiny@2" 0 "$draglab" --db "$db" -q fit --dataset "$dataset_id" --free k0 --cv 0 --no-global \
  --publish eq6_tiny
check "publish eq6_tiny@2" 0 "$draglab" --db "$db" -q law publish eq6_tiny@2
check "baseline eq6_tiny@2, U_mf tolerance 0" 0 "$draglab" --db "$db" regress register "$work/viscous.toml" \
  --law eq6_tiny@2 --replace --tol-umf-rel 0
check "pipeline reports the moved prediction" 1 "$draglab" --db "$db" pipeline --spec "$work/tiny.toml" \
  --no-report --regress-scene "$work/viscous.toml"
ok "the summary says PREDICTION MOVED" grep -q "PREDICTION MOVED: eq6_tiny@1" "$work/out"
ok "the error names the move" grep -q "eq6_tiny@1 on dpm_tiny_viscous vs eq6_tiny@2 (umf_m_s" "$work/err"

before="$(md5sum "$db" | cut -d" " -f1)"
sed 's/phi = \[0.15, 0.25, 0.35\]/phi = [0.15, 0.9]/' "$work/tiny.toml" > "$work/bad.toml"
check "bad spec (phi out of range)" 2 "$draglab" --db "$db" pipeline --spec "$work/bad.toml"
if grep -q "phi" "$work/err"; then passed=$((passed + 1)); else
  echo "FAIL bad spec message does not name phi"; failures=$((failures + 1)); fi
printf '[campaign]\nname = "x"\nbogus = 1\n' > "$work/bad2.toml"
check "bad spec (unknown key)" 2 "$draglab" --db "$db" pipeline --spec "$work/bad2.toml"
check "bad law name" 2 "$draglab" --db "$db" pipeline --spec "$work/tiny.toml" --law-name "a b"
check "missing regression scene" 2 "$draglab" --db "$db" pipeline --spec "$work/tiny.toml" --regress-scene "$work/none.toml"
sed 's/^cells_x = 4/cells_x = 0/' "$work/viscous.toml" >"$work/bad_scene.toml"
check "invalid regression scene" 2 "$draglab" --db "$db" pipeline --spec "$work/tiny.toml" --regress-scene "$work/bad_scene.toml"
ok "message names cells_x" grep -q "cells_x" "$work/err"
check "--no-regress with --regress-scene" 2 "$draglab" --db "$db" pipeline --spec "$work/tiny.toml" --no-regress --regress-scene "$work/viscous.toml"
after="$(md5sum "$db" | cut -d" " -f1)"
if [ "$before" = "$after" ]; then passed=$((passed + 1)); else
  echo "FAIL bad input changed the database"; failures=$((failures + 1)); fi

finish pipeline_test
