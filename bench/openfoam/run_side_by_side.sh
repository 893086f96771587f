#!/usr/bin/env bash
# Side-by-side two-fluid benchmark: draglab's TFM (`draglab scene run`, docs/tfm.md) against
# OpenFOAM v1912's twoPhaseEulerFoam (Debian's `openfoam`) on the tutorial
# multiphase/twoPhaseEulerFoam/laminar/fluidisedBed (Debian's `openfoam-examples`), same grid,
# closures and step. Prints a table and, last, one JSON line; both also go to --out.
#
# The case: 0.15 x 1.0 m, 30 x 200 cells (one across the 20 mm depth), 300 um particles of
# 2500 kg/m^3 at alpha = 0.55 up to 0.5 m, air in at 0.25 m/s and 300 K through the bottom
# (0.5 m/s once heated to the bed's 600 K), 2e-4 s steps.
# OpenFOAM is switched from the tutorial's phasePressure model to its own kinetic theory (the
# dormant kineticTheoryCoeffs block: Gidaspow viscosity and conductivity, Lun pressure,
# Sinclair-Jackson g0 with alpha_max 0.62, Johnson-Jackson friction Fr 0.05, 2, 5, 28.5 deg,
# alphaMinFriction 0.5, alphaDeltaMin 0.05, e = 0.8) with the granular temperature transported
# (equilibrium off, residualAlpha 1e-4), and its virtual mass is removed; draglab runs
# bench/openfoam/fluidised_bed.toml, which declares the same (gidaspow@1 = GidaspowErgunWenYu).
# What still differs: OpenFOAM's air is a perfect gas with an energy equation, entering at 300 K
# into a 600 K bed and heated there within the first cell row, so the bed sees twice the inlet's
# volume flow; draglab's gas is incompressible and isothermal at 600 K (0.579 kg/m^3) with that
# doubled flow, 0.5 m/s (the scene's header). OpenFOAM's momentum advection is limitedLinearV
# (draglab's upwind), and OpenFOAM runs PIMPLE with
# 3 outer correctors and an implicit phase pressure, draglab one explicit projection step whose
# size adapts below 2e-4 s when its stability limits ask (the steps and their limits are
# reported; the run is then at "the same step where stable").
#
# Timed: the simulated time --end-time from the same initial state, in a fresh process each,
# interleaved: OpenFOAM 1 rank, draglab 1 thread, OpenFOAM 2 ranks (decomposePar, simple 1 x 2);
# repeated --repeat times; medians. OpenFOAM's time is its ExecutionTime, draglab's the wall
# time of its run (wall_s). Rates are cell-steps/s (cells x steps / time) and, since the step
# counts can differ, simulated seconds per wall second. Results compared at --end-time: the bed
# height (top of the highest row whose width-averaged alpha_p exceeds half the initial 0.55),
# the solids inventory, and the mean absolute difference of the width-averaged alpha_p profiles
# over the lower 0.6 m (OpenFOAM 1 rank against draglab). A short run compares the expansion of
# the bed, not its bubbling statistics; a time-averaged profile needs seconds of simulated time
# (--end-time 2 takes ~8 min per OpenFOAM run on one core here): --results-window A:B runs each
# code once more, untimed, to B with fields every 0.05 s, and compares the time-averaged
# width-averaged alpha_p profiles, bed heights and solids centroids over [A, B].
#
# Installs nothing: it needs `twoPhaseEulerFoam`, `blockMesh`, `setFields`, `decomposePar`,
# `mpirun` (apt-get install openfoam openfoam-examples openmpi-bin), Debian's python3 with h5py
# and numpy, and a draglab build:
#   cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build --target draglab
#
# The time averages come with standard errors from 8 consecutive blocks of the window (each
# 0.5 s for 2:6, longer than a slug's period, so the block means are close to independent),
# and each difference with its size in combined standard errors.
#
# Usage: bench/openfoam/run_side_by_side.sh [--build-dir DIR] [--out DIR] [--end-time S]
#          [--repeat R] [--quick] [--results-window A:B] [--analyse-only]
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
tutorial=/usr/share/doc/openfoam-examples/examples/multiphase/twoPhaseEulerFoam/laminar/fluidisedBed

