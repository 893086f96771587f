// Random and ordered packing generation (draglab/arrays/packing.h).
//
// Set-up: periodic boxes of N spheres, lengths in units of the reference diameter d_ref (the
// sphere diameter, or the Sauter mean diameter of polydisperse packings). Checked against
// definitions, not against earlier output of the generator:
// - no two spheres overlap: the smallest surface gap, recomputed here by brute force over all
//   pairs (minimum image, which is the nearest image in an orthogonal box) and over each sphere's
//   own images, is >= 0 (>= min_gap when requested), for many seeds, phi up to 0.6 and the three
//   size distributions;
// - phi = sum (4/3) pi r^3 / V_box equals the target to 1e-12 (the box is set from the volumes);
// - the same options reproduce the same packing bit for bit (also with one or two threads);
// - size distributions: the bidisperse counts give the closest achievable volume share, the
//   lognormal sample has the requested sigma of ln d, and d_ref is the Sauter diameter;
// - IsValid names the field and the allowed range for each bad input of the issue.
#include "draglab/arrays/packing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "draglab/error.h"

namespace draglab {
namespace arrays {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Smallest surface gap over all pairs and all periodic images, by brute force: the minimum image
// is the nearest image of another sphere; a sphere's own nearest image is one box edge away.
double brute_force_min_gap(const Packing& p) {
  double gap = std::numeric_limits<double>::infinity();
  const double min_edge = std::min({p.box_length[0], p.box_length[1], p.box_length[2]});
  for (std::size_t i = 0; i < p.size(); ++i) {
    gap = std::min(gap, min_edge - 2.0 * p.radii[i]);
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      Vec3 d;
      for (int a = 0; a < 3; ++a) {
        d[a] = p.centers[j][a] - p.centers[i][a];
        d[a] -= p.box_length[a] * std::round(d[a] / p.box_length[a]);
      }
      gap = std::min(gap,
                     std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - p.radii[i] - p.radii[j]);
    }
  }
  return gap;
}

RandomPackingOptions options_for(SizeDistribution dist, double phi, int n, std::uint64_t seed) {
  RandomPackingOptions o;
  o.distribution = dist;
  o.phi = phi;
  o.n = n;
  o.seed = seed;
  o.size_ratio = 4.0;              // The largest ratio of the issue.
  o.large_volume_fraction = 0.8;   // 12 large and 188 small spheres for n = 200.
  o.lognormal_sigma = 0.5;         // The widest lognormal allowed.
  o.equilibration_sweeps = 50;     // Exercises the MC moves; equilibrium is tested elsewhere.
  o.max_crystalline_fraction = 1;  // Overlap checks only: accept every configuration.
  return o;
}

TEST(RandomPacking, NoOverlapsAndExactPhiOverManySeeds) {
  for (SizeDistribution dist : {SizeDistribution::kMonodisperse, SizeDistribution::kBidisperse,
                                SizeDistribution::kLognormal}) {
    for (double phi : {0.1, 0.35, 0.5, 0.6}) {
      for (std::uint64_t seed = 1; seed <= 5; ++seed) {
        SCOPED_TRACE(std::string(to_string(dist)) + " phi " + std::to_string(phi) + " seed " +
                     std::to_string(seed));
        const Packing p = generate_random_packing(options_for(dist, phi, 200, seed));
        ASSERT_EQ(p.size(), 200u);
        // Any overlap is a failure; touching (gap exactly 0) is allowed by the hard-sphere
        // condition but the generator keeps a relative safety of 1e-9, so > 0 is expected.
        const double gap = brute_force_min_gap(p);
        EXPECT_GT(gap, 0.0);
        // The cell-list statistics must find the same smallest gap (same formula, different
        // pair enumeration): agreement to round-off.
        const PackingStatistics s = compute_statistics(p);
        EXPECT_NEAR(s.min_gap, gap, 1e-12);
        EXPECT_EQ(s.overlapping_pairs, 0u);
        // phi from the sphere volumes and the box: exact up to the rounding of ~N additions.
        EXPECT_NEAR(p.phi(), phi, 1e-12);
        for (const Vec3& c : p.centers) {
          for (int a = 0; a < 3; ++a) {
            EXPECT_GE(c[a], 0.0);
            EXPECT_LT(c[a], p.box_length[a]);
          }
        }
      }
    }
  }
}

TEST(RandomPacking, ReachesPhi06WithTheDefaultSweeps) {
  // The target density with the default options (1000 MC sweeps, crystal rejection on).
  RandomPackingOptions o;
  o.phi = 0.6;
  o.n = 300;
  o.seed = 11;
  GenerationSummary summary;
  const Packing p = generate_random_packing(o, &summary);
  EXPECT_GT(brute_force_min_gap(p), 0.0);
  EXPECT_NEAR(p.phi(), 0.6, 1e-12);
  EXPECT_EQ(summary.mc_sweeps, 1000);
  EXPECT_LE(summary.crystalline_fraction, o.max_crystalline_fraction);
  // The step was adapted towards 30 % acceptance; the fixed-step part stays near it (the
  // structure keeps relaxing after the adaptation, so only a loose band is meaningful).
  EXPECT_GT(summary.mc_acceptance, 0.15);
  EXPECT_LT(summary.mc_acceptance, 0.6);
  EXPECT_NE(summary.BriefReport().find("attempt"), std::string::npos);
  EXPECT_NE(summary.FullReport().find("MC acceptance"), std::string::npos);
}

TEST(RandomPacking, MinGapIsRespected) {
  for (SizeDistribution dist : {SizeDistribution::kMonodisperse, SizeDistribution::kBidisperse}) {
    for (double min_gap : {0.02, 0.1}) {
      RandomPackingOptions o = options_for(dist, 0.4, 200, 3);
      o.min_gap = min_gap;
      const Packing p = generate_random_packing(o);
      // The MC keeps |r_ij| >= (r_i + r_j + min_gap)(1 + 1e-9): the gap is min_gap up to 1e-9
      // relative.
      EXPECT_GE(brute_force_min_gap(p), min_gap * (1.0 - 1e-9)) << to_string(dist) << min_gap;
    }
  }
}

TEST(RandomPacking, SameSeedSamePackingBitForBit) {
  for (SizeDistribution dist : {SizeDistribution::kMonodisperse, SizeDistribution::kLognormal}) {
    RandomPackingOptions o = options_for(dist, 0.55, 600, 42);
    o.equilibration_sweeps = 20;
    const Packing a = generate_random_packing(o);
    const Packing b = generate_random_packing(o);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(a.box_length, b.box_length);
    EXPECT_EQ(a.radii, b.radii);
    EXPECT_EQ(a.centers, b.centers);  // Exact comparison of every coordinate.
    EXPECT_EQ(a.settings_json, b.settings_json);
    o.seed = 43;
    const Packing c = generate_random_packing(o);
    EXPECT_NE(a.centers, c.centers);
  }
}

TEST(RandomPacking, ResultDoesNotDependOnTheThreadCount) {
  // The relaxation and the statistics run in parallel from 8192 spheres on: same packing with one
  // thread and with two.
  RandomPackingOptions o = options_for(SizeDistribution::kMonodisperse, 0.35, 9000, 8);
  o.equilibration_sweeps = 2;
#ifdef _OPENMP
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
#endif
  GenerationSummary one, two;
  const Packing a = generate_random_packing(o, &one);
#ifdef _OPENMP
  omp_set_num_threads(2);
#endif
  const Packing b = generate_random_packing(o, &two);
#ifdef _OPENMP
  omp_set_num_threads(threads);
#endif
  EXPECT_EQ(a.centers, b.centers);
  EXPECT_EQ(one.q6, two.q6);
  EXPECT_EQ(one.relaxation_iterations, two.relaxation_iterations);
}

TEST(RandomPacking, BidisperseCountsGiveTheClosestVolumeShare) {
  const int n = 500;
  for (double ratio : {1.5, 2.0, 4.0}) {
    for (double share : {0.0, 0.3, 0.5, 0.9, 1.0}) {
      RandomPackingOptions o = options_for(SizeDistribution::kBidisperse, 0.2, n, 5);
      o.size_ratio = ratio;
      o.large_volume_fraction = share;
      o.equilibration_sweeps = 0;
      const Packing p = generate_random_packing(o);
      const double r_max = *std::max_element(p.radii.begin(), p.radii.end());
      const double r_min = *std::min_element(p.radii.begin(), p.radii.end());
      if (r_max == r_min) {  // One size only: possible for a requested share of 0 or 1 only.
        EXPECT_TRUE(share == 0.0 || share == 1.0) << ratio << " " << share;
        continue;
      }
      EXPECT_NEAR(r_max / r_min, ratio, 1e-13);
      const long n_large = std::count(p.radii.begin(), p.radii.end(), r_max);
      // Achieved share vs the share of n_large +- 1 large spheres: none closer to the request.
      auto share_of = [&](long nl) {
        const double v = nl * ratio * ratio * ratio;
        return v / (v + (n - nl));
      };
      const double achieved = share_of(n_large);
      for (long other : {n_large - 1, n_large + 1}) {
        if (other < 0 || other > n) continue;
        EXPECT_LE(std::fabs(achieved - share), std::fabs(share_of(other) - share) + 1e-12);
      }
      // d_ref is the Sauter mean diameter.
      EXPECT_NEAR(p.sauter_diameter(), 1.0, 1e-12);
      EXPECT_NE(p.settings_json.find("large_volume_fraction_achieved"), std::string::npos);
    }
  }
}

TEST(RandomPacking, LognormalSampleHasTheRequestedSigma) {
  const int n = 4000;
  for (double sigma : {0.1, 0.5}) {
    RandomPackingOptions o = options_for(SizeDistribution::kLognormal, 0.05, n, 9);
    o.lognormal_sigma = sigma;
    o.equilibration_sweeps = 0;
    const Packing p = generate_random_packing(o);
    double mean = 0.0, var = 0.0;
    for (double r : p.radii) mean += std::log(2.0 * r) / n;
    for (double r : p.radii) var += std::pow(std::log(2.0 * r) - mean, 2) / (n - 1);
    // The sample standard deviation of a normal sample has standard error sigma / sqrt(2(n-1));
    // 4 standard errors.
    EXPECT_NEAR(std::sqrt(var), sigma, 4.0 * sigma / std::sqrt(2.0 * (n - 1)));
    EXPECT_NEAR(p.sauter_diameter(), 1.0, 1e-12);
  }
}

TEST(RandomPacking, CuboidBoxFollowsTheAspectRatios) {
  RandomPackingOptions o = options_for(SizeDistribution::kMonodisperse, 0.3, 300, 2);
  o.aspect = {1.0, 2.0, 0.5};
  const Packing p = generate_random_packing(o);
  EXPECT_NEAR(p.box_length[1] / p.box_length[0], 2.0, 1e-14);
  EXPECT_NEAR(p.box_length[2] / p.box_length[0], 0.5, 1e-14);
  EXPECT_NEAR(p.phi(), 0.3, 1e-12);
  EXPECT_GT(brute_force_min_gap(p), 0.0);
}

TEST(RandomPacking, SmallNUsesThePeriodicImages) {
  // n = 2 at phi = 0.3: box edge 1.52 d, so each sphere meets several images of the other one.
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const Packing p =
        generate_random_packing(options_for(SizeDistribution::kMonodisperse, 0.3, 2, seed));
    EXPECT_GT(brute_force_min_gap(p), 0.0);
    EXPECT_NEAR(p.phi(), 0.3, 1e-12);
  }
}

