// Packing statistics (compute_statistics) against independent references.
//
// Set-ups and references:
// - Perfect SC, BCC and FCC lattices: global Q6 equals the literature values of
//   data/bond_order_reference_values.csv (Steinhardt, Nelson & Ronchetti 1983; ten Wolde,
//   Ruiz-Montero & Frenkel 1996) with 6, 14 and 12 neighbours; every FCC and BCC sphere is
//   crystal-like by the ten Wolde-Frenkel criterion, also with thermal-like noise.
// - Uncorrelated (ideal-gas) centres: g(x) = 1, mono- and polydisperse.
// - Equilibrium hard-sphere fluid (random packings after the MC equilibration) at phi = 0.2 and
//   0.35, below freezing: the contact value g(1+) agrees with Carnahan-Starling
//   (1 - phi/2)/(1 - phi)^3, averaged over independent realizations.
// - Random packings: Q6 ~ 1/sqrt(bonds) and almost no crystal-like spheres.
// - Small boxes: the minimum gap includes the periodic images (brute force over images).
#include "draglab/arrays/packing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "draglab/error.h"

namespace draglab {
namespace arrays {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct LatticeReference {
  std::string lattice;
  int neighbours = 0;
  double q6 = 0.0;
};

std::vector<LatticeReference> read_lattice_references() {
  std::ifstream in(std::string(DRAGLAB_DATA_DIR) + "/bond_order_reference_values.csv");
  EXPECT_TRUE(in.good()) << "missing data/bond_order_reference_values.csv";
  std::vector<LatticeReference> rows;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {  // Column names.
      header = false;
      continue;
    }
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    LatticeReference r;
    fields >> r.lattice >> r.neighbours >> r.q6;
    rows.push_back(r);
  }
  return rows;
}

TEST(Statistics, PerfectLatticesHaveTheLiteratureQ6) {
  const std::vector<LatticeReference> refs = read_lattice_references();
  ASSERT_EQ(refs.size(), 3u);
  for (const LatticeReference& ref : refs) {
    const Lattice lattice = lattice_from_string(ref.lattice);
    for (int cells : {1, 2, 4}) {
      // The neighbour cutoff scales with the density: the same shells at every phi.
      for (double fraction : {0.2, 0.7, 1.0}) {
        OrderedPackingOptions o;
        o.lattice = lattice;
        o.cells = cells;
        o.phi = fraction * close_packing_phi(lattice);
        const PackingStatistics s = compute_statistics(generate_ordered_packing(o));
        SCOPED_TRACE(ref.lattice + " cells " + std::to_string(cells) + " phi " +
                     std::to_string(o.phi));
        // The references have five digits: half a unit of the last digit plus round-off.
        EXPECT_NEAR(s.q6, ref.q6, 1e-5);
        EXPECT_NEAR(s.mean_neighbours, ref.neighbours, 1e-12);
        EXPECT_NEAR(s.phi, o.phi, 1e-12);
        EXPECT_EQ(s.overlapping_pairs, 0u);  // Touching at close packing is not an overlap.
        // SC spheres have only 6 bonds, fewer than the 7 connections the criterion asks for.
        EXPECT_EQ(s.crystalline_fraction, lattice == Lattice::kSimpleCubic ? 0.0 : 1.0);
        if (fraction == 1.0) {
          EXPECT_NEAR(s.min_gap, 0.0, 1e-12);
        }
      }
    }
  }
}

TEST(Statistics, NoisyFccIsStillDetectedAsCrystal) {
  // FCC at phi = 0.5 with every centre displaced uniformly by up to 0.05 d per axis (rms 0.05 d,
  // about the vibration amplitude of a hard-sphere crystal near melting, Lindemann ratio ~ 0.1):
  // the detector that rejects crystallised random packings must still see a crystal.
  OrderedPackingOptions o;
  o.lattice = Lattice::kFaceCentredCubic;
  o.cells = 5;
  o.phi = 0.5;
  Packing p = generate_ordered_packing(o);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (Vec3& c : p.centers) {
    for (int a = 0; a < 3; ++a) {
      c[a] += u(rng);
      c[a] -= p.box_length[a] * std::floor(c[a] / p.box_length[a]);
    }
  }
  const PackingStatistics s = compute_statistics(p);
  EXPECT_GT(s.crystalline_fraction, 0.95);
  EXPECT_GT(s.q6, 0.45);  // Noise lowers Q6 below 0.5745, far above the fluid's ~0.03.
}

// Packing of n centres placed uniformly at random (overlaps allowed): an ideal gas.
Packing ideal_gas(int n, double box, bool polydisperse, std::uint64_t seed) {
  Packing p;
  p.box_length = {box, box, box};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < n; ++i) {
    p.centers.push_back({u(rng) * box, u(rng) * box, u(rng) * box});
    p.radii.push_back(polydisperse ? 0.2 + 0.6 * u(rng) : 0.5);
  }
  return p;
}