usage() {
  cat <<'EOF'
usage: bench/openfoam/run_side_by_side.sh [options]
  --build-dir DIR   draglab build with cli/draglab                      [build]
  --out DIR         work directory: cases, logs, results      [BUILD/openfoam_side_by_side]
  --end-time S      simulated time of each run [s], (0, 10]       [0.2; --quick 0.02]
  --repeat R        interleaved repetitions, >= 1                 [3; --quick 1]
  --quick           smoke check: short runs, one repetition
  --results-window A:B  also compare the time-averaged bed over [A, B] s: one more run of
                    each (OpenFOAM 2 ranks, draglab) to B with fields every 0.05 s, untimed
  --analyse-only    run nothing: recompute the tables from the runs already in --out (give
                    the --end-time and --results-window they were made with)
EOF
}
fail_usage() {
  echo "run_side_by_side: $*" >&2
  usage >&2
  exit 2
}

build_dir="$root/build" out="" end_time="" repeat="" quick=0 window="" analyse_only=0
while [ "$#" -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir="${2:?}"; shift 2 ;;
    --out) out="${2:?}"; shift 2 ;;
    --end-time) end_time="${2:?}"; shift 2 ;;
    --repeat) repeat="${2:?}"; shift 2 ;;
    --quick) quick=1; shift ;;
    --results-window) window="${2:?}"; shift 2 ;;
    --analyse-only) analyse_only=1; shift ;;
    -h|--help) usage; exit 0 ;;
    *) fail_usage "unknown option '$1'" ;;
  esac
done
if [ "$quick" -eq 1 ]; then end_time="${end_time:-0.02}" repeat="${repeat:-1}"; fi
end_time="${end_time:-0.2}" repeat="${repeat:-3}"
out="${out:-$build_dir/openfoam_side_by_side}"
python3_bin=/usr/bin/python3
"$python3_bin" -c "import sys; t = float(sys.argv[1]); sys.exit(0 if 0 < t <= 10 else 1)" \
  "$end_time" 2>/dev/null || fail_usage "--end-time $end_time is outside (0, 10] s"
[[ "$repeat" =~ ^[1-9][0-9]*$ ]] || fail_usage "--repeat $repeat must be an integer >= 1"
window_from="" window_to=""
if [ -n "$window" ]; then
  [[ "$window" =~ ^([0-9.]+):([0-9.]+)$ ]] || fail_usage "--results-window $window is not A:B"
  window_from="${BASH_REMATCH[1]}" window_to="${BASH_REMATCH[2]}"
  "$python3_bin" -c "import sys; a, b = map(float, sys.argv[1:]); sys.exit(0 if 0 <= a < b <= 20 else 1)" \
    "$window_from" "$window_to" 2>/dev/null ||
    fail_usage "--results-window $window must satisfy 0 <= A < B <= 20 s"
fi
if [ "$analyse_only" -eq 1 ]; then
  [ -f "$out/times.txt" ] || fail_usage "--analyse-only: no $out/times.txt (run the benchmark first)"
else
draglab="$build_dir/cli/draglab"
[ -x "$draglab" ] || fail_usage "no $draglab: build draglab first (see the header)"
for tool in twoPhaseEulerFoam blockMesh setFields decomposePar mpirun; do
  command -v "$tool" >/dev/null ||
    fail_usage "'$tool' not found: apt-get install openfoam openfoam-examples openmpi-bin"
done
[ -d "$tutorial" ] || fail_usage "no $tutorial: apt-get install openfoam-examples"
"$python3_bin" -c "import h5py, numpy" 2>/dev/null ||
  fail_usage "$python3_bin cannot import h5py and numpy: apt-get install python3-h5py"

# Debian's OpenFOAM finds its etc files through these.
export WM_PROJECT_DIR=/usr/share/openfoam FOAM_ETC=/usr/share/openfoam/etc
mkdir -p "$out"
case_dir="$out/openfoam_case"

