// Benchmark: LBM kernel speed against this machine's memory-bandwidth roofline.
//
// Sample runs:
//   build/bench/bench_lbm                      # all threads, 5 runs per figure
//   build/bench/bench_lbm --threads 2 --repeat 7
//
// Prints draglab::lbm::benchmark()'s result as one JSON object: mflups (100^3 all-fluid periodic
// box, double, TRT), mflups_fluid_packing (fluid-node updates per second on a phi = 0.4 random
// packing, d = 16, interpolated bounce-back included; _bb: halfway bounce-back), bandwidth_gbs
// (in-place update kernel b = s b) and roofline_fraction = mflups / (bandwidth / 304 bytes per
// node update). Every figure is the median of the runs (interleaved, so that a slow phase of a
// shared machine hits all of them alike). Reports, never asserts.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "draglab/lbm/lbm.h"

int main(int argc, char** argv) {
  int threads = 0, repeat = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--threads" && i + 1 < argc) {
      threads = std::max(0, std::atoi(argv[++i]));
    } else if (arg == "--repeat" && i + 1 < argc) {
      repeat = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: %s [--threads T] [--repeat R]\n", argv[0]);
      return 2;
    }
  }
  draglab::lbm::BenchOptions options;
  options.threads = threads;
  options.repeat = repeat;
  const draglab::lbm::BenchResult r = draglab::lbm::benchmark(options);
  const double roofline = r.bandwidth_gbs * 1e9 / 304.0 / 1e6;
  std::printf(
      "{\"threads\": %d, \"repeat\": %d, \"mflups\": %.2f, \"mflups_fluid_packing\": %.2f, "
      "\"mflups_fluid_packing_bb\": %.2f, \"packing_to_box_ratio\": %.3f, "
      "\"packing_bb_to_box_ratio\": %.3f, \"bandwidth_gbs\": %.2f, \"roofline_mlups\": %.2f, "
      "\"roofline_fraction\": %.3f}\n",
      r.threads, repeat, r.mflups, r.mflups_fluid_packing, r.mflups_fluid_packing_bb,
      r.mflups > 0.0 ? r.mflups_fluid_packing / r.mflups : 0.0,
      r.mflups > 0.0 ? r.mflups_fluid_packing_bb / r.mflups : 0.0, r.bandwidth_gbs, roofline,
      r.roofline_fraction);
  return 0;
}