TEST(Statistics, IdealGasHasGEqualToOne) {
  // 2000 uncorrelated centres in a box of edge 20 d: the pairs with x < 3 stay within half the
  // box (3 x (r_i + r_j) <= 4.8 < 10), so no pair is counted through two images.
  for (bool poly : {false, true}) {
    const Packing p = ideal_gas(2000, 20.0, poly, poly ? 2 : 1);
    const PackingStatistics s = compute_statistics(p);
    ASSERT_EQ(s.g_r.size(), 300u);
    // Pair-count-weighted mean of g over two ranges of x: the ideal count is proportional to the
    // shell volume x^2 dx. Poisson statistics: relative scatter 1/sqrt(expected pairs); 4 sigma
    // (3400 pairs in [0.5, 1.5): 6.9 %; 24700 in [1.5, 3): 2.5 %).
    for (const auto& range : {std::pair<double, double>{0.5, 1.5}, {1.5, 3.0}}) {
      double weighted = 0.0, weight = 0.0;
      for (std::size_t b = 0; b < s.g_r.size(); ++b) {
        const double x = s.g_r_x[b];
        if (x < range.first || x >= range.second) continue;
        weighted += s.g_r[b] * x * x;
        weight += x * x;
      }
      // Expected pairs with <(r_i + r_j)^3> = 1 (mono); the polydisperse radii U(0.2, 0.8) give
      // <(a + b)^3> = 2 E a^3 + 6 E a E a^2 = 1.18, more pairs, so this tolerance is conservative.
      const double expected_pairs = 0.5 * 2000.0 * 1999.0 * (4.0 * kPi / 3.0) *
                                    (std::pow(range.second, 3) - std::pow(range.first, 3)) / 8000.0;
      EXPECT_NEAR(weighted / weight, 1.0, 4.0 / std::sqrt(expected_pairs))
          << (poly ? "poly " : "mono ") << range.first << ".." << range.second;
    }
  }
}

TEST(Statistics, MinimumGapCountsPeriodicImages) {
  // Two spheres of radius 0.3 in a box of edge 1.5: own images 1.5 apart (gap 0.9), the other
  // sphere's nearest image at distance sqrt(0.3^2 + 0.6^2 + 0.1^2) = 0.678 through the boundary.
  Packing p;
  p.box_length = {1.5, 1.5, 1.5};
  p.centers = {{0.1, 0.2, 0.75}, {1.3, 0.8, 0.65}};
  p.radii = {0.3, 0.3};
  const PackingStatistics s = compute_statistics(p);
  const double nearest = std::sqrt(0.3 * 0.3 + 0.6 * 0.6 + 0.1 * 0.1);
  EXPECT_NEAR(s.min_gap, nearest - 0.6, 1e-12);
  EXPECT_EQ(s.overlapping_pairs, 0u);
  // Overlap through the boundary: sphere 1 at x = 1.1 is 0.5 from sphere 0's image at 1.6.
  p.centers[1] = {1.1, 0.2, 0.75};
  const PackingStatistics t = compute_statistics(p);
  EXPECT_NEAR(t.min_gap, -0.1, 1e-12);
  EXPECT_EQ(t.overlapping_pairs, 1u);
}

