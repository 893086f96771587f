#!/usr/bin/env bash
# End-to-end test of the draglab CLI on a fresh database in a temporary directory.
# Checks: exit codes (0 ok, 1 failure, 2 bad input), --json shapes and values, messages on
# stderr only, and that bad input leaves nothing behind. Values checked against
# data/law_check_values.csv (bvk2007 at phi 0.4, Re 100: F = 30.7416, 6 significant figures).
set -u
draglab="$1"
py=/usr/bin/python3
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export DRAGLAB_DB="$work/default.db"
failures=0; passed=0

check() {  # check NAME EXPECTED_EXIT CMD...
  local name="$1" expected="$2"; shift 2
  "$@" >"$work/out" 2>"$work/err"
  local rc=$?
  if [ "$rc" -ne "$expected" ]; then
    echo "FAIL $name: exit $rc, expected $expected"; sed 's/^/  stderr: /' "$work/err" | head -5
    failures=$((failures + 1))
  else
    passed=$((passed + 1))
  fi
}
json_check() {  # json_check NAME PYTHON_EXPRESSION_ON_j
  if "$py" -c "import json,sys; j=json.load(open('$work/out')); sys.exit(0 if ($2) else 1)"; then
    passed=$((passed + 1))
  else
    echo "FAIL $1: JSON check '$2' failed on:"; head -c 600 "$work/out"; echo
    failures=$((failures + 1))
  fi
}

# Database creation on first use, seeded with the literature library.
check "law list --json" 0 "$draglab" law list --json
json_check "list has the literature library" \
  "isinstance(j, list) and {'bvk2007','tang2015','vdh2004','gidaspow','hill_koch_ladd'} <= {x['name'] for x in j} and all({'name','version','status','form'} <= set(x) for x in j)"
[ -f "$DRAGLAB_DB" ] || { echo "FAIL: DRAGLAB_DB not created"; failures=$((failures + 1)); }

# --db takes precedence over $DRAGLAB_DB.
check "explicit --db" 0 "$draglab" --db "$work/explicit.db" db info --json
json_check "db info" "j['path'].endswith('explicit.db') and j['schema_version'] == j['code_schema_version'] and j['law_versions'] >= 15"

# law eval, JSON and table.
check "law eval --json" 0 "$draglab" law eval bvk2007 --phi 0.4 --re 100 --json
json_check "eval fields" "all(k in j for k in ('law','version','phi','re','F','beta_d2_over_mu','K'))"
json_check "eval value (data/law_check_values.csv)" "abs(j['F'] - 30.7416) / 30.7416 < 2e-6"
json_check "eval conversions" "abs(j['beta_d2_over_mu'] - 18*0.4*0.6*j['F']) < 1e-9*j['beta_d2_over_mu'] and abs(j['K'] - j['F']/0.6) < 1e-12*j['K']"
check "law eval table" 0 "$draglab" law eval tang2015 --phi 0.3 --re 10
grep -q "beta d^2/mu" "$work/out" || { echo "FAIL: eval table"; failures=$((failures + 1)); }
check "law eval grid json" 0 "$draglab" law eval bvk2007@1 --grid --json
json_check "grid" "len(j) == 30 and all('F' in x for x in j)"

# Bad input: exit 2 with a message naming the field.
check "phi out of physical range" 2 "$draglab" law eval bvk2007 --phi 1.2 --re 10
grep -q "phi" "$work/err" || { echo "FAIL: message does not name phi"; failures=$((failures + 1)); }
check "negative Re" 2 "$draglab" law eval bvk2007 --phi 0.3 --re -1
check "NaN phi" 2 "$draglab" law eval bvk2007 --phi nan --re 1
check "outside validity" 2 "$draglab" law eval bvk2007 --phi 0.05 --re 1
check "clamp policy" 0 "$draglab" law eval bvk2007 --phi 0.05 --re 1 --range-policy clamp --json
# Under clamp every quantity comes from one point, reported: F, beta and K at the clamped point
# (bvk2007's validity starts at phi = 0.1), the requested point kept beside it.
json_check "clamp: one evaluation point for every value, reported" \
  "j['phi'] == 0.05 and j['evaluated_at']['phi'] == 0.1 and abs(j['K'] - j['F']/0.9) < 1e-12*j['K'] and abs(j['beta_d2_over_mu'] - 18*0.1*0.9*j['F']) < 1e-9*j['beta_d2_over_mu']"