TEST(RandomPacking, ProgressReportsBothStagesWithinZeroAndOne) {
  std::vector<std::string> stages;
  bool in_range = true;
  RandomPackingOptions o = options_for(SizeDistribution::kMonodisperse, 0.3, 100, 1);
  generate_random_packing(o, nullptr, [&](double f, const std::string& stage) {
    in_range = in_range && f >= 0.0 && f <= 1.0;
    if (stages.empty() || stages.back() != stage) stages.push_back(stage);
  });
  EXPECT_TRUE(in_range);
  EXPECT_EQ(stages, (std::vector<std::string>{"relax", "equilibrate"}));
}

TEST(RandomPacking, JammedDensityGivesADiagnosis) {
  // Monodisperse spheres jam near phi = 0.64 (random close packing): the overlaps cannot be
  // removed and the generator must say so instead of returning an overlapping packing.
  RandomPackingOptions o = options_for(SizeDistribution::kMonodisperse, 0.64, 200, 1);
  try {
    generate_random_packing(o);
    FAIL() << "expected a jamming diagnosis at phi = 0.64";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInternal);
    EXPECT_NE(std::string(e.what()).find("jammed"), std::string::npos) << e.what();
  }
}

// Expects IsValid to fail with a message containing every string of `needles`, and
// generate_random_packing to throw kInvalidArgument.
void expect_invalid(const RandomPackingOptions& o, const std::vector<std::string>& needles) {
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  for (const std::string& needle : needles) {
    EXPECT_NE(error.find(needle), std::string::npos) << "'" << needle << "' not in: " << error;
  }
  try {
    generate_random_packing(o);
    ADD_FAILURE() << "no exception for: " << error;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_TRUE(e.is_bad_input());
  }
}

