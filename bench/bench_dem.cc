// bench_dem: DEM particle-steps per second for the seed's bed (2.5 mm glass beads, rho 2526
// kg/m^3, k_n = 7000 N/m, e = 0.97, friction 0.1, box 15 x 45 x 1.5 cm, dt = t_c/20), with 1 and
// 2 OpenMP threads, median of several timed runs; JSON on stdout.
//
// Default set-up (fast to build): the particles are placed on a simple cubic lattice with spacing
// 0.999 d filling the box bottom up (N = 35 000 -> a 24 cm column, ~6 touching neighbours each,
// like a packed bed), then `--warmup` steps under gravity before timing. `--settle` instead pours
// and settles the bed with settle_particles() first (slow: minutes). `--bed FILE` reads a given
// state instead (the side-by-side run with LIGGGHTS, bench/liggghts/run_side_by_side.sh, hands
// over the bed that LIGGGHTS settled). The JSON says which ran.
//
// --bed FILE: x y z vx vy vz wx wy wz diameter density per line, SI, draglab's axes (y up); format
// in bench/bench_util.h. The particle count is the file's.
//
// Contact options, to match another code's set-up (defaults: DemOptions'): --kn [N/m], --dt [s]
// (0 = t_c/20), --wall-restitution, --tangential-damping-ratio (eta_t / eta_n).
// --threads 1,2: the OpenMP thread counts timed, in that order (one process per count gives
// interleaved comparisons).
//
// Usage: bench_dem [--n 35000 | --bed FILE | --settle] [--steps 200] [--runs 5] [--warmup 200]
//                  [--threads 1,2] [--kn K] [--dt S] [--wall-restitution E]
//                  [--tangential-damping-ratio R]
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_util.h"
#include "draglab/consumers/dem.h"

using draglab::bench::OptionInteger;
using draglab::bench::OptionValue;
using draglab::bench::ParseNumber;
using draglab::bench::ParseThreadList;
using draglab::consumers::DemOptions;
using draglab::consumers::DemSystem;
using draglab::consumers::Particles;

namespace {

const char* kUsage =
    "usage: bench_dem [--n N | --bed FILE | --settle] [--steps S] [--runs R] [--warmup W]\n"
    "                 [--threads 1,2] [--kn K] [--dt S] [--wall-restitution E]\n"
    "                 [--tangential-damping-ratio R]\n";

}  // namespace