json_check "clamped value equals phi=0.1" "abs(j['F'] - 2.49816) < 1e-5"
check "unknown law" 2 "$draglab" law eval no_such_law --phi 0.3 --re 1
grep -q "bvk2007" "$work/err" || { echo "FAIL: unknown law does not list known names"; failures=$((failures + 1)); }
check "unknown option" 2 "$draglab" law eval bvk2007 --phii 0.3
check "missing subcommand" 2 "$draglab" law
check "help" 0 "$draglab" law eval --help
grep -q "Examples" "$work/out" || { echo "FAIL: help without examples"; failures=$((failures + 1)); }

# diff, show, export.
check "law diff" 0 "$draglab" law diff bvk2007 tang2015 --json
json_check "diff fields" "j['max_relative_difference'] > 0.1 and 'phi' in j['at']"
check "law diff self" 0 "$draglab" law diff bvk2007 bvk2007@1 --json
json_check "diff self is zero" "j['max_relative_difference'] == 0 and j['same_content']"
check "law show json" 0 "$draglab" law show vdh2004 --json
check "law export c" 0 "$draglab" law export bvk2007@1 --format c -o "$work/bvk.c"
[ -s "$work/bvk.c" ] || { echo "FAIL: export wrote nothing"; failures=$((failures + 1)); }
check "export unwritable" 2 "$draglab" law export bvk2007 --format c -o "$work/no/such/dir/x.c"
ls "$work/no" >/dev/null 2>&1 && { echo "FAIL: export left files"; failures=$((failures + 1)); }

# Retraction: stays loadable, with a warning.
check "retract" 0 "$draglab" law retract ergun@1 --reason "test retraction"
check "retracted loads" 0 "$draglab" law eval ergun@1 --phi 0.4 --re 10
grep -qi "retracted" "$work/err" || { echo "FAIL: no retraction warning"; failures=$((failures + 1)); }

# Bad database files.
echo "this is not a database" >"$work/bad.db"
check "not a database" 2 "$draglab" --db "$work/bad.db" law list
grep -q "bad.db" "$work/err" || { echo "FAIL: corrupt db message does not name the file"; failures=$((failures + 1)); }
check "empty --db" 2 "$draglab" --db '' law list
grep -q "empty path" "$work/err" || { echo "FAIL empty --db: no 'empty path' in the message"; failures=$((failures + 1)); }
for seed in -1 18446744073709551616 1.5; do
  check "pack --seed $seed" 2 "$draglab" pack --phi 0.3 --n 8 --seed "$seed" --out "$work/seed.h5"
  grep -q -- "--seed" "$work/err" || { echo "FAIL pack --seed $seed: the message does not name --seed"; failures=$((failures + 1)); }
done
[ ! -e "$work/seed.h5" ] || { echo "FAIL a refused seed wrote a packing"; failures=$((failures + 1)); }
check "db check" 0 "$draglab" db check

