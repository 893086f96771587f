#!/usr/bin/env bash
# Side-by-side DEM benchmark: draglab's DEM (bench/bench_dem) against LIGGGHTS 3.8 (Debian's
# `liggghts`, an MPI build) on the same settled bed and contact model, plus the coupled DPM run
# (bench/bench_dpm). Prints a table and, last, one JSON line; both also go to --out.
#
# The bed: the seed's 35 055 glass spheres (d = 2.5 mm, rho = 2526 kg/m^3) in the 15 x 45 x
# 1.5 cm box with gravity, inserted on a 2.6 mm lattice and settled ONCE in LIGGGHTS (in.settle,
# --settle-ranks, 0.36 s of simulated time as in the peer measurement but at dt = t_c/10 = 1.2e-5 s,
# half the cost; the timed runs use t_c/20 and start with warm-up steps at that step; the settled
# state is kept in --out and reused by later runs with the same settings).
# Both codes then time that settled state: LIGGGHTS from its restart, draglab from the same
# positions, velocities and spins (bench_dem --bed; LIGGGHTS has z up, draglab y up).
# Contact model, both: linear spring-dashpot, k_n = 7082.72 N/m (t_c = 1.2e-4 s), e = 0.97,
# k_t = 2/7 k_n, eta_t = eta_n, Coulomb mu = 0.1 (particles and walls), dt = t_c/20 = 6e-6 s.
# LIGGGHTS's damping gamma * m_eff gives walls (m_eff = m) e = 0.9578: draglab gets that too.
# Timed: `--warmup` untimed steps, then `--steps` timed steps, in a fresh process each time,
# interleaved: LIGGGHTS 1 rank, draglab 1 thread, LIGGGHTS 2 ranks, draglab 2 threads, draglab
# coupled 1 and 2 threads; repeated `--repeat` times; medians and draglab/LIGGGHTS ratios.
# LIGGGHTS's time is its `Loop time`, draglab's the wall time of its step loop. The CPU time
# each process got over its wall time is printed beside the rates (cpu/wall, summed over all its
# threads or ranks): below 1 per thread the machine was shared during that run, so the rates are
# low by about that factor (busy-waiting MPI ranks and OpenMP threads count as CPU time, too).
#
# Installs liggghts (and openmpi-bin) with apt-get if missing (sudo if not root); builds
# nothing: build first with
#   cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
#   cmake --build build --target bench_dem bench_dpm
#
# Usage: bench/liggghts/run_side_by_side.sh [--build-dir DIR] [--out DIR] [--steps S]
#          [--repeat R] [--warmup W] [--settle-steps N] [--settle-dt S] [--settle-ranks P]
#          [--gas-steps G] [--no-coupled] [--resettle] [--quick]
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"

usage() {
  cat <<'EOF'
usage: bench/liggghts/run_side_by_side.sh [options]
  --build-dir DIR     draglab build with bench/bench_dem (and bench/bench_dpm)   [build]
  --out DIR           work directory: settled bed, logs, results     [BUILD/liggghts_side_by_side]
  --steps S           timed steps per run, >= 1                      [2000; --quick 200]
  --repeat R          interleaved repetitions, >= 1                  [3; --quick 1]
  --warmup W          untimed steps before each timed run, >= 0      [200; --quick 50]
  --settle-steps N    LIGGGHTS settling steps, >= 1                  [30000; --quick 7500]
  --settle-dt S       LIGGGHTS settling step [s], (0, 1.2e-5]        [1.2e-5 = t_c/10]
  --settle-ranks P    MPI ranks for settling, 1 or 2 (1 on a busy machine)             [2]
  --gas-steps G       timed gas steps of the coupled run, >= 1       [20; --quick 5]
  --no-coupled        skip the coupled DPM run (bench_dpm)
  --resettle          settle again even if --out holds a settled bed
  --quick             smoke check: 5 700 spheres (20 lattice layers), short runs
EOF
}
fail_usage() {
  echo "run_side_by_side: $*" >&2
  usage >&2
  exit 2
}

build_dir="$root/build" out="" steps="" repeat="" warmup="" settle_steps="" gas_steps=""
settle_dt=1.2e-5 settle_ranks=2
quick=0 coupled=1 resettle=0
while (($#)); do
  case "$1" in
    --build-dir | --out | --steps | --repeat | --warmup | --settle-steps | --settle-dt | \
      --settle-ranks | --gas-steps)
      (($# >= 2)) || fail_usage "$1 needs a value"
      case "$1" in
        --build-dir) build_dir="$2" ;;
        --out) out="$2" ;;
        --steps) steps="$2" ;;
        --repeat) repeat="$2" ;;
        --warmup) warmup="$2" ;;
        --settle-steps) settle_steps="$2" ;;
        --settle-dt) settle_dt="$2" ;;
        --settle-ranks) settle_ranks="$2" ;;
        --gas-steps) gas_steps="$2" ;;
      esac
      shift 2 ;;
    --quick) quick=1; shift ;;
    --no-coupled) coupled=0; shift ;;
    --resettle) resettle=1; shift ;;
    -h | --help) usage; exit 0 ;;
    *) fail_usage "unknown option $1" ;;
  esac
