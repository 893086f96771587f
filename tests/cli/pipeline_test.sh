#!/usr/bin/env bash
# End-to-end test of `draglab pipeline` (campaign -> dataset -> fit -> published law -> report) on
# a tiny campaign: 3 phi x 3 Re (0, 4, 10), one 8-sphere packing per phi, d = 8 (a few seconds).
# Checks: exit 0 and the JSON fields the issue asks for; 9 units done; the law is published
# (immutable) with the dataset in its provenance; the dataset's F values are the campaign's
# (Stokes F grows with phi, as every drag law says); re-running resumes (no new unit, same
# dataset id) and reuses the identical law version instead of adding one; a bad spec exits 2
# and writes nothing.
set -u
draglab="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
db="$work/p.db"
. "$(dirname "$0")/harness.sh"
cat > "$work/tiny.toml" <<'TOML'
[campaign]
name = "tiny"
description = "pipeline test"
[grid]
phi = [0.15, 0.25, 0.35]
re = [0, 4, 10]
realizations = 1
seed = 7
[packing]
spheres = 8
[lbm]
resolutions = [8]
[dataset]
extrapolation = "finest"
TOML

check "pipeline" 0 "$draglab" --db "$db" pipeline --spec "$work/tiny.toml" --out "$work/report" --json
cp "$work/out" "$work/first.json"
pycheck "pipeline JSON" '
import json, os, sys
w = sys.argv[1]
r = json.load(open(w + "/first.json"))
for key in ("law", "version", "params", "ci95", "rms_rel_err", "max_rel_err", "dataset",
            "comparison", "units_total", "units_done", "wall_s"):
    assert key in r, key
assert r["law"] == "eq6_tiny" and r["version"] == 1, r
assert r["units_total"] == 9 and r["units_done"] == 9 and r["units_failed"] == 0, r
assert set(r["ci95"]) == {"k0", "k1", "c10", "c11", "c12"}, r["ci95"]
for k, (lo, hi) in r["ci95"].items():
    assert lo <= r["params"][k] <= hi, k
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

check "pipeline again" 0 "$draglab" --db "$db" pipeline --spec "$work/tiny.toml" --out "$work/report" --json
pycheck "re-run resumes and reuses" '
import json, sys
w = sys.argv[1]
a = json.load(open(w + "/first.json")); b = json.load(open(w + "/out"))
assert b["version"] == 1 and b["dataset"] == a["dataset"], (a["version"], b["version"])
assert b["params"] == a["params"]
'
check "still one version" 0 "$draglab" --db "$db" law list --json
pycheck "one eq6_tiny version" '
import json, sys
laws = json.load(open(sys.argv[1] + "/out"))
laws = laws["laws"] if isinstance(laws, dict) else laws
assert sum(1 for l in laws if l["name"] == "eq6_tiny") == 1
'

before="$(md5sum "$db" | cut -d" " -f1)"
sed 's/phi = \[0.15, 0.25, 0.35\]/phi = [0.15, 0.9]/' "$work/tiny.toml" > "$work/bad.toml"
check "bad spec (phi out of range)" 2 "$draglab" --db "$db" pipeline --spec "$work/bad.toml"
if grep -q "phi" "$work/err"; then passed=$((passed + 1)); else
  echo "FAIL bad spec message does not name phi"; failures=$((failures + 1)); fi
printf '[campaign]\nname = "x"\nbogus = 1\n' > "$work/bad2.toml"
check "bad spec (unknown key)" 2 "$draglab" --db "$db" pipeline --spec "$work/bad2.toml"
check "bad law name" 2 "$draglab" --db "$db" pipeline --spec "$work/tiny.toml" --law-name "a b"
after="$(md5sum "$db" | cut -d" " -f1)"
if [ "$before" = "$after" ]; then passed=$((passed + 1)); else
  echo "FAIL bad input changed the database"; failures=$((failures + 1)); fi

finish pipeline_test