TEST(RandomPackingOptions, BadInputNamesTheFieldAndTheLimit) {
  const RandomPackingOptions good;
  std::string error;
  EXPECT_TRUE(good.IsValid(&error)) << error;

  RandomPackingOptions o = good;
  o.phi = 0.65;
  expect_invalid(o, {"phi", "0.64"});
  o.phi = 0.0;
  expect_invalid(o, {"phi", "0.64"});
  o.phi = std::numeric_limits<double>::quiet_NaN();
  expect_invalid(o, {"phi"});

  o = good;
  o.n = 0;
  expect_invalid(o, {"n = 0", "[1,"});

  o = good;
  o.distribution = SizeDistribution::kBidisperse;
  o.size_ratio = 4.5;
  expect_invalid(o, {"size_ratio", "(1, 4]"});
  o.size_ratio = 1.0;
  expect_invalid(o, {"size_ratio", "(1, 4]"});
  o.size_ratio = 2.0;
  o.large_volume_fraction = 1.2;
  expect_invalid(o, {"large_volume_fraction", "[0, 1]"});
  // Ratio 4 at a large volume share of 0.25 needs about 190 small spheres per large one: 40
  // spheres hold no large sphere, 200 hold one (share 0.25 would need 0.5 of one).
  o.size_ratio = 4.0;
  o.large_volume_fraction = 0.25;
  o.n = 40;
  expect_invalid(o, {"n = 40", "0 large and 40 small",
                     "use n >= " + std::to_string(bidisperse_min_spheres(4.0, 0.25))});
  EXPECT_GT(bidisperse_min_spheres(4.0, 0.25), 100);
  const BidisperseCounts reachable =
      bidisperse_counts(bidisperse_min_spheres(4.0, 0.25), 4.0, 0.25);
  EXPECT_GE(reachable.large, 1);
  EXPECT_NEAR(reachable.large_volume_fraction, 0.25, kBidisperseShareTolerance);
  o.n = bidisperse_min_spheres(4.0, 0.25);
  std::string ok_error;
  EXPECT_TRUE(o.IsValid(&ok_error)) << ok_error;

  o = good;
  o.distribution = SizeDistribution::kLognormal;
  o.lognormal_sigma = 0.0;
  expect_invalid(o, {"lognormal_sigma", "(0, 0.5]"});
  o.lognormal_sigma = 0.7;
  expect_invalid(o, {"lognormal_sigma", "(0, 0.5]"});

  o = good;
  o.min_gap = -0.01;
  expect_invalid(o, {"min_gap", "[0, 0.5]"});
  o.phi = 0.6;
  o.min_gap = 0.05;  // Padded spheres would fill 0.6 * 1.05^3 = 0.69 > 0.64.
  expect_invalid(o, {"min_gap", "0.64"});

  o = good;
  o.aspect = {1.0, 5.0, 1.0};
  expect_invalid(o, {"aspect[1]", "[0.25, 4]"});

  o = good;
  o.equilibration_sweeps = -1;
  expect_invalid(o, {"equilibration_sweeps"});
  o = good;
  o.max_crystalline_fraction = 1.5;
  expect_invalid(o, {"max_crystalline_fraction", "[0, 1]"});
  o = good;
  o.max_attempts = 0;
  expect_invalid(o, {"max_attempts", "[1, 100]"});
}

