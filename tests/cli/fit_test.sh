#!/usr/bin/env bash
# End-to-end test of `draglab fit` and `draglab law publish` on synthetic data.
# Set-up: F from the seed's Eq. 6 (form vdh2004, canonical F = A phi/(18 eps^2) + (a/18)
# eps^(n-2) (1 + b sqrt(phi)) + (B + C1) Re/(18 eps^2), C1 = c0 + c1 phi + c2 phi^2) with the
# "true" coefficients a = 20, b = 1.2, c0 = -1.0, c1 = 1.5, c2 = -1.2 (A = 180, B = 1.75,
# n = 3 fixed) on a 6 phi x 5 Re grid, 1 % uncertainty, no noise: the fit must return the true
# values (to far inside their intervals), a chi2 of ~0, and Eq. 6 as printed must differ from
# the data by more than the fit does. Also: --publish stores a draft with the dataset in its
# provenance, `law publish` freezes it, and bad input exits 2 writing nothing.
set -u
draglab="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
db="$work/fit.db"
. "$(dirname "$0")/harness.sh"

"$py" - "$work/eq6.csv" <<'PY'
import math, sys
a, b, c0, c1, c2, A, B, n = 20.0, 1.2, -1.0, 1.5, -1.2, 180.0, 1.75, 3.0
with open(sys.argv[1], "w") as f:
    f.write("# Eq. 6 (vdh2004 form) with a=20 b=1.2 c0=-1 c1=1.5 c2=-1.2; 1 % uncertainty\n")
    f.write("phi,re,F,F_uncertainty\n")
    for phi in (0.1, 0.2, 0.3, 0.4, 0.5, 0.6):
        for re in (0.0, 5.0, 20.0, 100.0, 400.0):
            e = 1.0 - phi
            C1 = c0 + c1 * phi + c2 * phi * phi
            F = A * phi / (18 * e * e) + a / 18 * e ** (n - 2) * (1 + b * math.sqrt(phi)) \
                + (B + C1) * re / (18 * e * e)
            f.write("%r,%r,%r,%r\n" % (phi, re, F, 0.01 * F))
PY

check "fit --data --json" 0 "$draglab" --db "$db" fit --data "$work/eq6.csv" --json
cp "$work/out" "$work/fit.json"
pycheck "fit recovers the true coefficients" '
import json, sys
r = json.load(open(sys.argv[1] + "/fit.json"))
truth = {"k0": 20.0, "k1": 1.2, "c10": -1.0, "c11": 1.5, "c12": -1.2}
for k, v in truth.items():
    got = r["params"][k]
    lo, hi = r["ci95"][k]
    assert abs(got - v) <= 1e-6 * max(1.0, abs(v)), (k, got, v)
    assert lo <= v <= hi, (k, lo, hi)
assert r["version"] is None
assert r["rms_rel_err"] < 1e-8 and r["max_rel_err"] < 1e-8, r
eq6 = [c for c in r["comparison"] if c["law"].startswith("vdh2004")]
assert eq6 and eq6[0]["max_rel_err"] > 0.01, r["comparison"]
'

check "fit --publish" 0 "$draglab" --db "$db" fit --data "$work/eq6.csv" --publish eq6_test --json
cp "$work/out" "$work/pub.json"
pycheck "published draft version 1" '
import json, sys
r = json.load(open(sys.argv[1] + "/pub.json"))
assert r["law"] == "eq6_test" and r["version"] == 1, r
'
check "law show draft" 0 "$draglab" --db "$db" law show eq6_test@1 --json
pycheck "draft with fitted provenance" '
import json, sys
r = json.load(open(sys.argv[1] + "/out"))
text = json.dumps(r)
assert "draft" in text and "fitted" in text, text[:400]
'
check "law publish" 0 "$draglab" --db "$db" law publish eq6_test@1
check "published law evaluates like the truth" 0 "$draglab" --db "$db" law eval eq6_test@1 --phi 0.3 --re 20 --json
pycheck "F at (0.3, 20)" '
import json, math, sys
r = json.load(open(sys.argv[1] + "/out"))
F = r["F"] if "F" in r else r[0]["F"]
e = 0.7; phi = 0.3
C1 = -1.0 + 1.5 * phi - 1.2 * phi * phi
truth = 180 * phi / (18 * e * e) + 20 / 18 * e * (1 + 1.2 * math.sqrt(phi)) + (1.75 + C1) * 20 / (18 * e * e)
assert abs(F / truth - 1) < 1e-8, (F, truth)
'
check "publishing twice is refused (immutable: bad input, exit 2)" 2 "$draglab" --db "$db" law publish eq6_test@1
if grep -q immutable "$work/err"; then passed=$((passed + 1)); else
  echo "FAIL publishing twice: no 'immutable' in the message"; failures=$((failures + 1)); fi