# Packings: generation, statistics, bad input (exit 2, no file left behind).
check "pack random" 0 "$draglab" pack --phi 0.3 --n 60 --seed 5 --sweeps 50 --out "$work/p.h5" --json
json_check "pack json" "abs(j['phi'] - 0.3) < 1e-12 and j['n'] == 60 and j['overlapping_pairs'] == 0 and j['min_gap'] >= 0"
check "pack stats" 0 "$draglab" pack stats "$work/p.h5" --json
json_check "pack stats json" "set(('phi','n','min_gap','q6','g_contact')) <= set(j) and abs(j['phi'] - 0.3) < 1e-12"
check "pack ordered fcc" 0 "$draglab" pack --ordered fcc --phi 0.5 --cells 2 --out "$work/f.h5" --json
json_check "fcc q6 (Steinhardt FCC 0.5745)" "abs(j['q6'] - 0.57452) < 1e-4 and j['n'] == 32"
check "pack voxelize" 0 "$draglab" pack voxelize "$work/p.h5" --resolution 8 --json
json_check "voxelize json" "abs(j['phi_lattice'] - 0.3) < 0.05 and j['links'] > 0"
# --raw: one byte per node, x fastest, 1 = solid; its solid fraction is the lattice's phi.
check "pack voxelize --raw" 0 "$draglab" pack voxelize "$work/p.h5" --resolution 8 --raw "$work/p.raw" --json
json_check "voxelize --raw flags" "(lambda b: len(b) == j['dims'][0] * j['dims'][1] * j['dims'][2] and set(b) <= {0, 1} and abs(sum(b) / len(b) - j['phi_lattice']) < 1e-12)(open('$work/p.raw', 'rb').read())"
check "pack ensemble" 0 "$draglab" pack ensemble --phi 0.2 --n 40 --sweeps 20 -R 2 --out-dir "$work/ens" --json
json_check "ensemble json" "len(j) == 2 and j[0]['seed'] != j[1]['seed']"
check "pack phi too high" 2 "$draglab" pack --phi 0.7 --n 100 --out "$work/bad1.h5"
grep -q "0.64" "$work/err" || { echo "FAIL: random phi limit not named"; failures=$((failures + 1)); }
check "pack sc above close packing" 2 "$draglab" pack --ordered sc --phi 0.6 --out "$work/bad2.h5"
check "pack n < 1" 2 "$draglab" pack --phi 0.3 --n 0 --out "$work/bad3.h5"
check "pack size ratio" 2 "$draglab" pack --phi 0.3 --n 50 --dist bi --size-ratio 6 --out "$work/bad4.h5"
check "pack unwritable" 2 "$draglab" pack --phi 0.3 --n 50 --out "$work/no/such/dir/p.h5"
check "pack stats missing file" 2 "$draglab" pack stats "$work/missing.h5"
for f in bad1 bad2 bad3 bad4; do
  ls "$work/$f.h5"* >/dev/null 2>&1 && { echo "FAIL: $f left a file"; failures=$((failures + 1)); }
done

