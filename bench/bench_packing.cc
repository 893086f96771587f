// Benchmark: packing generation and voxelization.
//
// Sample runs:
//   build/bench/bench_packing                 # the cases, 3 repetitions each
//   build/bench/bench_packing --repeat 5
//
// Cases: random monodisperse N = 1000 at phi = 0.6 (goal: under a minute) and N = 4000 at
// phi = 0.4; voxelization of a phi = 0.4 random packing on a 256^3 lattice (time and memory of
// the flags and link lists). Median wall time of the repetitions (different seeds). Reports,
// never asserts.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "draglab/arrays/packing.h"
#include "draglab/arrays/voxelization.h"

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  using namespace draglab::arrays;
  int repeat = 3;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--repeat" && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: %s [--repeat R]\n", argv[0]);
      return 2;
    }
  }
  std::printf("draglab bench_packing: median of %d runs\n", repeat);
  std::printf("%-34s %10s %10s %10s %10s\n", "case", "median s", "min gap", "Q6", "crystal");
  Packing last;
  for (auto [n, phi] : {std::pair<int, double>{1000, 0.6}, {4000, 0.4}}) {
    std::vector<double> t;
    PackingStatistics s;
    for (int r = 0; r < repeat; ++r) {
      RandomPackingOptions o;
      o.n = n;
      o.phi = phi;
      o.seed = 1000 + r;
      const auto t0 = std::chrono::steady_clock::now();
      last = generate_random_packing(o);
      t.push_back(seconds_since(t0));
      s = compute_statistics(last);
    }
    char name[64];
    std::snprintf(name, sizeof name, "random mono N=%d phi=%.1f", n, phi);
    std::printf("%-34s %10.2f %10.2e %10.4f %10.4f\n", name, median(t), s.min_gap, s.q6,
                s.crystalline_fraction);
  }
  // Voxelize the last (N = 4000, phi = 0.4) packing at a resolution giving 256 nodes per edge.
  VoxelizationOptions vo;
  vo.resolution = 256.0 / last.box_length[0];
  std::vector<double> t;
  VoxelGrid g;
  for (int r = 0; r < repeat; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    g = voxelize(last, vo);
    t.push_back(seconds_since(t0));
  }
  std::printf("voxelize %lldx%lldx%lld (d/dx = %.2f): median %.2f s, %zu links, %.1f MiB "
              "(flags + links), phi exact %.6f lattice %.6f\n",
              static_cast<long long>(g.dims[0]), static_cast<long long>(g.dims[1]),
              static_cast<long long>(g.dims[2]), g.resolution(), median(t), g.num_links(),
              g.memory_bytes() / 1048576.0, last.phi(), g.phi_lattice());
  std::printf("extrapolated to 512^3 at the same d/dx... per node: %.2f bytes -> %.2f GiB\n",
              static_cast<double>(g.memory_bytes()) / g.num_nodes(),
              static_cast<double>(g.memory_bytes()) / g.num_nodes() * 512.0 * 512 * 512 /
                  (1024.0 * 1024 * 1024));
  return 0;
}