TEST(RandomPackingOptions, TooFewSpheresForTheBoxIsBadInput) {
  // One sphere at phi = 0.6 needs a box edge of 0.956 d < d: it would overlap its own image.
  RandomPackingOptions o;
  o.n = 1;
  o.phi = 0.6;
  try {
    generate_random_packing(o);
    FAIL() << "expected kInvalidArgument";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("box edge"), std::string::npos) << e.what();
  }
}

TEST(OrderedPacking, LatticesHaveExactPhiAndTheirNearestNeighbourGap) {
  struct Case {
    Lattice lattice;
    std::size_t basis;
    double nearest_over_a;  // Nearest-neighbour distance / lattice constant.
  };
  for (const Case& c : {Case{Lattice::kSimpleCubic, 1, 1.0},
                        Case{Lattice::kBodyCentredCubic, 2, std::sqrt(3.0) / 2.0},
                        Case{Lattice::kFaceCentredCubic, 4, 1.0 / std::sqrt(2.0)}}) {
    for (int cells : {1, 3}) {
      for (double fraction : {0.1, 0.5, 0.9, 1.0}) {
        OrderedPackingOptions o;
        o.lattice = c.lattice;
        o.cells = cells;
        o.phi = fraction * close_packing_phi(c.lattice);
        const Packing p = generate_ordered_packing(o);
        ASSERT_EQ(p.size(), c.basis * cells * cells * cells);
        EXPECT_NEAR(p.phi(), o.phi, 1e-12);
        // Lattice constant from phi: a^3 = n_basis (pi/6) / phi; gap = nearest distance - 1.
        const double a = std::cbrt(c.basis * kPi / 6.0 / o.phi);
        EXPECT_NEAR(p.box_length[0], cells * a, 1e-12);
        EXPECT_NEAR(brute_force_min_gap(p), c.nearest_over_a * a - 1.0, 1e-12);
        for (double r : p.radii) EXPECT_EQ(r, 0.5);
      }
    }
  }
}

