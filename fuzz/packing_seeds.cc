// Writes the seed files of fuzz_packing_hdf5 into a directory (scripts/fuzz.sh calls it): small
// random packings (mono-, bi- and lognormal-disperse), the three ordered lattices, and one file
// with the statistics attributes, all through write_packing_hdf5.
//   fuzz_packing_seeds DIR
#include <cstdio>
#include <exception>
#include <string>

#include "draglab/arrays/packing.h"
#include "draglab/arrays/packing_io.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
    return 2;
  }
  namespace a = draglab::arrays;
  const std::string dir = argv[1];
  try {
    int written = 0;
    auto random = [&](const std::string& name, a::SizeDistribution distribution, int n,
                      bool with_statistics) {
      a::RandomPackingOptions o;
      o.phi = 0.2;
      o.n = n;
      o.distribution = distribution;
      o.seed = 7;
      o.equilibration_sweeps = 10;
      const a::Packing p = a::generate_random_packing(o);
      const a::PackingStatistics s = a::compute_statistics(p);
      a::write_packing_hdf5(dir + "/" + name + ".h5", p, with_statistics ? &s : nullptr);
      ++written;
    };
    random("random_mono_4", a::SizeDistribution::kMonodisperse, 4, false);
    random("random_bi_6", a::SizeDistribution::kBidisperse, 6, false);
    random("random_lognormal_5", a::SizeDistribution::kLognormal, 5, false);
    random("random_mono_3_statistics", a::SizeDistribution::kMonodisperse, 3, true);
    for (const char* lattice : {"sc", "bcc", "fcc"}) {
      a::OrderedPackingOptions o;
      o.lattice = a::lattice_from_string(lattice);
      o.phi = 0.3;
      o.cells = 1;
      a::write_packing_hdf5(dir + "/ordered_" + lattice + ".h5", a::generate_ordered_packing(o));
      ++written;
    }
    std::printf("%d packing seeds in %s\n", written, dir.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_packing_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