TEST(Statistics, RandomPackingsHaveNoBondOrder) {
  // For N_b independent isotropic bonds, sum_m |Q_6m|^2 is a sum of 13 squared Gaussians, so
  // sqrt(N_b) Q6 ~ sqrt(chi2_13 / 13): mean ~1, 99.99 % quantile 1.73. In a dense fluid the ~12
  // bonds of a coordination shell are correlated (local polytetrahedral order), which widens the
  // distribution by up to sqrt(12 / 2) ~ 2.4 (bonds correlated in groups of ~6 independent
  // pairs); 1.73 * 2.4 ~ 4.2, bound 5 / sqrt(N_b). A crystal gives 0.57 sqrt(N_b) ~ 30 here.
  for (SizeDistribution dist : {SizeDistribution::kMonodisperse, SizeDistribution::kBidisperse,
                                SizeDistribution::kLognormal}) {
    for (double phi : {0.3, 0.55}) {
      RandomPackingOptions o;
      o.n = 500;
      o.phi = phi;
      o.distribution = dist;
      o.size_ratio = 3.0;
      o.seed = 21;
      o.equilibration_sweeps = 200;
      o.max_crystalline_fraction = 1.0;  // Measure, do not reject.
      const PackingStatistics s = compute_statistics(generate_random_packing(o));
      const double bonds = 0.5 * s.mean_neighbours * o.n;
      SCOPED_TRACE(std::string(to_string(dist)) + " phi " + std::to_string(phi));
      EXPECT_LT(s.q6, 5.0 / std::sqrt(bonds));
      // A fluid has about 12 neighbours within the density-scaled cutoff (the first shell); the
      // size-scaled cutoff of polydisperse packings counts fewer small-large bonds.
      EXPECT_GT(s.mean_neighbours, 6.0);
      EXPECT_LT(s.mean_neighbours, 16.0);
      // Crystal-like spheres need >= 7 aligned bonds; in a fluid that is rare: 1 % allowed
      // (a crystal nucleus of ~ 5 spheres).
      EXPECT_LT(s.crystalline_fraction, 0.01);
      EXPECT_EQ(s.overlapping_pairs, 0u);
      EXPECT_GT(s.min_gap, 0.0);
    }
  }
}

// Least-squares line through (x, y): returns {intercept at x = 1, slope}.
std::pair<double, double> line_fit_at_one(const std::vector<double>& x,
                                          const std::vector<double>& y) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = x[i] - 1.0;
    n += 1;
    sx += t;
    sy += y[i];
    sxx += t * t;
    sxy += t * y[i];
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  return {(sy - slope * sx) / n, slope};
}