# LBM: tiny lattices only (d = 5-6, boxes of 10^3 nodes), a few seconds in all; one thread each
# (OpenMP teams on lattices this small only add barrier cost, and ctest runs tests side by side).
# Reference: Sangani-Acrivos series for SC arrays in Stokes flow (data/sangani_acrivos_sc_series.csv).
check "lbm help" 0 "$draglab" lbm run --help
grep -q "Examples" "$work/out" || { echo "FAIL: lbm run help without examples"; failures=$((failures + 1)); }
check "lbm run sc" 0 "$draglab" lbm run --array sc --phi 0.125 --d 6 --re 0 --json --threads 1
json_check "lbm run keys" "all(k in j for k in ('F','K','beta_d2_over_mu','re','phi','phi_lattice','converged','steps','wall_s','mflups','momentum_balance_rel','mach_max','error_estimate'))"
json_check "lbm run converged" "j['converged'] is True and j['steps'] > 0 and j['wall_s'] > 0 and j['momentum_balance_rel'] < 1e-6"
# Conventions: K = F/(1 - phi), beta d^2/mu = 18 phi (1 - phi) F (exact identities).
json_check "lbm run conventions" "abs(j['K'] - j['F']/(1-j['phi'])) < 1e-9*j['K'] and abs(j['beta_d2_over_mu'] - 18*j['phi']*(1-j['phi'])*j['F']) < 1e-9*j['beta_d2_over_mu']"
# Series F = (1 - 0.125) K(0.125) = 3.7555 (Zick & Homsy K = 4.292); d = 6 is coarse: 10 % band.
json_check "lbm run near the series" "abs(j['F']/3.7555 - 1) < 0.10 and 'error' in j"
check "lbm run fields" 0 "$draglab" lbm run --array sc --phi 0.125 --d 6 --re 0 --fields "$work/flow.h5" --json --threads 1
[ -s "$work/flow.h5" ] && [ -s "$work/flow.xmf" ] || { echo "FAIL: lbm fields files missing"; failures=$((failures + 1)); }
grep -q "flow.h5:/fields/velocity" "$work/flow.xmf" 2>/dev/null || { echo "FAIL: xmf does not reference flow.h5"; failures=$((failures + 1)); }
check "lbm run table (bgk-bb)" 0 "$draglab" lbm run --array sc --phi 0.2 --d 6 --re 0 --collision bgk --boundary bb --threads 1
grep -q "beta d^2/mu" "$work/out" || { echo "FAIL: lbm run table"; failures=$((failures + 1)); }
check "lbm run Re = 1" 0 "$draglab" lbm run --array sc --phi 0.2 --d 6 --re 1 --json --threads 1
# The engine adjusts the body force until the achieved Re is within 1 % of the target.
json_check "lbm run achieved Re" "j['converged'] and abs(j['re'] - 1) <= 0.01 and j['re_target'] == 1"
# The default operator is chosen per run: TRT within its stable cell Reynolds number, rr with
# TRT's wall beyond (kappa Re / d = 4.95 x 40 / 8 = 24.7 > 23), and the record says which and why.
check "lbm run collision auto" 0 "$draglab" lbm run --array sc --phi 0.3 --d 8 --re 40 --json --threads 1
json_check "lbm run auto picks rr" "j['converged'] and j['collision'] == 'rr' and j['collision_requested'] == 'auto' and '> 23' in j['collision_reason'] and j['wall_corrected']"
check "lbm run named collision" 0 "$draglab" lbm run --array sc --phi 0.3 --d 8 --re 40 --collision trt --json --threads 1
json_check "lbm run named trt keeps its record" "j['collision'] == 'trt' and 'collision_requested' not in j"
check "lbm calibrate" 0 "$draglab" lbm calibrate --d 5 --json --threads 1
json_check "lbm calibrate keys" "0.8 < j['d_h_over_d'] < 1.2 and j['scheme'] == 'trt-bb' and j['calibration']['F_input'] > 0"
check "lbm convergence" 0 "$draglab" lbm convergence --array sc --phi 0.125 --re 0 --d 5,6,7 --schemes trt-bb,trt-ibb --json --threads 1
json_check "lbm convergence json" "j['reference_source'].startswith('Sangani') and len(j['schemes']) == 2 and all(len(s['points']) == 3 and all(p['converged'] and p['error'] is not None and p['wall_s'] > 0 for p in s['points']) for s in j['schemes'])"
if command -v gnuplot >/dev/null 2>&1 || "$py" -c "import matplotlib" >/dev/null 2>&1; then
  check "lbm convergence plot" 0 "$draglab" lbm convergence --array sc --phi 0.125 --re 0 --d 5,6 --schemes trt-ibb --plot "$work/wp.png" --threads 1
  head -c 8 "$work/wp.png" 2>/dev/null | grep -q "PNG" || { echo "FAIL: convergence plot is not a PNG"; failures=$((failures + 1)); }
fi
# LBM bad input: exit 2, the field named, nothing written.
check "lbm Re negative" 2 "$draglab" lbm run --array sc --phi 0.1 --d 8 --re -1
grep -q -- "--re" "$work/err" || { echo "FAIL: Re message does not name --re"; failures=$((failures + 1)); }
check "lbm Re too high" 2 "$draglab" lbm run --array sc --phi 0.1 --d 8 --re 1e5
check "lbm phi above close packing" 2 "$draglab" lbm run --array sc --phi 0.6 --d 8 --re 0
grep -q -- "--phi" "$work/err" || { echo "FAIL: phi message does not name --phi"; failures=$((failures + 1)); }
check "lbm gap too small (opt-in check)" 2 "$draglab" lbm run --array sc --phi 0.5 --d 8 --re 0 --min-gap-nodes 1
grep -q "lattice units" "$work/err" || { echo "FAIL: gap message without the gap in lattice units"; failures=$((failures + 1)); }
check "lbm --min-gap-nodes out of range" 2 "$draglab" lbm run --array sc --phi 0.5 --d 8 --re 0 --min-gap-nodes -1
# campaign plan: units, memory, predicted time, before any work; a spec that cannot fit is exit 2.
check "campaign plan" 0 "$draglab" campaign plan quick --jobs 2 --node-update-ns 50 --json
json_check "campaign plan json" "j['units'] == 60 and j['wall_seconds'] > 0 and j['fits_in_memory'] and len(j['points']) == 20"
printf '[campaign]\nname = "huge"\n[grid]\nphi = [0.1]\nre = [0]\nrealizations = 1\n[lbm]\nresolutions = [500]\n[dataset]\nextrapolation = "finest"\n' > "$work/huge.toml"
check "campaign plan too big" 2 "$draglab" campaign plan "$work/huge.toml" --jobs 2 --node-update-ns 50
grep -q "GiB" "$work/err" || { echo "FAIL: plan memory message without GiB"; failures=$((failures + 1)); }
# Touching spheres (SC close packing) are run by default and their contacts reported.
check "lbm touching sc" 0 "$draglab" lbm run --array sc --phi 0.5235987755982988 --d 12 --re 0 --json --threads 1
json_check "lbm touching sc json" "j['converged'] and j['narrow_gap_pairs'] == 3 and j['narrow_gap_fluid_fraction'] > 0 and 38 < j['K'] < 46 and any('gaps below one lattice spacing' in w for w in j['warnings'])"

