#!/usr/bin/env bash
# End-to-end test of `draglab report` on a synthetic CSV dataset in a temporary directory.
# Checks: exit codes (0 ok, 1 no renderer, 2 bad input), the four PNGs (PNG signature), report.md
# linking them, the bundle's bvk2007 values against `draglab law eval` (same library, so equal to
# ~1e-12: the JSON carries 17 significant digits), the bundle's residual statistics recomputed
# independently here, the database left untouched, and nothing written on bad input.
# The data come from a formula (Carman-Kozeny Stokes term plus a linear Re term, +-3 % zig-zag),
# not from a law, so every law differs from them.
set -u
draglab="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export DRAGLAB_DB="$work/default.db"
. "$(dirname "$0")/harness.sh"

# Synthetic dataset: 4 phi x 3 Re (Re = 0 included), 2 % uncertainty.
"$py" - "$work/data.csv" <<'EOF'
import sys
with open(sys.argv[1], "w") as f:
    f.write("# synthetic: F = 10 phi/eps^2 + 1 + 0.1 Re/eps^2, times 1 +- 0.03\n")
    f.write("phi,re,F,F_uncertainty\n")
    k = 0
    for phi in (0.1, 0.2, 0.35, 0.5):
        for re in (0.0, 10.0, 100.0):
            eps = 1.0 - phi
            F = (10 * phi / eps**2 + 1 + 0.1 * re / eps**2) * (1.03 if k % 2 else 0.97)
            f.write("%r,%r,%r,%r\n" % (phi, re, F, 0.02 * F))
            k += 1
EOF

have_matplotlib=1
"$py" -c 'import matplotlib' >/dev/null 2>&1 || have_matplotlib=0

# Seed the database first, then fingerprint it: a report only reads it.
check "seed db" 0 "$draglab" --db "$work/t.db" law list
db_sum_before="$(md5sum < "$work/t.db")"

if [ "$have_matplotlib" -eq 1 ]; then
  check "report --data" 0 "$draglab" --db "$work/t.db" report --data "$work/data.csv" \
    --law vdh2004@1 --compare ergun@1,hill_koch_ladd@1,bvk2007@1 --out "$work/rep" --json
  pycheck "json shape" "
import json, os, sys
j = json.load(open(sys.argv[1] + '/out'))
assert set(j) >= {'out_dir', 'report', 'figures', 'bundle'}, j
assert len(j['figures']) == 4 and all(os.path.isfile(f) for f in j['figures']), j
"
  for fig in fig3_seed.png parity.png residuals.png work_precision.png; do
    ok "$fig is a PNG" "$py" -c "import sys; sys.exit(open('$work/rep/$fig','rb').read(8) != b'\x89PNG\r\n\x1a\n')"
    ok "report.md links $fig" grep -q "]($fig)" "$work/rep/report.md"
  done
  ok "report.md has the coefficient table" grep -q "| k0 | 18 |" "$work/rep/report.md"
  ok "report.md states the conventions" grep -q "drag-only" "$work/rep/report.md"
  ok "stdout is JSON only" "$py" -c "import json; json.load(open('$work/out'))"

  # bvk2007 at one data point against `law eval` (phi = 0.35, Re = 10).
  check "law eval bvk2007" 0 "$draglab" --db "$work/t.db" law eval bvk2007@1 --phi 0.35 --re 10 --json
  cp "$work/out" "$work/eval.json"
  pycheck "bundle bvk2007 == law eval" "
import json, sys
w = sys.argv[1]
b = json.load(open(w + '/rep/report_bundle.json'))
e = json.load(open(w + '/eval.json'))
pts = b['dataset']['points']
k = [i for i, p in enumerate(pts) if p['phi'] == 0.35 and p['re'] == 10.0]
assert len(k) == 1, k
law = [l for l in b['laws'] if l['reference'] == 'bvk2007@1'][0]
got = law['at_points']['F'][k[0]]
assert abs(got / e['F'] - 1) < 1e-12, (got, e['F'])
"
  # The statistics recomputed here from the CSV and the bundle's values at the points; the
  # roles and conventions the figures rely on.
  pycheck "bundle statistics and roles" "