# ---- the OpenFOAM case, with draglab's closures ----
rm -rf "$case_dir"
cp -r "$tutorial" "$case_dir"
gunzip -f "$case_dir"/0/*.gz 2>/dev/null || true
[ -f "$case_dir/0/alpha.particles" ] || cp "$case_dir/0/alpha.particles.orig" "$case_dir/0/alpha.particles"
"$python3_bin" - "$case_dir" "$end_time" <<'PY'
import re, sys
case, end = sys.argv[1], sys.argv[2]
def edit(path, fn):
    with open(path) as f:
        text = f.read()
    new = fn(text)
    if new == text:
        sys.exit("run_side_by_side: could not edit " + path + " (tutorial changed?)")
    with open(path, "w") as f:
        f.write(new)
edit(case + "/constant/turbulenceProperties.particles", lambda s: s
     .replace("RASModel phasePressure;", "RASModel kineticTheory;")
     .replace("equilibrium             on;", "equilibrium             off;")
     .replace("e                       0.8;", "e                       0.8;\n        residualAlpha           1e-4;"))
edit(case + "/constant/phaseProperties",
     lambda s: re.sub(r"virtualMass\n\(.*?\n\);", "virtualMass\n(\n);", s, flags=re.S))
edit(case + "/system/controlDict", lambda s: re.sub(r"functions\n\{.*\n\}\n", "functions\n{\n}\n",
     s.replace("endTime         2;", "endTime         %s;" % end)
      .replace("writeInterval   0.01;", "writeInterval   %s;" % end), flags=re.S))
edit(case + "/system/fvSchemes", lambda s: s.replace(
    "    div((((alpha.air*thermo:rho.air)*nuEff.air)*dev2(T(grad(U.air))))) Gauss linear;",
    "    div((((alpha.air*thermo:rho.air)*nuEff.air)*dev2(T(grad(U.air))))) Gauss linear;\n"
    "    div((((thermo:rho.particles*nut.particles)*dev2(T(grad(U.particles))))+"
    "(((thermo:rho.particles*lambda.particles)*div(phi.particles))*I))) Gauss linear;\n"
    "    \"div\\(alphaRhoPhi.*,Theta.*\\)\" Gauss limitedLinear 1;\n"
    "    \"div\\(phi.*,Theta.*\\)\" Gauss limitedLinear 1;"))
with open(case + "/system/decomposeParDict", "w") as f:
    f.write("FoamFile { version 2.0; format ascii; class dictionary; object decomposeParDict; }\n"
            "numberOfSubdomains 2;\nmethod simple;\n"
            "simpleCoeffs { n (1 2 1); delta 0.001; }\n")
PY
(cd "$case_dir" && blockMesh >log.blockMesh 2>&1 && setFields >log.setFields 2>&1 &&
   decomposePar -force >log.decomposePar 2>&1) ||
  { echo "run_side_by_side: OpenFOAM case set-up failed, see $case_dir/log.*" >&2; exit 1; }
# Each timed run starts from the same initial state: the 0/ and processor*/0 directories only.
clean_case() {
  find "$case_dir" -maxdepth 1 -type d -regex '.*/[0-9.e-]+' ! -name 0 -exec rm -rf {} +
  for p in "$case_dir"/processor*; do
    find "$p" -maxdepth 1 -type d -regex '.*/[0-9.e-]+' ! -name 0 -exec rm -rf {} +
  done
}

scene="$out/fluidised_bed.toml"
sed "s/^duration_s = 0.1$/duration_s = $end_time/; s/^t_ref_s = 0.1$/t_ref_s = $end_time/" \
  "$here/fluidised_bed.toml" >"$scene"
sed -i "s|^range_policy = \"clamp\"|range_policy = \"clamp\"\n\n[outputs]\nfields = true\ndirectory = \"$out/draglab_fields\"|" "$scene"

run_openfoam() {  # RANKS -> prints "seconds steps"
  clean_case
  local log="$case_dir/log.run$1"
  if [ "$1" -eq 1 ]; then
    (cd "$case_dir" && twoPhaseEulerFoam >"$log" 2>&1)
  else
    (cd "$case_dir" && mpirun --allow-run-as-root --oversubscribe -np 2 twoPhaseEulerFoam -parallel >"$log" 2>&1)
  fi || { echo "run_side_by_side: twoPhaseEulerFoam ($1 rank(s)) failed, see $log" >&2; exit 1; }
  local t steps
  t="$(grep '^ExecutionTime' "$log" | tail -1 | awk '{print $3}')"
  steps="$(grep -c '^Time = ' "$log")"
  echo "$t $steps"
}
run_draglab() {  # -> prints "seconds steps"
  local json="$out/draglab_run.json"
  OMP_NUM_THREADS=1 "$draglab" --db "$out/bench.db" scene run "$scene" --no-store --json \
    >"$json" 2>"$out/draglab_run.err" ||
    { echo "run_side_by_side: draglab failed, see $out/draglab_run.err" >&2; exit 1; }
  "$python3_bin" -c 'import json, sys; r = json.load(open(sys.argv[1])); print(r["wall_s"], r["steps"])' "$json"
}