int main(int argc, char** argv) {
  int n = 35000, steps = 200, runs = 5, warmup = 200;
  bool settle = false, n_given = false;
  std::string bed;
  std::vector<int> thread_counts{1, 2};
  DemOptions o;  // defaults: the seed's box and contact parameters
  try {
    for (int a = 1; a < argc; ++a) {
      const std::string arg = argv[a];
      auto value = [&] { return OptionValue(argc, argv, &a); };
      auto integer = [&] { return OptionInteger(argc, argv, &a); };
      if (arg == "--n") {
        n = integer();
        n_given = true;
      } else if (arg == "--steps") {
        steps = integer();
      } else if (arg == "--runs") {
        runs = integer();
      } else if (arg == "--warmup") {
        warmup = integer();
      } else if (arg == "--settle") {
        settle = true;
      } else if (arg == "--bed") {
        bed = value();
      } else if (arg == "--threads") {
        thread_counts = ParseThreadList(value());
      } else if (arg == "--kn") {
        o.normal_stiffness = ParseNumber(arg, value());
      } else if (arg == "--dt") {
        o.dt = ParseNumber(arg, value());
      } else if (arg == "--wall-restitution") {
        o.wall_restitution = ParseNumber(arg, value());
      } else if (arg == "--tangential-damping-ratio") {
        o.tangential_damping_ratio = ParseNumber(arg, value());
      } else {
        throw std::invalid_argument("unknown option " + arg);
      }
    }
    if (n < 1 || steps < 1 || runs < 1 || warmup < 0)
      throw std::invalid_argument("--n, --steps, --runs must be >= 1, --warmup >= 0");
    if (static_cast<int>(settle) + static_cast<int>(!bed.empty()) + static_cast<int>(n_given) > 1)
      throw std::invalid_argument("--n, --bed and --settle exclude each other");
    std::string error;
    if (!o.IsValid(&error)) throw std::invalid_argument(error);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_dem: %s\n%s", e.what(), kUsage);
    return 2;
  }

  const double d = 2.5e-3, rho = 2526.0;
  Particles p;
  std::string setup;
  try {
    if (!bed.empty()) {
      p = draglab::bench::ReadBedFile(bed);
      n = static_cast<int>(p.size());
      setup = "state read from " + bed + ", then warm-up steps";
    } else if (settle) {
      draglab::consumers::SettleOptions s;
      s.n = n;
      s.diameter = d;
      s.density = rho;
      s.kinetic_energy_tolerance = 1e-5;
      const auto r = draglab::consumers::settle_particles(o, s);
      std::fprintf(stderr, "%s\n", r.BriefReport().c_str());
      p = r.particles;
      setup = "settled with settle_particles";
    } else {
      const double s = 0.999 * d;
      const int nx = static_cast<int>((o.box_max[0] - o.box_min[0]) / s - 0.5);
      const int nz = static_cast<int>((o.box_max[2] - o.box_min[2]) / s - 0.5);
      for (int k = 0; static_cast<int>(p.size()) < n; ++k) {
        for (int j = 0; j < nz && static_cast<int>(p.size()) < n; ++j) {
          for (int i = 0; i < nx && static_cast<int>(p.size()) < n; ++i) {
            p.add(0.5 * d + i * s, 0.5 * d + k * s, 0.5 * d + j * s, d, rho);
          }
        }
      }
      setup = "simple cubic lattice, spacing 0.999 d, then warm-up steps under gravity";
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_dem: %s\n", e.what());
    return 2;
  }
  const int max_threads = std::min(2, omp_get_max_threads());
  double kinetic_after_warmup = 0.0;
  try {
    DemSystem dem(o, p);
    dem.sort_particles();
    dem.advance(warmup * dem.time_step());
    kinetic_after_warmup = dem.kinetic_energy();
    std::printf(
        "{\"benchmark\": \"dem\", \"n\": %d, \"setup\": \"%s\", \"dt_s\": %.6g, "
        "\"contact_time_s\": %.6g, \"normal_stiffness_n_m\": %.6g, \"wall_restitution\": %.6g, "
        "\"tangential_damping_ratio\": %.6g, \"kinetic_energy_after_warmup_j\": %.4g, "
        "\"contacts_per_particle\": %.3f, \"warmup_steps\": %d, \"steps_per_run\": %d, "
        "\"runs\": %d, \"results\": [",
        n, setup.c_str(), dem.time_step(), dem.contact_time(), o.normal_stiffness,
        o.wall_restitution, o.tangential_damping_ratio, kinetic_after_warmup,
        2.0 * dem.contact_count() / n, warmup, steps, runs);
    bool first = true;
    for (const int threads : thread_counts) {
      omp_set_num_threads(threads);
      std::vector<double> rates;
      for (int r = 0; r < runs; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        for (int s = 0; s < steps; ++s) dem.step();
        const double wall =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        rates.push_back(static_cast<double>(n) * steps / wall);
      }
      std::sort(rates.begin(), rates.end());
      std::printf(
          "%s{\"threads\": %d, \"median_particle_steps_per_s\": %.4g, \"min\": %.4g, "
          "\"max\": %.4g}",
          first ? "" : ", ", threads, rates[rates.size() / 2], rates.front(), rates.back());
      first = false;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_dem: %s\n", e.what());
    return 2;
  }
  std::printf("], \"max_threads_available\": %d}\n", max_threads);
  return 0;
}
