// bench_dem: DEM particle-steps per second for the seed's bed (2.5 mm glass beads, rho 2526
// kg/m^3, k_n = 7000 N/m, e = 0.97, friction 0.1, box 15 x 45 x 1.5 cm, dt = t_c/20), with 1 and
// 2 OpenMP threads, median of several timed runs; JSON on stdout.
//
// Default set-up (fast to build): the particles are placed on a simple cubic lattice with spacing
// 0.999 d filling the box bottom up (N = 35 000 -> a 24 cm column, ~6 touching neighbours each,
// like a packed bed), then `--warmup` steps under gravity before timing. `--settle` instead pours
// and settles the bed with settle_particles() first (slow: minutes). The JSON says which ran.
//
// Usage: bench_dem [--n 35000] [--steps 200] [--runs 5] [--warmup 200] [--settle]
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "draglab/consumers/dem.h"

using draglab::consumers::DemOptions;
using draglab::consumers::DemSystem;
using draglab::consumers::Particles;

int main(int argc, char** argv) {
  int n = 35000, steps = 200, runs = 5, warmup = 200;
  bool settle = false;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    auto next = [&]() { return a + 1 < argc ? std::atoi(argv[++a]) : 0; };
    if (arg == "--n")
      n = next();
    else if (arg == "--steps")
      steps = next();
    else if (arg == "--runs")
      runs = next();
    else if (arg == "--warmup")
      warmup = next();
    else if (arg == "--settle")
      settle = true;
    else {
      std::fprintf(stderr,
                   "usage: bench_dem [--n N] [--steps S] [--runs R] [--warmup W] [--settle]\n");
      return 2;
    }
  }
  if (n < 1 || steps < 1 || runs < 1 || warmup < 0) {
    std::fprintf(stderr, "bench_dem: --n, --steps, --runs must be >= 1, --warmup >= 0\n");
    return 2;
  }
  const double d = 2.5e-3, rho = 2526.0;
  DemOptions o;  // defaults: the seed's box and contact parameters
  Particles p;
  std::string setup;
  try {
    if (settle) {
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
  DemSystem dem(o, p);
  dem.sort_particles();
  dem.advance(warmup * dem.time_step());
  std::printf(
      "{\"benchmark\": \"dem\", \"n\": %d, \"setup\": \"%s\", \"dt_s\": %.4g, "
      "\"contact_time_s\": %.4g, \"contacts_per_particle\": %.3f, \"steps_per_run\": %d, "
      "\"runs\": %d, \"results\": [",
      n, setup.c_str(), dem.time_step(), dem.contact_time(), 2.0 * dem.contact_count() / n, steps,
      runs);
  const int max_threads = std::min(2, omp_get_max_threads());
  for (int threads = 1; threads <= 2; ++threads) {
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
        threads > 1 ? ", " : "", threads, rates[rates.size() / 2], rates.front(), rates.back());
  }
  std::printf("], \"max_threads_available\": %d}\n", max_threads);
  return 0;
}