: >"$out/times.txt"
for r in $(seq 1 "$repeat"); do
  echo "openfoam1 $(run_openfoam 1)" >>"$out/times.txt"
  # Keep the one-rank result for the comparison of the fields.
  rm -rf "$out/openfoam_result" && cp -r "$case_dir/$end_time" "$out/openfoam_result" 2>/dev/null ||
    cp -r "$(ls -d "$case_dir"/[0-9]* | sort -g | tail -1)" "$out/openfoam_result"
  echo "draglab1 $(run_draglab)" >>"$out/times.txt"
  echo "openfoam2 $(run_openfoam 2)" >>"$out/times.txt"
  echo "repetition $r of $repeat done" >&2
done

# ---- untimed: the time-averaged bed over the results window ----
if [ -n "$window" ]; then
  win_case="$out/openfoam_window"
  rm -rf "$win_case" && cp -r "$case_dir" "$win_case"
  (cd "$win_case" && find . -maxdepth 2 -type d -regex '.*/[0-9.e-]+' ! -name 0 -exec rm -rf {} +)
  sed -i "s/^endTime .*/endTime         $window_to;/; s/^writeInterval .*/writeInterval   0.05;/" \
    "$win_case/system/controlDict"
  echo "results window: OpenFOAM (2 ranks) to $window_to s, fields every 0.05 s" >&2
  (cd "$win_case" && mpirun --allow-run-as-root --oversubscribe -np 2 twoPhaseEulerFoam -parallel \
     >log.window 2>&1 && reconstructPar -fields '(alpha.particles)' >log.reconstruct 2>&1) ||
    { echo "run_side_by_side: the OpenFOAM window run failed, see $win_case/log.*" >&2; exit 1; }
  echo "results window: draglab to $window_to s" >&2
  win_scene="$out/fluidised_bed_window.toml"
  sed "s/^duration_s = 0.1$/duration_s = $window_to/; s/^t_ref_s = 0.1$/t_ref_s = $window_to/" \
    "$here/fluidised_bed.toml" >"$win_scene"
  sed -i "s|^range_policy = \"clamp\"|range_policy = \"clamp\"\n\n[outputs]\nfields = true\ninterval_s = 0.05\ndirectory = \"$out/draglab_window\"|" "$win_scene"
  rm -rf "$out/draglab_window"
  OMP_NUM_THREADS=1 "$draglab" --db "$out/bench.db" scene run "$win_scene" --no-store --json \
    >"$out/draglab_window.json" 2>"$out/draglab_window.err" ||
    { echo "run_side_by_side: draglab's window run failed, see $out/draglab_window.err" >&2; exit 1; }
fi

fi  # --analyse-only

"$python3_bin" - "$out" "$end_time" "$(nproc)" "$window_from" "$window_to" <<'PY'
import glob, json, os, re, statistics, sys
import h5py, numpy as np
out, end, cores = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
window = (float(sys.argv[4]), float(sys.argv[5])) if sys.argv[4] else None
cells, nx, nz, dz = 6000, 30, 200, 0.005
runs = {}
for line in open(out + "/times.txt"):
    name, t, steps = line.split()
    runs.setdefault(name, []).append((float(t), int(steps)))
def med(name):
    t = statistics.median(x[0] for x in runs[name])
    steps = runs[name][0][1]
    return t, steps
rows = {}
for name in ("openfoam1", "draglab1", "openfoam2"):
    t, steps = med(name)
    rows[name] = {"seconds": t, "steps": steps, "cell_steps_per_s": cells * steps / t,
                  "simulated_s_per_wall_s": end / t, "runs": len(runs[name])}
