// lbm::run_case, the one entry from a packing to a drag record (`lbm run` and campaign units).
//
// Set-up: one sphere in a periodic cube (simple-cubic array), Stokes flow, a few hundred steps.
// Reference: the Sangani-Acrivos series (Sangani & Acrivos 1982), which run_case records beside
// the run; with a hydrodynamic diameter d_h the series is taken at (d_h/d)^3 phi (van der Hoef et
// al. 2005's procedure). Checked: the record is the run's (the same F as lbm::run on the same
// voxelization, to the bit), the lattice and the reference are named, a field file is written
// and its failure kept beside a complete drag, and bad case options are refused before any work.
// Bidisperse packings: each size class's drag with its own diameter, and the mixture's F in van
// der Hoef et al. (2005)'s convention (drag force per unit volume, d_ref the Sauter mean), checked
// against the per-sphere forces it is made of and against beta.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "draglab/error.h"
#include "draglab/lbm/calibration.h"
#include "draglab/lbm/case_run.h"
#include "draglab/lbm/fields_io.h"
#include "validation_support.h"

namespace draglab {
namespace lbm {
namespace validation {
namespace {

arrays::Packing sc_packing(double phi) {
  arrays::OrderedPackingOptions o;
  o.lattice = arrays::Lattice::kSimpleCubic;
  o.phi = phi;
  return arrays::generate_ordered_packing(o);
}

CaseOptions stokes_case(double d) {
  CaseOptions co;
  co.run = stokes_options(Collision::kTrt, Boundary::kInterpolated, kFastStokesTau);
  co.run.threads = 1;
  co.resolution = d;
  return co;
}

TEST(CaseRun, RecordsTheRunTheLatticeAndTheSeriesReference) {
  const arrays::Packing packing = sc_packing(0.125);
  CaseOptions co = stokes_case(8.0);
  co.description = "sc, phi 0.125";
  const CaseResult r = run_case(packing, co);
  ASSERT_TRUE(r.run.converged) << r.run.diagnosis;

  // The same run as lbm::run on the packing at the same d: the same bits.
  const RunResult direct = run(packing, 8.0, co.run);
  EXPECT_EQ(r.run.F, direct.F);
  EXPECT_EQ(r.run.steps, direct.steps);

  EXPECT_EQ(r.spheres, 1);
  EXPECT_GT(r.dims[0], 0);
  EXPECT_NEAR(r.resolution, 8.0, 0.5);  // a whole number of nodes per box edge
  EXPECT_DOUBLE_EQ(r.reference_F, sangani_acrivos_sc_F(0.125));
  // d 8 with interpolated walls: within a few per cent of the series (the engine's own estimate
  // bounds it; docs/validation.md).
  EXPECT_LT(std::abs(r.run.F / r.reference_F - 1.0), r.run.error_estimate);

  const auto j = nlohmann::json::parse(r.ToJson(co));
  EXPECT_EQ(j.at("case"), "sc, phi 0.125");
  EXPECT_EQ(j.at("F").get<double>(), r.run.F);
  EXPECT_EQ(j.at("re_target").get<double>(), 0.0);
  EXPECT_EQ(j.at("spheres").get<int>(), 1);
  EXPECT_EQ(j.at("reference"), "Sangani-Acrivos series (SC, Stokes)");
  EXPECT_DOUBLE_EQ(j.at("error").get<double>(), r.run.F / r.reference_F - 1.0);
  EXPECT_FALSE(j.contains("fields"));
  EXPECT_FALSE(j.contains("calibration"));
}

TEST(CaseRun, HydrodynamicDiameterMovesTheReferenceToPhiHydrodynamic) {
  const arrays::Packing packing = sc_packing(0.125);
  CaseOptions co = stokes_case(8.0);
  co.hydrodynamic_diameter = 8.4;
  const CaseResult r = run_case(packing, co);
  ASSERT_TRUE(r.run.converged) << r.run.diagnosis;
  const double ratio = 8.4 / r.resolution;
  EXPECT_DOUBLE_EQ(r.phi_hydrodynamic, r.run.phi * ratio * ratio * ratio);
  EXPECT_DOUBLE_EQ(r.reference_F, sangani_acrivos_sc_F(r.phi_hydrodynamic));
  const auto j = nlohmann::json::parse(r.ToJson(co));
  EXPECT_EQ(j.at("d_hydrodynamic").get<double>(), 8.4);
  EXPECT_EQ(j.at("reference"), "Sangani-Acrivos series (SC, Stokes) at phi_hydrodynamic");
}

TEST(CaseRun, WritesTheFieldFileOrKeepsItsFailureBesideTheDrag) {
  const arrays::Packing packing = sc_packing(0.1);
  CaseOptions co = stokes_case(6.0);
  co.fields = ::testing::TempDir() + "draglab_case_run_" + std::to_string(::getpid()) + ".h5";
  const CaseResult r = run_case(packing, co);
  ASSERT_TRUE(r.run.converged) << r.run.diagnosis;
  EXPECT_TRUE(r.fields_error.empty()) << r.fields_error;
  const Fields f = read_fields(co.fields);
  EXPECT_EQ(f.dims, r.dims);
  auto j = nlohmann::json::parse(r.ToJson(co));
  EXPECT_EQ(j.at("fields"), co.fields);
  std::remove(co.fields.c_str());
  std::remove(xdmf_path_for(co.fields).c_str());

  co.fields = "/nonexistent-directory/flow.h5";
  const CaseResult failed = run_case(packing, co);
  EXPECT_TRUE(failed.run.converged);
  EXPECT_EQ(failed.run.F, r.run.F);
  EXPECT_FALSE(failed.fields_error.empty());
  j = nlohmann::json::parse(failed.ToJson(co));
  EXPECT_TRUE(j.at("fields").is_null());
  EXPECT_EQ(j.at("fields_error"), failed.fields_error);
}

TEST(CaseRun, BidisperseGivesEachSizeClassAndTheMixtureInVanDerHoefsConvention) {
  arrays::RandomPackingOptions po;
  po.phi = 0.3;
  po.n = 24;
  po.distribution = arrays::SizeDistribution::kBidisperse;
  po.size_ratio = 2.0;
  po.large_volume_fraction = 0.5;
  po.seed = 5;
  const arrays::Packing packing = arrays::generate_random_packing(po);
  const CaseResult r = run_case(packing, stokes_case(8.0));
  ASSERT_TRUE(r.run.converged) << r.run.diagnosis;
  ASSERT_EQ(r.species.size(), 2u);
  const SpeciesDrag& small = r.species[0];
  const SpeciesDrag& large = r.species[1];
  EXPECT_NEAR(large.diameter / small.diameter, 2.0, 1e-12);
  EXPECT_EQ(small.spheres + large.spheres, 24);
  EXPECT_NEAR(small.volume_fraction + large.volume_fraction, 1.0, 1e-12);
  EXPECT_NEAR(large.volume_fraction, 0.5, 0.5 / large.spheres);  // whole spheres

  // The classes from the per-sphere forces (normalised with d_ref, the Sauter mean).
  double sum_y3 = 0.0, sum_small = 0.0, sum_large = 0.0, sum_body = 0.0;
  for (std::size_t s = 0; s < packing.size(); ++s) {
    const double y = 2.0 * packing.radii[s];
    sum_y3 += y * y * y;
    sum_body += r.run.body_F[s];
    (y < 1.0 ? sum_small : sum_large) += r.run.body_F[s] / y;
  }
  EXPECT_NEAR(small.F, sum_small / small.spheres, 1e-12 * small.F);
  EXPECT_NEAR(large.F, sum_large / large.spheres, 1e-12 * large.F);
  // The mixture: total drag per unit volume, f = sum_s F_d,s / V, as F = f d_ref^2/(18 mu phi U)
  // = (sum_s F_d,s/(3 pi mu d_ref U)) / sum_s y_s^3 = sum_i x_i F_i / y_i^2; beta from it as for
  // one size.
  EXPECT_NEAR(r.run.F, sum_body / sum_y3, 1e-12 * r.run.F);
  const double by_classes = small.volume_fraction * small.F / (small.diameter * small.diameter) +
                            large.volume_fraction * large.F / (large.diameter * large.diameter);
  EXPECT_NEAR(r.run.F, by_classes, 1e-12 * r.run.F);
  EXPECT_NEAR(r.run.beta_d2_over_mu, 18.0 * r.run.phi * (1.0 - r.run.phi) * r.run.F,
              1e-12 * r.run.beta_d2_over_mu);
  // The large spheres carry more drag per own diameter (van der Hoef et al. 2005: F_i grows
  // with y_i as (1 - phi) y_i + phi y_i^2; a ratio near 2.5 at phi 0.3).
  EXPECT_GT(large.F / small.F, 1.5);
  EXPECT_LT(large.F / small.F, 3.5);

  const auto j = nlohmann::json::parse(r.ToJson(stokes_case(8.0)));
  ASSERT_EQ(j.at("species").size(), 2u);
  EXPECT_EQ(j.at("species")[1].at("F").get<double>(), large.F);

  // One size: no classes, and F the mean over the spheres.
  const CaseResult mono = run_case(sc_packing(0.125), stokes_case(8.0));
  EXPECT_TRUE(mono.species.empty());
}

TEST(CaseRun, RefusesBadCaseOptionsBeforeAnyWork) {
  const arrays::Packing packing = sc_packing(0.125);
  auto refused = [&packing](const CaseOptions& co, const std::string& field) {
    try {
      run_case(packing, co);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
      return;
    }
    ADD_FAILURE() << "not refused: " << field;
  };
  CaseOptions co = stokes_case(2.0);
  refused(co, "resolution");
  co = stokes_case(8.0);
  co.hydrodynamic_diameter = 20.0;
  refused(co, "hydrodynamic_diameter");
  co.calibrate = true;
  refused(co, "not both");
  co = stokes_case(8.0);
  co.calibrate = true;
  co.run.re = 10.0;
  co.run.tau = 0.0;
  refused(co, "needs tau");
}

}  // namespace
}  // namespace validation
}  // namespace lbm
}  // namespace draglab
