// Fast unit checks of the LBM engine core (lbm_engine/src): streaming and bounce-back against an
// independent dense reference, the exact steady momentum balance, Stokes mode against the full
// equilibrium at vanishing Re, mass conservation, the stability diagnoses (tau near 1/2, Mach
// limit, step limit), target-Re control, float storage, bad input, and the regularized collision
// kernel against its textbook form (Latt & Chopard 2006 with Guo forcing, written out below).
//
// Set-ups: (a) small periodic boxes with random solid flags and the collision switched off
// (omega = 0, no force), where the AA-pattern sweeps must reproduce plain streaming with
// halfway bounce-back exactly; (b) one sphere in a periodic cube (a simple-cubic array) at
// phi = 0.125 with 12 nodes per edge (d = 7.4 lattice units): small enough to converge in well
// under a second, large enough to have all link kinds. References: exact identities of the
// scheme (momentum and mass conservation, linearity), not values copied from the engine.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "collision.h"
#include "d3q19.h"
#include "draglab/arrays/packing.h"
#include "draglab/arrays/voxelization.h"
#include "draglab/error.h"
#include "draglab/lbm/lbm.h"
#include "lattice.h"
#include "solver.h"

namespace draglab {
namespace lbm {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Simple-cubic array: one sphere of volume fraction phi in a periodic cube of `nodes` nodes.
arrays::VoxelGrid simple_cubic_grid(double phi, int nodes) {
  arrays::OrderedPackingOptions options;
  options.lattice = arrays::Lattice::kSimpleCubic;
  options.phi = phi;
  const arrays::Packing packing = arrays::generate_ordered_packing(options);
  arrays::VoxelizationOptions vox;
  vox.resolution = nodes / packing.box_length[0];
  return arrays::voxelize(packing, vox);
}

/// A box with random solid flags and no bodies (for the streaming checks).
arrays::VoxelGrid random_solid_box(std::array<std::int64_t, 3> dims, double solid_fraction,
                                   unsigned seed) {
  arrays::VoxelGrid grid;
  grid.dims = dims;
  grid.solid.assign(static_cast<std::size_t>(grid.num_nodes()), 0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (auto& s : grid.solid) s = u(rng) < solid_fraction ? 1 : 0;
  return grid;
}

/// Independent reference: dense two-lattice streaming with halfway bounce-back, no collision:
/// f_i(x, t+1) = f_i(x - c_i, t) if x - c_i is fluid, else f_opp(i)(x, t).
std::vector<double> reference_stream(const arrays::VoxelGrid& grid, const std::vector<double>& f) {
  const auto& dims = grid.dims;
  std::vector<double> out(f.size(), 0.0);
  for (std::int64_t k = 0; k < dims[2]; ++k) {
    for (std::int64_t j = 0; j < dims[1]; ++j) {
      for (std::int64_t i = 0; i < dims[0]; ++i) {
        const std::int64_t x = grid.index(i, j, k);
        if (grid.solid[x]) continue;
        for (int q = 0; q < d3q19::kQ; ++q) {
          const auto& c = d3q19::kC[q];
          const std::int64_t src =
              grid.index((i - c[0] + dims[0]) % dims[0], (j - c[1] + dims[1]) % dims[1],
                         (k - c[2] + dims[2]) % dims[2]);
          out[19 * x + q] = grid.solid[src] ? f[19 * x + d3q19::kOpposite[q]] : f[19 * src + q];
        }
      }
    }
  }
  return out;
}

// The AA even/odd sweeps with the run-length coded neighbour table must move every population
// exactly as plain streaming + halfway bounce-back does (collision off: omega = 0 makes the
// collision the identity). Exact equality: both only copy values. A non-cubic box with 25 %
// random solids exercises short segments, periodic wrap and bounce-back in all 18 directions;
// 2 threads split it into two work ranges.
TEST(LbmEngineSmoke, AaSweepsReproduceStreamingWithBounceBack) {
  const arrays::VoxelGrid grid = random_solid_box({7, 6, 5}, 0.25, 3);
  const SparseLattice lattice(grid, 2, sizeof(double));
  const LinkTable links = lattice.build_links(grid, WallScheme::kBounceBack);
  SolverSettings settings;
  settings.omega_plus = 0.0;
  settings.omega_minus = 0.0;
  settings.force_x = 0.0;
  settings.interpolated = false;
  auto solver = make_solver(Precision::kDouble, lattice, links, settings, 2);

  std::vector<double> reference(static_cast<std::size_t>(19 * grid.num_nodes()), 0.0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  auto fluid = [&](std::int64_t n) { return grid.solid[lattice.node(n)] == 0; };
  for (std::int64_t n = 0; n < lattice.num_stored(); ++n) {
    if (!fluid(n)) continue;  // ghost (solid neighbour of a fluid node): storage only
    for (int q = 0; q < 19; ++q) {
      const double value = u(rng);
      solver->set_deviation(q, n, value);
      reference[19 * lattice.node(n) + q] = value;
    }
  }
  for (int pair = 0; pair < 3; ++pair) {
    solver->advance_pair(nullptr);
    reference = reference_stream(grid, reference_stream(grid, reference));
    for (std::int64_t n = 0; n < lattice.num_stored(); ++n) {
      if (!fluid(n)) continue;
      for (int q = 0; q < 19; ++q) {
        ASSERT_EQ(solver->deviation(q, n), reference[19 * lattice.node(n) + q])
            << "pair " << pair << ", fluid node " << n << ", direction " << q;
      }
    }
  }
}

// Work split: two threads (two work ranges of x-rows, each sweeping its rows and then doing the
// links of its rows, with the reflected values written across range boundaries) must produce
// the flow of one thread to round-off: same moments and per-body momentum exchange (1e-12
// relative after 40 steps; only the order in which the per-range mass defects and forces are
// summed differs). A random packing of 40 spheres at d = 12 has interpolation fallbacks (one-node
// gaps) and is large enough (> 2 x 32768 fluid nodes) to really use 2 threads.
TEST(LbmEngineSmoke, TwoThreadsMatchOneThread) {
  arrays::RandomPackingOptions packing_options;
  packing_options.phi = 0.3;
  packing_options.n = 40;
  packing_options.seed = 7;
  const arrays::Packing packing = arrays::generate_random_packing(packing_options);
  arrays::VoxelizationOptions vox;
  vox.resolution = 12.0;
  const arrays::VoxelGrid grid = arrays::voxelize(packing, vox);
  const SparseLattice one_range(grid, 1, sizeof(double));
  const SparseLattice two_ranges(grid, 2, sizeof(double));
  ASSERT_EQ(two_ranges.num_ranges(), 2);
  ASSERT_GT(two_ranges.num_fluid(), 2 * 32768);
  const LinkTable links_one = one_range.build_links(grid, WallScheme::kCentralLinear);
  const LinkTable links_two = two_ranges.build_links(grid, WallScheme::kCentralLinear);
  ASSERT_GT(links_one.fallback_links, 0);
  for (bool stokes : {true, false}) {
    SolverSettings settings;
    settings.stokes = stokes;
    settings.omega_plus = 1.0 / 0.9;
    settings.omega_minus = 1.0 / (0.5 + (3.0 / 16.0) / 0.4);
    settings.force_x = 1e-4;
    settings.interpolated = true;
    auto one = make_solver(Precision::kDouble, one_range, links_one, settings, 1);
    auto two = make_solver(Precision::kDouble, two_ranges, links_two, settings, 2);
    std::vector<double> force_one, force_two;
    for (int pair = 0; pair < 20; ++pair) {
      one->advance_pair(&force_one);
      two->advance_pair(&force_two);
    }
    const MomentSummary a = one->moments(), b = two->moments();
    EXPECT_NEAR(b.sum_u[0] / a.sum_u[0], 1.0, 1e-12) << "stokes " << stokes;
    ASSERT_EQ(force_one.size(), force_two.size());
    double total = 0.0;
    for (std::size_t k = 0; k < force_one.size(); k += 3) total += force_one[k];
    for (std::size_t k = 0; k < force_one.size(); ++k) {
      EXPECT_NEAR(force_two[k], force_one[k], 1e-12 * total) << "component " << k;
    }
  }
}

RunOptions quick_options() {
  RunOptions options;
  options.threads = 2;
  options.throw_on_failure = false;
  return options;
}

// Steady state: the momentum the body force puts in, G per fluid node per step, leaves through
// the walls, so sum of body forces = G N_fluid exactly (lbm.md 4.1). With the convergence
// tolerance at 1e-11 the remaining transient contributes below 1e-11 of G N_fluid; round-off
// of the link sums is about 1e-16 times (sum |f c| ~ 30) / (G N_fluid ~ 0.01) ~ 1e-13. Bound:
// 1e-10, for both boundary schemes.
TEST(LbmEngineSmoke, MomentumBalanceAtRoundOffWhenConverged) {
  const arrays::VoxelGrid grid = simple_cubic_grid(0.125, 12);
  for (Boundary boundary : {Boundary::kInterpolated, Boundary::kHalfwayBounceBack}) {
    RunOptions options = quick_options();
    options.boundary = boundary;
    options.tolerance = 1e-11;
    const RunResult r = run(grid, 0.125, options);
    ASSERT_TRUE(r.converged) << r.diagnosis;
    EXPECT_LT(r.momentum_balance_rel, 1e-10) << to_string(boundary);
    // The reported F is the per-body momentum exchange normalised as in lbm.h.
    EXPECT_NEAR(r.F * 3.0 * kPi * r.nu * r.d * r.superficial_velocity,
                r.body_force * static_cast<double>(r.fluid_nodes),
                1e-9 * r.body_force * r.fluid_nodes);
  }
}

// Halfway bounce-back moves populations without changing their sum, and every collision
// conserves mass: the total mass is constant to round-off (1e-13 relative: 19 N additions of
// O(1e-3) deviations per step over a few thousand steps stay far below that).
TEST(LbmEngineSmoke, MassConservedWithBounceBack) {
  arrays::RandomPackingOptions packing_options;
  packing_options.phi = 0.25;
  packing_options.n = 6;
  packing_options.seed = 5;
  const arrays::Packing packing = arrays::generate_random_packing(packing_options);
  RunOptions options = quick_options();
  options.boundary = Boundary::kHalfwayBounceBack;
  options.tolerance = 1e-5;
  options.min_gap_nodes = 0.0;  // a coarse lattice is fine for a conservation check
  const RunResult r = run(packing, 6.0, options);
  ASSERT_TRUE(r.converged) << r.diagnosis;
  EXPECT_LT(std::abs(r.mass_change_rel), 1e-13);
}

// Stokes mode (linear equilibrium, re = 0) against the full equilibrium at the same tiny
// velocity (Stokes mode off, re = 0: lattice Re about 0.03). For a simple-cubic array the first
// inertial correction of F is O(Re^2) (the array is symmetric under x -> -x), here about 1e-3 *
// 0.03^2 ~ 1e-6, and the compressibility error O(Ma^2) ~ 3e-4 * 0.03; the difference must be
// below 1e-4 relative, far smaller than the scheme's discretisation error, while both share
// the same boundary error.
TEST(LbmEngineSmoke, StokesModeMatchesFullEquilibriumAtVanishingRe) {
  const arrays::VoxelGrid grid = simple_cubic_grid(0.125, 12);
  RunOptions options = quick_options();
  options.tolerance = 1e-8;
  options.stokes_mode = RunOptions::StokesMode::kOn;
  const RunResult stokes = run(grid, 0.125, options);
  options.stokes_mode = RunOptions::StokesMode::kOff;
  const RunResult full = run(grid, 0.125, options);
  ASSERT_TRUE(stokes.converged) << stokes.diagnosis;
  ASSERT_TRUE(full.converged) << full.diagnosis;
  EXPECT_TRUE(stokes.stokes_mode);
  EXPECT_FALSE(full.stokes_mode);
  EXPECT_EQ(stokes.re, 0.0);
  EXPECT_GT(full.re, 0.0);
  EXPECT_LT(full.re, 0.1);
  EXPECT_NEAR(stokes.F / full.F, 1.0, 1e-4);
}

// In Stokes mode the scheme is linear in the force, so F does not depend on the force the engine
// picks: a target Re (which rescales the force) must give the same F to the convergence
// tolerance (1e-9 here, so 1e-7 relative is a safe bound), and reach the target Re within its
// band (re_tolerance = 1 %).
TEST(LbmEngineSmoke, StokesModeIsLinearAndHitsTargetRe) {
  const arrays::VoxelGrid grid = simple_cubic_grid(0.125, 12);
  RunOptions options = quick_options();
  options.tolerance = 1e-9;
  const RunResult zero = run(grid, 0.125, options);
  options.re = 2.0;
  options.stokes_mode = RunOptions::StokesMode::kOn;
  const RunResult two = run(grid, 0.125, options);
  ASSERT_TRUE(zero.converged) << zero.diagnosis;
  ASSERT_TRUE(two.converged) << two.diagnosis;
  EXPECT_NEAR(two.re, 2.0, 0.02);
  EXPECT_NEAR(two.F / zero.F, 1.0, 1e-7);
}

// Full equilibrium with a target Re: the force controller must land within re_tolerance.
TEST(LbmEngineSmoke, TargetReReachedWithFullEquilibrium) {
  const arrays::VoxelGrid grid = simple_cubic_grid(0.125, 12);
  RunOptions options = quick_options();
  options.re = 5.0;
  options.tolerance = 1e-6;
  const RunResult r = run(grid, 0.125, options);
  ASSERT_TRUE(r.converged) << r.diagnosis;
  EXPECT_FALSE(r.stokes_mode);
  EXPECT_LE(std::abs(r.re / 5.0 - 1.0), options.re_tolerance);
  EXPECT_TRUE(std::isfinite(r.error_estimate));
  EXPECT_GT(r.error_estimate, 0.0);
}

// Float storage of the shifted populations: the deviations keep ~7 significant digits, so F
// must agree with double to well within 1e-4 (observed ~1e-6; the discretisation error at this
// resolution is ~1e-2).
TEST(LbmEngineSmoke, FloatStorageAgreesWithDouble) {
  const arrays::VoxelGrid grid = simple_cubic_grid(0.125, 12);
  RunOptions options = quick_options();
  options.tolerance = 1e-7;
  const RunResult dbl = run(grid, 0.125, options);
  options.precision = Precision::kFloat;
  const RunResult flt = run(grid, 0.125, options);
  ASSERT_TRUE(dbl.converged) << dbl.diagnosis;
  ASSERT_TRUE(flt.converged) << flt.diagnosis;
  EXPECT_NEAR(flt.F / dbl.F, 1.0, 1e-4);
}

// Fields of the final state: zero velocity in solids, and the mean of the stored velocity over
// the whole box is the superficial velocity the drag was normalised with (to float rounding of
// the stored fields, 1e-6 relative). Progress reports stay in [0, 1] and end at 1.
TEST(LbmEngineSmoke, FieldsAndProgressAreConsistent) {
  const arrays::VoxelGrid grid = simple_cubic_grid(0.125, 12);
  RunOptions options = quick_options();
  options.re = 1.0;
  Fields fields;
  std::vector<double> fractions;
  const RunResult r = run_with_fields(
      grid, 0.125, options, &fields, [&](double f, const std::string&) { fractions.push_back(f); });
  ASSERT_TRUE(r.converged) << r.diagnosis;
  ASSERT_EQ(fields.dims, grid.dims);
  ASSERT_EQ(fields.velocity.size(), 3 * static_cast<std::size_t>(grid.num_nodes()));
  double sum_ux = 0.0;
  for (std::int64_t n = 0; n < grid.num_nodes(); ++n) {
    EXPECT_EQ(fields.solid[n], grid.solid[n]);
    if (grid.solid[n]) {
      EXPECT_EQ(fields.velocity[3 * n], 0.0f);
      EXPECT_EQ(fields.density[n], 0.0f);
    } else {
      // Weakly compressible: |drho| ~ Ma^2 (here max Ma ~ 0.2 with tau capped at 1.5); 10 %
      // would mean Ma ~ 0.3, where the run stops.
      EXPECT_NEAR(fields.density[n], 1.0f, 0.1f);
    }
    sum_ux += fields.velocity[3 * n];
  }
  EXPECT_NEAR(sum_ux / grid.num_nodes() / r.superficial_velocity, 1.0, 1e-6);
  ASSERT_FALSE(fractions.empty());
  for (double f : fractions) {
    EXPECT_GE(f, 0.0);
    EXPECT_LE(f, 1.0);
  }
  EXPECT_EQ(fractions.back(), 1.0);
}

// tau - 1/2 < 1e-3 is refused for TRT: no drag, a diagnosis naming the limit and a remedy, and
// an Error (kOutOfValidity) when throwing is on.
TEST(LbmEngineSmoke, TauTooCloseToHalfIsDiagnosed) {
  const arrays::VoxelGrid grid = simple_cubic_grid(0.125, 12);
  RunOptions options = quick_options();
  options.tau = 0.5005;
  const RunResult r = run(grid, 0.125, options);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(std::isnan(r.F));
  EXPECT_TRUE(std::isnan(r.error_estimate));
  EXPECT_NE(r.diagnosis.find("tau"), std::string::npos) << r.diagnosis;
  EXPECT_NE(r.diagnosis.find("1/2"), std::string::npos) << r.diagnosis;
  EXPECT_NE(r.diagnosis.find("remedy"), std::string::npos) << r.diagnosis;
  options.throw_on_failure = true;
  try {
    run(grid, 0.125, options);
    FAIL() << "expected draglab::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kOutOfValidity);
  }
}

// A target Re far beyond what the lattice can carry at a fixed tau (U = Re nu / d ~ 2) must hit
// the Mach limit and stop with the limit, the step and the node in the diagnosis.
TEST(LbmEngineSmoke, MachLimitStopsTheRun) {
  const arrays::VoxelGrid grid = simple_cubic_grid(0.125, 12);
  RunOptions options = quick_options();
  options.re = 50.0;
  options.tau = 1.5;
  const RunResult r = run(grid, 0.125, options);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(std::isnan(r.F));
  EXPECT_NE(r.diagnosis.find("Mach"), std::string::npos) << r.diagnosis;
  EXPECT_NE(r.diagnosis.find("step"), std::string::npos) << r.diagnosis;
  EXPECT_NE(r.diagnosis.find("node ("), std::string::npos) << r.diagnosis;
  EXPECT_LT(r.steps, options.max_steps);
}

// A failed finite-Re run still says how far it got: the last Re of its history (not a
// measurement; F stays NaN).
TEST(LbmEngineSmoke, FailedRunReportsTheReItReached) {
  const arrays::VoxelGrid grid = simple_cubic_grid(0.125, 12);
  RunOptions options = quick_options();
  options.re = 10.0;
  options.max_steps = 600;
  const RunResult r = run(grid, 0.125, options);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(std::isnan(r.F));
  ASSERT_FALSE(r.history.empty());
  EXPECT_EQ(r.re, r.history.back().re);
  EXPECT_GT(r.re, 0.0);
}

// Hitting max_steps is "not converged", never a drag value.
TEST(LbmEngineSmoke, StepLimitMeansNotConverged) {
  const arrays::VoxelGrid grid = simple_cubic_grid(0.125, 12);
  RunOptions options = quick_options();
  options.max_steps = 20;
  const RunResult r = run(grid, 0.125, options);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(std::isnan(r.F));
  EXPECT_TRUE(r.body_F.empty());
  EXPECT_NE(r.diagnosis.find("max_steps"), std::string::npos) << r.diagnosis;
  EXPECT_FALSE(r.history.empty());
}

// Resolution too low for the gaps: bad input naming the smallest gap in lattice units.
TEST(LbmEngineSmoke, GapTooSmallForResolutionIsBadInput) {
  arrays::OrderedPackingOptions packing_options;
  packing_options.phi = 0.5;  // SC close packing is 0.5236: gap = (1.0155 - 1) d
  const arrays::Packing packing = arrays::generate_ordered_packing(packing_options);
  RunOptions options = quick_options();
  options.min_gap_nodes = 1.0;
  try {
    run(packing, 16.0, options);  // gap = 0.0155 * 16 = 0.25 lattice units
    FAIL() << "expected draglab::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    const std::string message = e.what();
    EXPECT_NE(message.find("gap"), std::string::npos) << message;
    EXPECT_NE(message.find("0.2"), std::string::npos) << message;
    // Remedies: the resolution that would resolve the gap, or a packing with a minimum gap.
    EXPECT_NE(message.find("raise the resolution to at least"), std::string::npos) << message;
    EXPECT_NE(message.find("--min-gap"), std::string::npos) << message;
  }
}

/// The regularized kernel (written in pair form for speed) against the textbook form it must
/// equal: f*_i = feq_i + (1 - omega) w_i (4.5 Q_i : Pi_neq - 1.5 c_i.G) + F_i, with the
/// second-order equilibrium, Pi_neq = sum g c c - drho I/3 - j u, Q_i = c_i c_i - I/3 and Guo's
/// F_i = (1 - omega/2) w_i (3 c_i.G + 9 (c_i.u)(c_i.G) - 3 u.G) (Stokes mode: the equilibrium and
/// Pi_eq linear in j, F_i without its u terms). Random shifted populations; round-off tolerance.
TEST(LbmEngineSmoke, RegularizedKernelIsItsTextbookForm) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> deviation(-0.02, 0.02);
  for (double tau : {0.501, 0.6, 1.0, 1.7}) {
    for (bool stokes : {false, true}) {
      const double omega = 1.0 / tau, G = 3e-4;
      KernelParams<double> p;
      p.omega_plus = p.omega_minus = omega;
      p.force_x = G;
      p.force_even = p.force_odd = (1.0 - 0.5 * omega) * G;
      double g[19], o[19];
      for (double& v : g) v = deviation(rng);
      if (stokes) {
        collide_node<double, CollisionKernel::kRegularized, true>(g, o, p);
      } else {
        collide_node<double, CollisionKernel::kRegularized, false>(g, o, p);
      }
      double drho = 0.0, j[3] = {0.5 * G, 0.0, 0.0}, second[3][3] = {};
      for (int i = 0; i < 19; ++i) {
        drho += g[i];
        for (int a = 0; a < 3; ++a) {
          j[a] += g[i] * d3q19::kC[i][a];
          for (int b = 0; b < 3; ++b) second[a][b] += g[i] * d3q19::kC[i][a] * d3q19::kC[i][b];
        }
      }
      double u[3];
      for (int a = 0; a < 3; ++a) u[a] = stokes ? j[a] : j[a] / (1.0 + drho);
      double pi[3][3];
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          pi[a][b] = second[a][b] - (a == b ? drho / 3.0 : 0.0) - (stokes ? 0.0 : j[a] * u[b]);
        }
      }
      const double ju = j[0] * u[0] + j[1] * u[1] + j[2] * u[2];
      for (int i = 0; i < 19; ++i) {
        SCOPED_TRACE("tau " + std::to_string(tau) + (stokes ? ", Stokes" : "") + ", i " +
                     std::to_string(i));
        const auto& c = d3q19::kC[i];
        const double w = d3q19::weight(i);
        const double cj = c[0] * j[0] + c[1] * j[1] + c[2] * j[2];
        const double cu = c[0] * u[0] + c[1] * u[1] + c[2] * u[2];
        const double feq = w * (drho + 3.0 * cj + (stokes ? 0.0 : 4.5 * cj * cu - 1.5 * ju));
        double q_pi = 0.0;
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) q_pi += (c[a] * c[b] - (a == b ? 1.0 / 3.0 : 0.0)) * pi[a][b];
        }
        const double cG = c[0] * G;
        const double guo =
            (1.0 - 0.5 * omega) * w * (3.0 * cG + (stokes ? 0.0 : 9.0 * cu * cG - 3.0 * u[0] * G));
        const double expected = feq + (1.0 - omega) * w * (4.5 * q_pi - 1.5 * cG) + guo;
        EXPECT_NEAR(o[i], expected, 1e-15);
      }
    }
  }
}