text = open(out + "/openfoam_result/alpha.particles").read()
m = re.search(r"internalField\s+nonuniform\s+List<scalar>\s*(\d+)\s*\((.*?)\)\s*;", text, re.S)
of = np.array(m.group(2).split(), float).reshape(nz, nx).mean(axis=1)
with h5py.File(glob.glob(out + "/draglab_fields/*.h5")[0], "r") as f:
    last = sorted(k for k in f if k.startswith("t"))[-1]
    dl = f[last]["phi"][0].mean(axis=1)
def height(p):
    rows_ = np.where(p > 0.5 * 0.55)[0]
    return float((rows_.max() + 1) * dz) if len(rows_) else 0.0
result = {
    "case": "OpenFOAM v1912 twoPhaseEulerFoam laminar/fluidisedBed (kinetic theory) vs draglab tfm",
    "end_time_s": end, "cells": cells, "machine_cores": cores,
    "openfoam_1_rank": rows["openfoam1"], "draglab_1_thread": rows["draglab1"],
    "openfoam_2_ranks": rows["openfoam2"],
    "ratio_cell_steps_vs_openfoam_1": rows["draglab1"]["cell_steps_per_s"] / rows["openfoam1"]["cell_steps_per_s"],
    "ratio_wall_vs_openfoam_1": rows["openfoam1"]["seconds"] / rows["draglab1"]["seconds"],
    "ratio_wall_vs_openfoam_2": rows["openfoam2"]["seconds"] / rows["draglab1"]["seconds"],
    "bed_height_m": {"openfoam": height(of), "draglab": height(dl)},
    "solids_inventory_m": {"openfoam": float(of.sum() * dz), "draglab": float(dl.sum() * dz)},
    "profile_mean_abs_difference": float(np.abs(of[:120] - dl[:120]).mean()),
}
if window:
    # Width-averaged alpha_p per sample in [A, B]; their mean profile, the solids centroid.
    z = (np.arange(nz) + 0.5) * dz
    def of_profile(path):
        txt = open(path).read()
        mm = re.search(r"internalField\s+nonuniform\s+List<scalar>\s*(\d+)\s*\((.*?)\)\s*;", txt, re.S)
        return np.array(mm.group(2).split(), float).reshape(nz, nx).mean(axis=1)
    # In time order (the blocks of the standard errors are consecutive).
    of_dirs = sorted((float(os.path.basename(d)), d)
                     for d in glob.glob(out + "/openfoam_window/[0-9]*")
                     if window[0] - 1e-9 <= float(os.path.basename(d)) <= window[1] + 1e-9
                     and os.path.exists(d + "/alpha.particles"))
    of_samples = [of_profile(d + "/alpha.particles") for _, d in of_dirs]
    dl_timed = []
    with h5py.File(glob.glob(out + "/draglab_window/*.h5")[0], "r") as f:
        for k in f:
            if k.startswith("t") and window[0] - 1e-9 <= f[k].attrs["time_s"] <= window[1] + 1e-9:
                dl_timed.append((float(f[k].attrs["time_s"]), f[k]["phi"][0].mean(axis=1)))
    dl_samples = [p for _, p in sorted(dl_timed, key=lambda x: x[0])]
    def summary(samples):
        # Standard errors from 8 consecutive blocks: each block's mean (and the height of its
        # mean profile), s / sqrt(8).
        mean = np.mean(samples, axis=0)
        c = np.array([float((z * p).sum() / p.sum()) for p in samples])
        low = np.array([float(p[:80].mean()) for p in samples])
        blocks = np.array_split(np.arange(len(samples)), 8)
        def se(values):
            return float(np.std(values, ddof=1) / np.sqrt(len(values)))
        return mean, {"samples": len(samples), "bed_height_m": height(mean),
                      "bed_height_se_m": se([height(np.mean([samples[k] for k in b], axis=0))
                                             for b in blocks]),
                      "centroid_m": float(c.mean()), "centroid_sd_m": float(np.std(c)),
                      "centroid_se_m": se([c[b].mean() for b in blocks]),
                      "mean_solids_fraction_0_to_0.4_m": float(low.mean()),
                      "mean_solids_fraction_0_to_0.4_m_se": se([low[b].mean() for b in blocks])}
    of_mean, of_sum = summary(of_samples)
    dl_mean, dl_sum = summary(dl_samples)
    result["window_s"] = list(window)
    def sigmas(key, se_key):
        d = dl_sum[key] - of_sum[key]
        return {"difference": d, "combined_se": float(np.hypot(dl_sum[se_key], of_sum[se_key])),
                "sigmas": float(abs(d) / max(np.hypot(dl_sum[se_key], of_sum[se_key]), 1e-300))}
    result["time_averaged"] = {"openfoam": of_sum, "draglab": dl_sum,
                               "differences": {
                                   "centroid_m": sigmas("centroid_m", "centroid_se_m"),
                                   "mean_solids_fraction_0_to_0.4_m": sigmas(
                                       "mean_solids_fraction_0_to_0.4_m",
                                       "mean_solids_fraction_0_to_0.4_m_se"),
                                   "bed_height_m": sigmas("bed_height_m", "bed_height_se_m")},
                               "profile_mean_abs_difference_0_to_0.8_m":
                                   float(np.abs(of_mean[:160] - dl_mean[:160]).mean()),
                               "profiles_every_5_cm": [[round(float(z[j]), 4), round(float(of_mean[j]), 4),
                                                        round(float(dl_mean[j]), 4)]
                                                       for j in range(0, 180, 10)]}
