// Validation 6: stiff and extreme cases. Each either converges to a sound result or stops with a
// diagnosis that names the limit; the tests assert which, and that a failed run returns no drag
// (F, K, beta NaN, and run() throws draglab::Error unless throw_on_failure is false).
//
// Cases and expected outcomes:
//  a. phi = 0.6 random packing (27 spheres, d = 16, Stokes, TRT + interpolated bounce-back).
//     Hard-sphere packings this dense have near contacts far below one lattice unit (the smallest
//     gap is computed here independently with arrays::min_gap_lattice_units), so with the opt-in
//     check min_gap_nodes = 1 the engine must refuse the resolution as bad input (kInvalidArgument,
//     naming the gap). By default (no check) it must converge: Stokes flow is linear and stable,
//     the momentum balance holds, and F is near the van der Hoef 2005 fit (37.85 at phi = 0.6):
//     within 20 % for one packing at d = 16 (mean gaps of 0.1-0.2 d are only 2-3 nodes wide, so
//     the near-contact regions are under-resolved; realization scatter at N = 27 is several %).
//  b. Re = 1000 at phi = 0.3 (random packing, 27 spheres, d = 16, engine defaults, with TRT and
//     with the regularized collision). The Mach budget (max |u| ~ 0.1) gives nu = U d/Re and
//     tau = 1/2 + 1.3e-3, boundary layers of d/sqrt(Re) = 0.5 node: hopelessly under-resolved.
//     Expected: no drag value; the run stops before the step limit at a stability limit
//     (divergence or the Mach limit), with the node and a remedy named.
//  c. tau = 0.5001: refused up front for TRT and BGK (tau - 1/2 < 1e-3) with a diagnosis that
//     names tau and the remedy, after zero steps. The regularized collision accepts it; in Stokes
//     flow it is stable, but the viscosity 3.3e-5 makes the steady state d^2/nu ~ 4e6 steps
//     away, so within a bounded max_steps it must stop as not converged (step limit named).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "draglab/error.h"
#include "validation_support.h"

namespace draglab {
namespace lbm {
namespace validation {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

void expect_no_drag(const RunResult& r) {
  EXPECT_FALSE(r.converged);
  EXPECT_FALSE(r.diagnosis.empty());
  EXPECT_TRUE(std::isnan(r.F));
  EXPECT_TRUE(std::isnan(r.K));
  EXPECT_TRUE(std::isnan(r.beta_d2_over_mu));
  EXPECT_TRUE(r.body_F.empty());
}

TEST(StiffValidation, DenseRandomPackingPhi06) {
  const arrays::Packing packing = make_random_packing(0.6, 27, 1);
  const double d = 16.0;
  const double smallest_gap = arrays::min_gap_lattice_units(packing, d);
  report("stiff phi=0.6 smallest gap (lattice units)", std::to_string(smallest_gap));
  RunOptions options = stokes_options(Collision::kTrt, Boundary::kInterpolated, kFastStokesTau);
  options.min_gap_nodes = 1.0;
  if (smallest_gap < options.min_gap_nodes) {
    try {
      lbm::run(packing, d, options);
      ADD_FAILURE() << "a gap of " << smallest_gap << " nodes must be refused";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_TRUE(contains(e.what(), "gap")) << e.what();
      report("stiff phi=0.6 opt-in gap check", e.what());
    }
  }
  options.min_gap_nodes = RunOptions().min_gap_nodes;  // the default: no check
  EXPECT_EQ(options.min_gap_nodes, 0.0);
  const RunResult r = lbm::run(packing, d, options);
  char text[128];
  std::snprintf(text, sizeof(text), "vs vdH05 %+.3e, fallback links %lld of %lld | ",
                r.F / van_der_hoef_2005_F(0.6) - 1.0, static_cast<long long>(r.fallback_links),
                static_cast<long long>(r.boundary_links));
  report("stiff phi=0.6 d=16 no gap check", text + format_run(r));
  ASSERT_TRUE(r.converged) << r.diagnosis;
  EXPECT_LT(r.momentum_balance_rel, 1e-5);
  EXPECT_NEAR(r.F, van_der_hoef_2005_F(0.6), 0.2 * van_der_hoef_2005_F(0.6));
}

TEST(StiffValidation, Re1000AtPhi03StopsWithADiagnosis) {
  const arrays::Packing packing = make_random_packing(0.3, 27, 1);
  for (Collision collision : {Collision::kTrt, Collision::kRegularized}) {
    RunOptions options;  // engine defaults: interpolated bounce-back, tau from the Mach budget
    options.collision = collision;
    options.re = 1000.0;
    options.min_gap_nodes = 0.0;
    options.max_steps = 40000;
    options.throw_on_failure = false;
    const RunResult r = lbm::run(packing, 16.0, options);
    report(std::string("stiff Re=1000 phi=0.3 d=16 ") + to_string(collision),
           format_run(r) + " | " + r.diagnosis);
    expect_no_drag(r);
    // A stability limit (divergence: non-finite values or density <= 0; or the Mach limit),
    // hit before the step limit, with the place and a remedy named.
    EXPECT_TRUE(contains(r.diagnosis, "diverged") || contains(r.diagnosis, "Mach")) << r.diagnosis;
    EXPECT_TRUE(contains(r.diagnosis, "node")) << r.diagnosis;
    EXPECT_TRUE(contains(r.diagnosis, "remedy")) << r.diagnosis;
    EXPECT_LT(r.steps, options.max_steps);
    // The throwing variant reports the same failure as an exception.
    options.throw_on_failure = true;
    EXPECT_THROW(lbm::run(packing, 16.0, options), Error);
  }
}

TEST(StiffValidation, TauNearOneHalf) {
  const ScArray sc = make_sc_array(0.125, 12.0);
  for (Collision collision : {Collision::kTrt, Collision::kBgk}) {
    RunOptions options = stokes_options(collision, Boundary::kInterpolated, 0.5001);
    options.throw_on_failure = false;
    const RunResult r = lbm::run(sc.grid, sc.packing.phi(), options);
    report(std::string("stiff tau=0.5001 ") + to_string(collision), r.diagnosis);
    expect_no_drag(r);
    EXPECT_EQ(r.steps, 0);
    EXPECT_TRUE(contains(r.diagnosis, "tau")) << r.diagnosis;
    EXPECT_TRUE(contains(r.diagnosis, "remedy")) << r.diagnosis;
    options.throw_on_failure = true;
    EXPECT_THROW(lbm::run(sc.grid, sc.packing.phi(), options), Error);
  }
  RunOptions options = stokes_options(Collision::kRegularized, Boundary::kInterpolated, 0.5001);
  options.throw_on_failure = false;
  options.max_steps = 20000;
  const RunResult r = lbm::run(sc.grid, sc.packing.phi(), options);
  report("stiff tau=0.5001 rr", format_run(r) + " | " + r.diagnosis);
  expect_no_drag(r);
  EXPECT_TRUE(contains(r.diagnosis, "max_steps")) << r.diagnosis;
}

}  // namespace
}  // namespace validation
}  // namespace lbm
}  // namespace draglab