TEST(OrderedPacking, ClosePackingLimitsAreTheKnownValues) {
  EXPECT_NEAR(close_packing_phi(Lattice::kSimpleCubic), 0.5235987755982988, 1e-15);
  EXPECT_NEAR(close_packing_phi(Lattice::kBodyCentredCubic), 0.6801747615878315, 1e-15);
  EXPECT_NEAR(close_packing_phi(Lattice::kFaceCentredCubic), 0.7404804896930610, 1e-15);
}

TEST(OrderedPackingOptions, BadInputNamesTheFieldAndTheLimit) {
  struct Case {
    Lattice lattice;
    double phi;
    const char* limit;
  };
  for (const Case& c : {Case{Lattice::kSimpleCubic, 0.53, "0.523599"},
                        Case{Lattice::kBodyCentredCubic, 0.69, "0.680175"},
                        Case{Lattice::kFaceCentredCubic, 0.75, "0.74048"}}) {
    OrderedPackingOptions o;
    o.lattice = c.lattice;
    o.phi = c.phi;
    std::string error;
    EXPECT_FALSE(o.IsValid(&error));
    EXPECT_NE(error.find("phi"), std::string::npos) << error;
    EXPECT_NE(error.find(c.limit), std::string::npos) << error;
    EXPECT_THROW(generate_ordered_packing(o), Error);
  }
  OrderedPackingOptions o;
  o.cells = 0;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("cells"), std::string::npos) << error;
  o.cells = 65;
  EXPECT_FALSE(o.IsValid(&error));
  o.cells = 2;
  o.phi = -0.1;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("phi"), std::string::npos) << error;
}

TEST(PackingNames, RoundTripAndRejectUnknownNames) {
  for (SizeDistribution d : {SizeDistribution::kMonodisperse, SizeDistribution::kBidisperse,
                             SizeDistribution::kLognormal}) {
    EXPECT_EQ(size_distribution_from_string(to_string(d)), d);
  }
  for (Lattice l :
       {Lattice::kSimpleCubic, Lattice::kBodyCentredCubic, Lattice::kFaceCentredCubic}) {
    EXPECT_EQ(lattice_from_string(to_string(l)), l);
  }
  try {
    size_distribution_from_string("gaussian");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("mono, bi, lognormal"), std::string::npos);
  }
  EXPECT_THROW(lattice_from_string("hcp"), Error);
}

}  // namespace
}  // namespace arrays
}  // namespace draglab