lines = ["%-22s %10s %8s %16s %12s" % ("run", "wall s", "steps", "cell-steps/s", "sim s/wall s")]
for key, label in (("openfoam_1_rank", "OpenFOAM 1 rank"), ("draglab_1_thread", "draglab 1 thread"),
                   ("openfoam_2_ranks", "OpenFOAM 2 ranks")):
    r = result[key]
    lines.append("%-22s %10.2f %8d %16.3g %12.4f" % (label, r["seconds"], r["steps"],
                                                      r["cell_steps_per_s"], r["simulated_s_per_wall_s"]))
lines.append("draglab / OpenFOAM: cell-steps/s x%.2f (1 rank); wall time x%.2f (1 rank), x%.2f (2 ranks)" % (
    result["ratio_cell_steps_vs_openfoam_1"], result["ratio_wall_vs_openfoam_1"],
    result["ratio_wall_vs_openfoam_2"]))
lines.append("results at t = %g s: bed height OpenFOAM %.3f m, draglab %.3f m; solids inventory %.4f / %.4f m; "
             "mean |alpha_p difference| over 0-0.6 m %.4f" % (
                 end, result["bed_height_m"]["openfoam"], result["bed_height_m"]["draglab"],
                 result["solids_inventory_m"]["openfoam"], result["solids_inventory_m"]["draglab"],
                 result["profile_mean_abs_difference"]))
if window:
    ta = result["time_averaged"]
    lines.append("time-averaged over %g-%g s (%d / %d samples): bed height OpenFOAM %.3f m, draglab "
                 "%.3f m; solids centroid %.3f +- %.3f / %.3f +- %.3f m (sample sd); mean alpha_p "
                 "0-0.4 m %.3f / %.3f; mean |alpha_p difference| over 0-0.8 m %.4f" % (
                     window[0], window[1], ta["openfoam"]["samples"], ta["draglab"]["samples"],
                     ta["openfoam"]["bed_height_m"], ta["draglab"]["bed_height_m"],
                     ta["openfoam"]["centroid_m"], ta["openfoam"]["centroid_sd_m"],
                     ta["draglab"]["centroid_m"], ta["draglab"]["centroid_sd_m"],
                     ta["openfoam"]["mean_solids_fraction_0_to_0.4_m"],
                     ta["draglab"]["mean_solids_fraction_0_to_0.4_m"],
                     ta["profile_mean_abs_difference_0_to_0.8_m"]))
    for key, label, unit in (("centroid_m", "solids centroid", "m"),
                             ("mean_solids_fraction_0_to_0.4_m", "mean alpha_p 0-0.4 m", ""),
                             ("bed_height_m", "bed height", "m")):
        d = ta["differences"][key]
        lines.append("  draglab - OpenFOAM, %s: %+.3f %s +- %.3f (block standard errors, 8 blocks), "
                     "%.1f sigma" % (label, d["difference"], unit, d["combined_se"], d["sigmas"]))
with open(out + "/results.txt", "w") as f:
    f.write("\n".join(lines) + "\n")
with open(out + "/results.json", "w") as f:
    json.dump(result, f, indent=1)
print("\n".join(lines))
print(json.dumps(result))
PY
