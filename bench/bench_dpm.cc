// bench_dpm: particle-steps per second of the COUPLED DPM run (DpmSimulation: particles -> grid,
// drag per particle, gas step with implicit drag, grid -> particles, DEM substeps) on the seed's
// bed, against the DEM alone on the very same state; JSON on stdout.
//
// Set-up: the scene (default data/scenes/dpm_bubble.toml: 15 x 45 x 1.5 cm, 30 x 90 gas cells,
// 2.5 mm glass, k_n = 7000 N/m, DEM step t_c/20, gas step from the scene) with its first law
// (or --law) loaded from a fresh temporary database seeded with the literature laws (or --db).
// The packing: --bed FILE (bench/bench_util.h format, e.g. the bed LIGGGHTS settled for
// bench/liggghts/run_side_by_side.sh; velocities and spins are zeroed, since Start() wants a bed
// at rest), or --settle (DpmSimulation::Settle: minutes for 35 000 particles). Start() turns the
// background flow on (the jet starts 0.05 s later, after what is timed here), then
// --warmup-gas-steps untimed gas steps, then per thread count --runs timed runs of --gas-steps
// gas steps. A particle-step is one particle advanced by one DEM substep, so the coupled rate is
// N * DEM substeps / wall time and includes the gas and the coupling. After each thread count's
// coupled runs a copy of the current DEM state (same options, same external forces) is timed
// alone for the same number of DEM steps: coupled / alone is the price of the coupling.
//
// Usage: bench_dpm (--bed FILE | --settle) [--scene PATH] [--law NAME@V] [--db PATH]
//                  [--gas-steps 20] [--warmup-gas-steps 5] [--runs 3] [--threads 1,2]
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_util.h"
#include "draglab/consumers/dem.h"
#include "draglab/consumers/dpm.h"
#include "draglab/consumers/scene.h"
#include "draglab/drag_db/database.h"

#ifndef DRAGLAB_SCENE_DIR
#define DRAGLAB_SCENE_DIR "data/scenes"
#endif

using draglab::Database;
using draglab::bench::OptionInteger;
using draglab::bench::OptionValue;
using draglab::bench::ParseNumber;
using draglab::bench::ParseThreadList;
using draglab::consumers::DemSystem;
using draglab::consumers::DpmOptions;
using draglab::consumers::DpmSimulation;
using draglab::consumers::Particles;
using draglab::consumers::Scene;