TEST(LbmEngineSmoke, OptionValidationAndNames) {
  RunOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.re = -1.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("re"), std::string::npos);
  options = RunOptions();
  options.tau = 0.4;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("tau"), std::string::npos);
  for (Collision c : {Collision::kBgk, Collision::kTrt, Collision::kRegularized}) {
    EXPECT_EQ(collision_from_string(to_string(c)), c);
  }
  for (Boundary b : {Boundary::kHalfwayBounceBack, Boundary::kInterpolated}) {
    EXPECT_EQ(boundary_from_string(to_string(b)), b);
  }
  for (Precision p : {Precision::kDouble, Precision::kFloat}) {
    EXPECT_EQ(precision_from_string(to_string(p)), p);
  }
  BenchOptions bench;
  EXPECT_TRUE(bench.IsValid(&error)) << error;
  for (double phi : {0.05, 0.7, std::nan("")}) {
    bench.packing_phi = phi;
    EXPECT_FALSE(bench.IsValid(&error));
    EXPECT_NE(error.find("solid fraction"), std::string::npos);
    EXPECT_THROW(benchmark(bench), Error);
  }
  try {
    collision_from_string("mrt");
    FAIL() << "expected draglab::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
  }
  const arrays::VoxelGrid grid = simple_cubic_grid(0.125, 12);
  RunOptions bad = quick_options();
  bad.tolerance = 0.0;
  EXPECT_THROW(run(grid, 0.125, bad), Error);
}

}  // namespace
}  // namespace lbm
}  // namespace draglab