done

# Case: lattice top ztop sets the particle count (57 x 5 sites per 2.6 mm layer).
if ((quick)); then
  ztop=0.0515 # 20 layers: 5 700 spheres
  : "${steps:=200}" "${repeat:=1}" "${warmup:=50}" "${settle_steps:=7500}" "${gas_steps:=5}"
else
  ztop=0.3190 # 123 layers: 35 055 spheres
  : "${steps:=2000}" "${repeat:=3}" "${warmup:=200}" "${settle_steps:=30000}" "${gas_steps:=20}"
fi
check_int() { # name value minimum
  [[ "$2" =~ ^[0-9]+$ ]] && (($2 >= $3)) || fail_usage "$1 must be an integer >= $3, got '$2'"
}
check_int --steps "$steps" 1
check_int --repeat "$repeat" 1
check_int --warmup "$warmup" 0
check_int --settle-steps "$settle_steps" 1
check_int --gas-steps "$gas_steps" 1
[[ "$settle_ranks" =~ ^[12]$ ]] || fail_usage "--settle-ranks must be 1 or 2, got '$settle_ranks'"
# t_c/10 keeps the linear spring well inside its stability limit (~t_c/1.6) while settling.
awk -v v="$settle_dt" \
  'BEGIN { exit !(v ~ /^[0-9.]+([eE][-+]?[0-9]+)?$/ && v > 0 && v <= 1.2e-5) }' ||
  fail_usage "--settle-dt must be in (0, 1.2e-5] s, got '$settle_dt'"

build_dir="$(cd "$build_dir" 2>/dev/null && pwd)" ||
  fail_usage "--build-dir: no such directory (build draglab first, see the script header)"
bench_dem="$build_dir/bench/bench_dem"
bench_dpm="$build_dir/bench/bench_dpm"
[ -x "$bench_dem" ] || fail_usage "no $bench_dem: cmake --build $build_dir --target bench_dem"
if ((coupled)) && [ ! -x "$bench_dpm" ]; then
  fail_usage "no $bench_dpm: cmake --build $build_dir --target bench_dpm (or --no-coupled)"
fi
out="${out:-$build_dir/liggghts_side_by_side}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"