TEST(Statistics, ContactValueOfTheHardSphereFluidIsCarnahanStarling) {
  // R = 30 independent monodisperse packings of N spheres per phi (N = 1000 at phi = 0.2, where
  // fewer pairs are near contact, N = 500 at phi = 0.35), each equilibrated with
  // 300 MC sweeps. Equilibration: starting from the relaxed (over-contacted) configuration, the
  // contact value at phi = 0.35 reaches its plateau after ~100 sweeps (measured while developing:
  // 6.5 after 0, 3.2 after 50, 3.0 after 100 sweeps), so 300 sweeps leave a factor 3 margin.
  //
  // Tolerance, from the statistics of this very run:
  //  * 4 standard errors of the mean over the realizations (sample scatter / sqrt(R));
  //  * the bias of the linear extrapolation: for g(1 + t) ~ g_c exp(-k t) the least-squares line
  //    over [0, w] misses the intercept by g_c k^2 w^2 / 12 (the line through t^2 on [0, w] has
  //    intercept -w^2/6); k = -slope/intercept of the fit to the averaged g;
  //  * 1 % for Carnahan-Starling itself (it matches simulated hard-sphere pressures to better
  //    than 1 % below freezing).
  const StatisticsOptions so;  // bin 0.01, fit over [1, 1.1]
  const int realizations = 30;
  for (double phi : {0.2, 0.35}) {
    std::vector<double> contacts;
    std::vector<double> mean_g;
    std::vector<double> x;
    for (int r = 0; r < realizations; ++r) {
      RandomPackingOptions o;
      o.n = phi < 0.3 ? 1000 : 500;
      o.phi = phi;
      o.seed = 1000 + r;
      o.equilibration_sweeps = 300;
      const PackingStatistics s = compute_statistics(generate_random_packing(o), so);
      contacts.push_back(s.g_contact);
      if (mean_g.empty()) {
        mean_g.assign(s.g_r.size(), 0.0);
        x = s.g_r_x;
      }
      for (std::size_t b = 0; b < s.g_r.size(); ++b) mean_g[b] += s.g_r[b] / realizations;
    }
    double mean = 0.0, var = 0.0;
    for (double c : contacts) mean += c / realizations;
    for (double c : contacts) var += (c - mean) * (c - mean) / (realizations - 1);
    const double standard_error = std::sqrt(var / realizations);

    std::vector<double> fit_x, fit_y;
    for (std::size_t b = 0; b < x.size(); ++b) {
      if (x[b] > 1.0 && x[b] < 1.0 + so.contact_fit_width) {
        fit_x.push_back(x[b]);
        fit_y.push_back(mean_g[b]);
      }
    }
    const auto [intercept, slope] = line_fit_at_one(fit_x, fit_y);
    const double k = -slope / intercept;
    const double bias = intercept * k * k * so.contact_fit_width * so.contact_fit_width / 12.0;
    const double reference = carnahan_starling_contact(phi);
    const double tolerance = 4.0 * standard_error + bias + 0.01 * reference;
    EXPECT_NEAR(mean, reference, tolerance)
        << "phi " << phi << ": se " << standard_error << ", extrapolation bias " << bias;
    // The tolerance must stay meaningful: below 10 % of the value.
    EXPECT_LT(tolerance, 0.1 * reference);
    // g vanishes inside contact (no overlaps) and tends to 1 far away.
    EXPECT_EQ(mean_g[95], 0.0);
    EXPECT_NEAR(mean_g[280], 1.0, 0.1);
  }
}

TEST(Statistics, CarnahanStarlingContactValue) {
  // (1 - phi/2)/(1 - phi)^3: 1 for the ideal gas; 0.85 / 0.343 = 2.478134111 at phi = 0.3.
  EXPECT_EQ(carnahan_starling_contact(0.0), 1.0);
  EXPECT_NEAR(carnahan_starling_contact(0.3), 2.478134111, 1e-9);
  EXPECT_THROW(carnahan_starling_contact(1.0), Error);
  EXPECT_THROW(carnahan_starling_contact(-0.1), Error);
}

TEST(Statistics, BadOptionsAndPackingsAreRejected) {
  OrderedPackingOptions oo;
  const Packing p = generate_ordered_packing(oo);
  StatisticsOptions so;
  so.g_r_bin = 0.0;
  EXPECT_THROW(compute_statistics(p, so), Error);
  so = StatisticsOptions();
  so.g_r_max = 1.05;  // Below 1 + contact_fit_width.
  EXPECT_THROW(compute_statistics(p, so), Error);
  Packing bad = p;
  bad.radii[0] = -1.0;
  try {
    compute_statistics(bad);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("radius"), std::string::npos);
  }
  Packing empty;
  EXPECT_THROW(compute_statistics(empty), Error);
}

}  // namespace
}  // namespace arrays
}  // namespace draglab