check "lbm unknown collision" 2 "$draglab" lbm run --array sc --phi 0.1 --d 8 --re 0 --collision mrt
check "lbm unknown scheme" 2 "$draglab" lbm convergence --array sc --phi 0.1 --re 0 --d 6 --schemes foo-bb
check "lbm missing packing" 2 "$draglab" lbm run --packing "$work/none.h5" --d 8 --re 0
echo "not hdf5" >"$work/bad_packing.h5"
check "lbm malformed packing" 2 "$draglab" lbm run --packing "$work/bad_packing.h5" --d 8 --re 0
check "lbm both geometries" 2 "$draglab" lbm run --packing "$work/p.h5" --array sc --phi 0.1 --d 8 --re 0
check "lbm no resolution" 2 "$draglab" lbm run --array sc --phi 0.1 --re 0
check "lbm resolution out of range" 2 "$draglab" lbm run --array sc --phi 0.1 --d 2 --re 0
check "lbm fields unwritable" 2 "$draglab" lbm run --array sc --phi 0.1 --d 6 --re 0 --fields "$work/no/such/f.h5"
ls "$work/no" >/dev/null 2>&1 && { echo "FAIL: lbm left files"; failures=$((failures + 1)); }
check "lbm calibrate d too small" 2 "$draglab" lbm calibrate --d 2
check "lbm bench repeat" 2 "$draglab" lbm bench --repeat 0

# A database whose directory (where SQLite keeps its -wal and -shm files) the user cannot write:
# read-only, said once on stderr, and reads still work; a change fails with a clear message.
# Root writes everywhere, so as root the check runs as the user nobody.
shared="$(mktemp -d)"
cp "$DRAGLAB_DB" "$shared/shared.db"
chmod 644 "$shared/shared.db"
chmod 755 "$shared"
as_user=()
if [ "$(id -u)" -eq 0 ]; then
  id nobody >/dev/null 2>&1 && chmod 666 "$shared/shared.db" && as_user=(setpriv --reuid=nobody --regid=nogroup --clear-groups)
else
  chmod 555 "$shared"
fi
if [ "$(id -u)" -ne 0 ] || [ ${#as_user[@]} -gt 0 ]; then
  check "read-only directory: eval" 0 "${as_user[@]}" "$draglab" --db "$shared/shared.db" law eval bvk2007 --phi 0.4 --re 100 --json
  json_check "read-only directory: value" "abs(j['F'] - 30.7416) / 30.7416 < 2e-6"
  [ "$(grep -c 'opened read-only' "$work/err")" -eq 1 ] || { echo "FAIL: read-only note not said once"; failures=$((failures + 1)); }
  # Bad input (bad-input finding B22): exit 2, naming the permission the change needs.
  check "read-only directory: change refused" 2 "${as_user[@]}" "$draglab" --db "$shared/shared.db" law retract ergun@1 --reason "read-only test"
  grep -q "read-only, so it cannot be changed: changing it needs write permission on the file and on its directory" "$work/err" || { echo "FAIL: read-only change message"; failures=$((failures + 1)); }
fi
chmod 755 "$shared"
rm -rf "$shared"

# The main job.
check "law compare" 0 "$draglab" law compare
grep -q "bvk2007" "$work/out" || { echo "FAIL: compare table"; failures=$((failures + 1)); }

echo "cli: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