# Narrow data (phi <= 0.3, Re <= 5 of the same Eq. 6): the fit says which coefficients are not
# determined and fits the largest determined subset; --select off fits all five as asked.
"$py" - "$work/eq6.csv" "$work/narrow.csv" <<'PY'
import sys
rows = [l for l in open(sys.argv[1]) if not l.startswith("#")]
with open(sys.argv[2], "w") as f:
    f.write(rows[0])
    for l in rows[1:]:
        phi, re = (float(x) for x in l.split(",")[:2])
        if phi <= 0.3 and re <= 5.0:
            f.write(l)
PY
check "fit selects a determined subset" 0 "$draglab" --db "$db" fit --data "$work/narrow.csv" --json
cp "$work/out" "$work/narrow.json"
pycheck "selection: chosen subset, every interval narrower than its value" '
import json, sys
r = json.load(open(sys.argv[1] + "/narrow.json"))
s = r["selection"]
assert s["performed"] and s["undetermined"], s
assert set(r["free"]) == set(s["chosen"]) and len(s["chosen"]) < 5, (r["free"], s)
for k in r["free"]:
    lo, hi = r["ci95"][k]
    assert (hi - lo) / 2 < abs(r["params"][k]), (k, lo, hi)
'
check "fit --select off fits the requested set" 0 "$draglab" --db "$db" fit --data "$work/narrow.csv" \
  --select off --json
pycheck "select off: all five free" '
import json, sys
r = json.load(open(sys.argv[1] + "/out"))
assert sorted(r["free"]) == ["c10", "c11", "c12", "k0", "k1"] and not r["selection"]["performed"], r
'
check "fit --compare-forms" 0 "$draglab" --db "$db" fit --data "$work/eq6.csv" --compare-forms --json
pycheck "form comparison: Eq. 6 refit fits its own data, every row present" '
import json, sys
rows = json.load(open(sys.argv[1] + "/out"))["form_comparison"]
labels = [r["label"] for r in rows]
assert labels[:4] == ["Eq. 6 (vdh2004) refit, n = 3", "Eq. 6 (vdh2004) refit, n free",
                      "bvk2007 refit", "tang2015 refit"], labels
assert "vdh2004@1 as published" in labels and "tang2015@1 as published" in labels, labels
assert rows[0]["error"] == "" and rows[0]["rms_rel_err"] < 1e-6, rows[0]
printed = rows[labels.index("vdh2004@1 as published")]
assert printed["rms_rel_err"] > 0.01 and printed["cv_rms_rel_err"] == printed["rms_rel_err"], printed
'
check "fit --select bogus" 2 "$draglab" --db "$db" fit --data "$work/eq6.csv" --select bogus
check "fit of a form with nothing to fit" 2 "$draglab" --db "$db" fit --data "$work/eq6.csv" \
  --form schiller_naumann

# Bad input: exit 2, and the database is not changed.
before="$(md5sum "$db" | cut -d" " -f1)"
check "unknown form" 2 "$draglab" --db "$db" fit --data "$work/eq6.csv" --form nosuch --publish x
check "unknown parameter" 2 "$draglab" --db "$db" fit --data "$work/eq6.csv" --free a,zz --publish x
check "both sources" 2 "$draglab" --db "$db" fit --data "$work/eq6.csv" --dataset abcd --publish x
check "no source" 2 "$draglab" --db "$db" fit --publish x
head -4 "$work/eq6.csv" > "$work/small.csv"
check "too few points" 2 "$draglab" --db "$db" fit --data "$work/small.csv" --publish x
printf 'phi,re,F,F_uncertainty\n0.3,0,abc,0.1\n' > "$work/bad.csv"
check "malformed CSV" 2 "$draglab" --db "$db" fit --data "$work/bad.csv" --publish x
after="$(md5sum "$db" | cut -d" " -f1)"
if [ "$before" = "$after" ]; then passed=$((passed + 1)); else
  echo "FAIL bad input changed the database"; failures=$((failures + 1)); fi

finish fit_test