# ---- LIGGGHTS and MPI: install only what is missing (as scripts/setup.sh does) ----
missing=()
command -v liggghts >/dev/null || missing+=(liggghts)
command -v mpirun >/dev/null || missing+=(openmpi-bin)
if ((${#missing[@]})); then
  echo "run_side_by_side: installing missing Debian packages: ${missing[*]}" >&2
  if [ "$(id -u)" -eq 0 ]; then
    sudo=(env DEBIAN_FRONTEND=noninteractive)
  elif command -v sudo >/dev/null; then
    sudo=(sudo env DEBIAN_FRONTEND=noninteractive)
  else
    echo "run_side_by_side: missing ${missing[*]} and neither root nor sudo: install them" \
         "(apt-get install ${missing[*]}) and run again" >&2
    exit 1
  fi
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
mpi=(mpirun --bind-to none) # draglab's OpenMP threads are not pinned either
[ "$(id -u)" -eq 0 ] && mpi+=(--allow-run-as-root)
(($(nproc) >= 2)) || mpi+=(--oversubscribe)
export OMP_NUM_THREADS=1 # LIGGGHTS is MPI only; bench_* set their own thread counts

cp "$here/in.common" "$here/in.settle" "$here/in.time" "$out/"
cd "$out"
fail_run() { # what, log
  echo "run_side_by_side: $1 failed; last lines of $out/$2:" >&2
  tail -n 20 "$2" >&2
  exit 1
}

# ---- settle once in LIGGGHTS (2 ranks), convert the state for draglab ----
settle_key="ztop=$ztop settle_steps=$settle_steps dt=$settle_dt vinit=0.05"
if ((resettle)) || [ ! -f settled.restart ] || [ ! -f bed.txt ] ||
   [ "$(cat settle.key 2>/dev/null)" != "$settle_key" ]; then
  rm -f settled.restart settled.dump bed.txt settle.key
  echo "run_side_by_side: settling in LIGGGHTS, $settle_ranks rank(s), $settle_steps steps" \
       "(full bed: several minutes)..." >&2
  t0=$(date +%s)
  "${mpi[@]}" -np "$settle_ranks" liggghts -in in.settle -var ztop "$ztop" -var vinit 0.05 \
    -var dtsettle "$settle_dt" -var nsettle "$settle_steps" -log log.settle >settle.out 2>&1 ||
    fail_run "LIGGGHTS settling" settle.out
  echo "settle_wall_s=$(($(date +%s) - t0)) ranks=$settle_ranks" >settle.wall
  # LIGGGHTS: x width, y depth, z up -> draglab: x width, y up, z depth. The axis swap is a
  # reflection, so the spin (a pseudovector) changes sign as well.
  awk 'BEGIN { pi = 3.14159265358979324 }
       /^ITEM: ATOMS/ { atoms = 1; print "# x y z vx vy vz wx wy wz diameter density"; next }
       /^ITEM:/ { atoms = 0 }
       atoms { d = 2 * $11; rho = $12 / (pi / 6 * d * d * d)
               printf "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n",
                      $2, $4, $3, $5, $7, $6, -$8, -$10, -$9, d, rho }' settled.dump >bed.txt
  echo "$settle_key" >settle.key
else
  echo "run_side_by_side: reusing the settled bed in $out (--resettle to settle again)" >&2
fi

# ---- interleaved timed runs ----
TIMEFORMAT='%R %U %S' # bash `time`: wall, user, system seconds of a process and its children
dem_args=(--bed bed.txt --kn 7082.72 --dt 6.0e-6 --wall-restitution 0.9578
          --tangential-damping-ratio 1 --warmup "$warmup" --steps "$steps" --runs 1)
rm -f time.*.out dem.*.json dpm.*.json *.cpu
for ((r = 1; r <= repeat; ++r)); do
  for np in 1 2; do
    echo "run_side_by_side: repeat $r/$repeat: LIGGGHTS $np rank(s), draglab $np thread(s)" >&2
    { time "${mpi[@]}" -np "$np" liggghts -in in.time -var px "$np" -var nwarm "$warmup" \
        -var ntime "$steps" -log "log.time.np$np.r$r" >"time.np$np.r$r.out" 2>&1; } \
      2>"time.np$np.r$r.cpu" || fail_run "LIGGGHTS timed run" "time.np$np.r$r.out"
    { time OMP_NUM_THREADS=$np "$bench_dem" "${dem_args[@]}" --threads "$np" \
        >"dem.t$np.r$r.json" 2>"dem.t$np.r$r.err"; } 2>"dem.t$np.r$r.cpu" ||
      fail_run "bench_dem" "dem.t$np.r$r.err"
  done
  if ((coupled)); then
    for t in 1 2; do
      { time OMP_NUM_THREADS=$t "$bench_dpm" --bed bed.txt --gas-steps "$gas_steps" --runs 1 \
          --threads "$t" >"dpm.t$t.r$r.json" 2>"dpm.t$t.r$r.err"; } 2>"dpm.t$t.r$r.cpu" ||
        fail_run "bench_dpm" "dpm.t$t.r$r.err"
    done
  fi
done

# ---- summary: table and one JSON line ----
/usr/bin/python3 - "$repeat" "$steps" "$warmup" "$settle_steps" "$quick" <<'EOF' | tee summary.txt
import glob, json, os, platform, re, statistics, sys, time

repeat, steps, warmup, settle_steps, quick = (int(a) for a in sys.argv[1:])
mps = lambda v: v / 1e6

def liggghts_rate(path):
    text = open(path).read()
    loops = re.findall(r"^Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps "
                       r"with (\d+) atoms", text, re.M)
    if not loops:
        sys.exit(f"run_side_by_side: no 'Loop time' line in {path}")
    wall, procs, nsteps, atoms = loops[-1]  # the last run is the timed one
    return int(atoms) * int(nsteps) / float(wall), int(atoms)

# Settled state: last thermo line of the settling run (step atoms ke c_rke c_zmax c_zavg cpu).
thermo = [l.split() for l in open("settle.out") if re.match(r"^\s*\d+\s+\d+\s+[0-9.eE+-]+\s", l)]
step, atoms, ke, rke, zmax, zavg = (float(x) for x in thermo[-1][:6])
m = 2526 * 3.141592653589793 / 6 * 0.0025 ** 3
settle = {"steps": int(step), "particles": int(atoms), "kinetic_energy_j": ke,
          "rotational_energy_j": rke, "max_z_m": zmax, "mean_z_m": zavg,
          "mean_ke_over_m_g_d": (ke + rke) / atoms / (m * 9.81 * 0.0025)}
if os.path.exists("settle.wall"):
    words = open("settle.wall").read().split()
    settle.update({k: int(v) for k, v in (w.split("=") for w in words)})
settle["dt_s"] = float(re.search(r"dt=(\S+)", open("settle.key").read()).group(1))
version = re.search(r"LIGGGHTS \(Version ([^,)]*)",
                    open(sorted(glob.glob("time.np1.r*.out"))[0]).read())

def cpu_share(path):  # (user + system) / wall of one process, from bash's `time`
    wall, user, system = (float(x) for x in open(path).read().split()[-3:])
    return (user + system) / wall

codes = ("liggghts", "draglab_dem", "draglab_coupled", "coupled_dem_alone")
files = {"liggghts": "time.np{np}.r{r}", "draglab_dem": "dem.t{np}.r{r}",
         "draglab_coupled": "dpm.t{np}.r{r}"}
runs_of, cpu_of, n = {c: {} for c in codes}, {c: {} for c in codes}, None
for np in ("1", "2"):
    names = [files["liggghts"].format(np=np, r=r) for r in range(1, repeat + 1)]
    lig = [liggghts_rate(f + ".out") for f in names]
    dem = [json.load(open(files["draglab_dem"].format(np=np, r=r) + ".json"))
           for r in range(1, repeat + 1)]
    if any(atoms != d["n"] for (_, atoms), d in zip(lig, dem)):
        sys.exit("run_side_by_side: LIGGGHTS and draglab timed different particle counts")
    n = dem[0]["n"]
    runs_of["liggghts"][np] = [v for v, _ in lig]
    runs_of["draglab_dem"][np] = [d["results"][0]["median_particle_steps_per_s"] for d in dem]
    if os.path.exists(files["draglab_coupled"].format(np=np, r=1) + ".json"):
        dpm = [json.load(open(files["draglab_coupled"].format(np=np, r=r) + ".json"))
               for r in range(1, repeat + 1)]
        runs_of["draglab_coupled"][np] = [d["results"][0]["median_particle_steps_per_s"]
                                          for d in dpm]
        runs_of["coupled_dem_alone"][np] = [
            d["results"][0]["dem_alone_median_particle_steps_per_s"] for d in dpm]
        coupled_setup = {k: dpm[0][k] for k in ("scene", "law", "gas_dt_s",
                         "dem_substeps_per_gas_step", "gas_cells", "gas_steps_per_run")}
    for code, pattern in files.items():
        if np in runs_of[code]:
            cpu_of[code][np] = [cpu_share(pattern.format(np=np, r=r) + ".cpu")
                                for r in range(1, repeat + 1)]
runs_of = {c: v for c, v in runs_of.items() if v}
medians = {c: {k: statistics.median(v) for k, v in runs.items()} for c, runs in runs_of.items()}
ratios = {k: medians["draglab_dem"][k] / medians["liggghts"][k] for k in ("1", "2")}

print(f"\nSide-by-side DEM, {n} spheres, settled bed, {steps} timed steps after "
      f"{warmup} warm-up, {repeat} interleaved repeat(s), {os.cpu_count()} CPUs; "
      f"M particle-steps/s")
print(f"settled in LIGGGHTS: {settle['steps']} steps of {settle['dt_s']:g} s, "
      f"KE {settle['kinetic_energy_j']:.3g} J "
      f"(mean KE / (m g d) = {settle['mean_ke_over_m_g_d']:.2g}), mean z {zavg:.4f} m, "
      f"max z {zmax:.4f} m")
print(f"{'code':<30}{'threads':>8}  {'runs':<24}{'median':>8}   cpu/wall per run")
labels = {"liggghts": f"LIGGGHTS {version.group(1).split()[-1] if version else ''} (MPI ranks)",
          "draglab_dem": "draglab DEM", "draglab_coupled": "draglab coupled DPM",
          "coupled_dem_alone": "  same state, DEM alone"}
for np in ("1", "2"):
    for code in labels:
        if code in medians and np in medians[code]:
            runs = " ".join(f"{mps(v):.2f}" for v in runs_of[code][np])
            cpu = " ".join(f"{v:.2f}" for v in cpu_of[code].get(np, []))
            print(f"{labels[code]:<30}{np:>8}  {runs:<24}{mps(medians[code][np]):>8.2f}   {cpu}")
    print(f"{'ratio draglab / LIGGGHTS':<30}{np:>8}  {'':<24}{ratios[np]:>8.2f}")
summary = {"benchmark": "dem_side_by_side", "date": time.strftime("%Y-%m-%d"),
           "machine": f"{os.cpu_count()} CPUs, {platform.processor() or platform.machine()}",
           "liggghts_version": version.group(1) if version else None, "n": n,
           "steps": steps, "warmup": warmup, "repeat": repeat, "quick": bool(quick),
           "settled_bed": settle, "runs_particle_steps_per_s": runs_of,
           "cpu_over_wall": {c: v for c, v in cpu_of.items() if v},
           "median_particle_steps_per_s": medians, "ratio_draglab_over_liggghts": ratios,
           "coupled_setup": coupled_setup if runs_of.get("draglab_coupled") else None}
print(json.dumps(summary))
EOF
echo "run_side_by_side: logs and summary.txt in $out" >&2