import csv, json, math, sys
w = sys.argv[1]
b = json.load(open(w + '/rep/report_bundle.json'))
rows = [r for r in csv.DictReader(l for l in open(w + '/data.csv') if not l.startswith('#'))]
assert b['format'] == 'draglab_report_bundle' and 'F' in b['conventions']
assert len(b['dataset']['points']) == len(rows) == 12
roles = {l['reference']: l['role'] for l in b['laws']}
assert roles == {'vdh2004@1': 'fit', 'ergun@1': 'reference', 'hill_koch_ladd@1': 'reference',
                 'bvk2007@1': 'reference'}, roles
for law in b['laws']:
    rel = [abs(f / float(r['F']) - 1) for f, r in zip(law['at_points']['F'], rows)]
    s = law['stats']
    assert abs(s['max_rel_diff'] - max(rel)) < 1e-12, (law['reference'], s, max(rel))
    rms = math.sqrt(sum(x * x for x in rel) / len(rel))
    assert abs(s['rms_rel_diff'] - rms) < 1e-12
    assert s['n_evaluated'] == 12
    assert len(law['curves']) == 4 and all(len(c['re']) == len(c['F']) for c in law['curves'])
    assert all(f is None or f > 0 for f in law['stokes_curve']['F'])
"
  ok "database untouched" test "$(md5sum < "$work/t.db")" = "$db_sum_before"

  # Table output; a second run into the same directory replaces the files.
  check "report table" 0 "$draglab" --db "$work/t.db" report --data "$work/data.csv" --out "$work/rep"
  ok "table names the laws" grep -q "bvk2007@1" "$work/out"

  # No renderer: clear error naming the Debian package, exit 1, the bundle still written.
  check "no python" 1 env DRAGLAB_PYTHON="$work/no/python3" "$draglab" --db "$work/t.db" report \
    --data "$work/data.csv" --out "$work/rep2"
  ok "no-python error names python3-matplotlib" grep -q "python3-matplotlib" "$work/err"
  ok "bundle written without a renderer" test -s "$work/rep2/report_bundle.json"
else
  echo "NOTE: $py cannot import matplotlib: figures skipped, checking the clear error instead"
  check "report without matplotlib" 1 "$draglab" --db "$work/t.db" report --data "$work/data.csv" \
    --out "$work/rep"
  ok "error names python3-matplotlib" grep -q "python3-matplotlib" "$work/err"
  ok "bundle written without matplotlib" test -s "$work/rep/report_bundle.json"
fi

# Bad input: exit 2, a message naming the field, and nothing written.
check "missing --out" 2 "$draglab" --db "$work/t.db" report --data "$work/data.csv"
ok "message names --out" grep -q -- "--out" "$work/err"
check "missing data file" 2 "$draglab" --db "$work/t.db" report --data "$work/nope.csv" --out "$work/bad1"
ok "message names --data" grep -q -- "--data" "$work/err"
ok "nothing written (missing file)" test ! -e "$work/bad1"
check "unknown law" 2 "$draglab" --db "$work/t.db" report --data "$work/data.csv" --law no_such_law@1 --out "$work/bad2"
ok "message names the law" grep -q "no_such_law" "$work/err"
ok "nothing written (unknown law)" test ! -e "$work/bad2"
check "unknown comparison law" 2 "$draglab" --db "$work/t.db" report --data "$work/data.csv" --compare bvk2007,nope --out "$work/bad3"
ok "nothing written (unknown comparison)" test ! -e "$work/bad3"
check "no dataset" 2 "$draglab" --db "$work/t.db" report --out "$work/bad4"
check "both --data and --dataset" 2 "$draglab" --db "$work/t.db" report --data "$work/data.csv" --dataset abcd --out "$work/bad5"
check "unknown dataset" 2 "$draglab" --db "$work/t.db" report --dataset ffffffff --out "$work/bad6"
printf 'phi,re,F,F_uncertainty\n0.9,1,2,0.1\n' > "$work/badphi.csv"
check "phi out of range in CSV" 2 "$draglab" --db "$work/t.db" report --data "$work/badphi.csv" --out "$work/bad7"
ok "message names phi" grep -q "phi" "$work/err"
ok "nothing written (bad CSV)" test ! -e "$work/bad7"
ok "database untouched by bad input" test "$(md5sum < "$work/t.db")" = "$db_sum_before"

finish report_test