namespace {

const char* kUsage =
    "usage: bench_dpm (--bed FILE | --settle) [--scene PATH] [--law NAME@V] [--db PATH]\n"
    "                 [--gas-steps G] [--warmup-gas-steps W] [--runs R] [--threads 1,2]\n";

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Removes the temporary database (and SQLite's side files) on every exit path.
struct TemporaryFile {
  std::string path;
  ~TemporaryFile() {
    if (path.empty()) return;
    for (const char* suffix : {"", "-wal", "-shm", "-journal"})
      std::remove((path + suffix).c_str());
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string bed, scene_path = std::string(DRAGLAB_SCENE_DIR) + "/dpm_bubble.toml", law_ref,
                   db_path;
  bool settle = false;
  int gas_steps = 20, warmup_gas_steps = 5, runs = 3;
  std::vector<int> thread_counts{1, 2};
  try {
    for (int a = 1; a < argc; ++a) {
      const std::string arg = argv[a];
      auto value = [&] { return OptionValue(argc, argv, &a); };
      auto integer = [&] { return OptionInteger(argc, argv, &a); };
      if (arg == "--bed")
        bed = value();
      else if (arg == "--settle")
        settle = true;
      else if (arg == "--scene")
        scene_path = value();
      else if (arg == "--law")
        law_ref = value();
      else if (arg == "--db")
        db_path = value();
      else if (arg == "--gas-steps")
        gas_steps = integer();
      else if (arg == "--warmup-gas-steps")
        warmup_gas_steps = integer();
      else if (arg == "--runs")
        runs = integer();
      else if (arg == "--threads")
        thread_counts = ParseThreadList(value());
      else
        throw std::invalid_argument("unknown option " + arg);
    }
    if (bed.empty() == !settle) throw std::invalid_argument("give exactly one of --bed, --settle");
    if (gas_steps < 1 || runs < 1 || warmup_gas_steps < 0)
      throw std::invalid_argument("--gas-steps, --runs must be >= 1, --warmup-gas-steps >= 0");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_dpm: %s\n%s", e.what(), kUsage);
    return 2;
  }

  TemporaryFile temporary;
  try {
    const Scene scene = draglab::consumers::load_scene(scene_path);
    if (law_ref.empty()) law_ref = scene.laws.front();
    if (db_path.empty()) {
      temporary.path = (std::filesystem::temp_directory_path() /
                        ("bench_dpm_" + std::to_string(::getpid()) + ".db"))
                           .string();
      db_path = temporary.path;
    }
    std::shared_ptr<const draglab::Law> law;
    {
      Database db(db_path);
      law = db.load(law_ref, draglab::range_policy_from_string(scene.range_policy));
    }
    DpmSimulation sim(scene, law, DpmOptions{});
    std::string setup;
    if (!bed.empty()) {
      Particles p = draglab::bench::ReadBedFile(bed);
      for (auto* v : {&p.vx, &p.vy, &p.vz, &p.wx, &p.wy, &p.wz})
        std::fill(v->begin(), v->end(), 0.0);
      sim.Start(std::move(p));
      setup = "packing read from " + bed + " (velocities zeroed), Start(), warm-up gas steps";
    } else {
      std::fprintf(stderr, "bench_dpm: settling the scene's bed (minutes for 35 000)...\n");
      sim.Settle();
      setup = "DpmSimulation::Settle(), warm-up gas steps";
    }
    const auto n = static_cast<double>(sim.dem().particles().size());
    for (int s = 0; s < warmup_gas_steps; ++s) sim.Step();
    const std::int64_t dem0 = sim.dem().steps();
    sim.Step();
    const std::int64_t substeps = sim.dem().steps() - dem0;
    if (substeps < 1) throw std::runtime_error("the coupled step made no DEM step");
    std::printf(
        "{\"benchmark\": \"dpm\", \"scene\": \"%s\", \"law\": \"%s\", \"n\": %.0f, "
        "\"setup\": \"%s\", \"gas_dt_s\": %.6g, \"dem_substeps_per_gas_step\": %lld, "
        "\"gas_cells\": %d, \"warmup_gas_steps\": %d, \"gas_steps_per_run\": %d, \"runs\": %d, "
        "\"results\": [",
        scene.name.c_str(), law_ref.c_str(), n, setup.c_str(), sim.gas_dt(),
        static_cast<long long>(substeps), scene.grid.cells_x * scene.grid.cells_y,
        warmup_gas_steps + 1, gas_steps, runs);
    bool first = true;
    for (const int threads : thread_counts) {
      omp_set_num_threads(threads);
      std::vector<double> coupled, gas_rate, alone;
      for (int r = 0; r < runs; ++r) {
        const std::int64_t before = sim.dem().steps();
        const auto t0 = std::chrono::steady_clock::now();
        for (int s = 0; s < gas_steps; ++s) sim.Step();
        const double wall = Seconds(t0);
        coupled.push_back(n * static_cast<double>(sim.dem().steps() - before) / wall);
        gas_rate.push_back(gas_steps / wall);
      }
      // The DEM alone on a copy of the current state, same options and external forces.
      DemSystem dem(sim.dem().options(), sim.dem().particles());
      const double dt = sim.gas_dt() / static_cast<double>(substeps);
      for (int r = 0; r < runs; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        for (std::int64_t s = 0; s < substeps * gas_steps; ++s) dem.step(dt);
        alone.push_back(n * static_cast<double>(substeps * gas_steps) / Seconds(t0));
      }
      const double c = Median(coupled), d = Median(alone);
      std::printf(
          "%s{\"threads\": %d, \"median_particle_steps_per_s\": %.4g, \"min\": %.4g, "
          "\"max\": %.4g, \"median_gas_steps_per_s\": %.4g, "
          "\"dem_alone_median_particle_steps_per_s\": %.4g, \"coupled_over_dem_alone\": %.3f}",
          first ? "" : ", ", threads, c, *std::min_element(coupled.begin(), coupled.end()),
          *std::max_element(coupled.begin(), coupled.end()), Median(gas_rate), d, c / d);
      std::fflush(stdout);
      first = false;
    }
    std::printf("], \"simulated_time_s\": %.6g}\n", sim.time());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_dpm: %s\n", e.what());
    return 2;
  }
  return 0;
}
