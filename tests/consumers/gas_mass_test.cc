// Gas phase validation 2: gas mass conservation with a time-varying void fraction
// (consumers/gas_phase.h), plus bad-input checks.
//
// Set-up: a 0.10 m x 0.20 m bed (20 x 40 cells, 1.5 cm deep), air, background inflow 0.5 m/s
// through the bottom, a 1 cm central jet at 3 m/s opened for 20 ms, pressure outlet at the top,
// no-slip side walls. A Gaussian blob of particles (peak solids fraction pulsing between 0.2 and
// 0.6, width 2 cm) rises and sways through the bed and drags the gas (beta up to 3e3 kg/m^3/s,
// solids velocity = blob velocity). dt = 1e-4 s, 300 steps.
// Reference: the continuity equation d eps/dt + div(eps u) = 0 integrated over the domain:
// inflow = outflow + rho_g d/dt integral(eps) dV, every step. The test recomputes the three terms
// from the returned fields (not from the solver's own diagnostics) and requires the imbalance to
// be round-off, 1e-12 of the inflow for the direct solver, and 1e-7 for CG at a relative
// tolerance of 1e-10 (the residual of a Poisson solve is amplified by the matrix condition
// number ~ (nz)^2 ~ 1e3 relative to the flux scale).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "draglab/consumers/gas_phase.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

constexpr double kPi = 3.14159265358979323846;

GasOptions BedOptions() {
  GasOptions o;
  o.nx = 20;
  o.nz = 40;
  o.width_m = 0.10;
  o.height_m = 0.20;
  o.depth_m = 0.015;
  o.background_velocity_m_s = 0.5;
  o.jet_width_m = 0.01;
  o.jet_velocity_m_s = 3.0;
  o.jet_start_s = 0.00505;  // off the step grid: no round-off at the switch
  o.jet_duration_s = 0.02;
  return o;
}

struct Blob {
  double x, z, vx, vz, phi;
};

Blob BlobAt(double t) {
  return {0.05 + 0.01 * std::sin(2 * kPi * t / 0.02), 0.05 + 1.0 * t,
          0.01 * 2 * kPi / 0.02 * std::cos(2 * kPi * t / 0.02), 1.0,
          0.4 + 0.2 * std::sin(2 * kPi * t / 0.015)};
}

void RunBalance(PoissonSolver solver, double tolerance) {
  GasOptions o = BedOptions();
  o.poisson = solver;
  GasPhase gas(o);
  const double dt = 1e-4;
  Eigen::ArrayXXd eps(o.nx, o.nz), beta(o.nx, o.nz), upx(o.nx, o.nz), upz(o.nx, o.nz);
  auto fill = [&](double t) {
    const Blob b = BlobAt(t);
    for (int j = 0; j < o.nz; ++j) {
      for (int i = 0; i < o.nx; ++i) {
        const double x = (i + 0.5) * gas.dx(), z = (j + 0.5) * gas.dz();
        const double phi =
            b.phi * std::exp(-((x - b.x) * (x - b.x) + (z - b.z) * (z - b.z)) / (0.02 * 0.02));
        eps(i, j) = 1.0 - phi;
        beta(i, j) = 5e3 * phi;
        upx(i, j) = b.vx;
        upz(i, j) = b.vz;
      }
    }
  };
  fill(0.0);
  gas.SetVoidFraction(eps);
  double max_relative = 0.0, max_storage = 0.0;
  const double area = o.width_m * o.depth_m, rho = o.rho_g;
  for (int s = 0; s < 300; ++s) {
    const Eigen::ArrayXXd eps_old = gas.eps();
    fill((s + 1) * dt);
    gas.SetSolids(eps, beta, upx, upz);
    gas.Step(dt);
    // Independent balance from the fields: superficial flux = eps_face * w at the boundaries.
    double in = 0.0, out = 0.0;
    for (int i = 0; i < o.nx; ++i) {
      in += eps(i, 0) * gas.w()(i, 0) * gas.dx();
      out += eps(i, o.nz - 1) * gas.w()(i, o.nz) * gas.dx();
    }
    const double storage = (eps - eps_old).sum() * gas.dx() * gas.dz() / dt;
    const double in_kg = rho * o.depth_m * in;
    const double imbalance = rho * o.depth_m * (in - out - storage);
    max_relative = std::max(max_relative, std::abs(imbalance) / in_kg);
    max_storage = std::max(max_storage, std::abs(storage) / in);
    // The jet must really be injected: the bottom flux is background + jet exactly.
    const double t_new = (s + 1) * dt;
    const bool jet = t_new >= o.jet_start_s && t_new < o.jet_start_s + o.jet_duration_s;
    const double expected_in = o.background_velocity_m_s * o.width_m +
                               (jet ? (o.jet_velocity_m_s - o.background_velocity_m_s) * 0.01 : 0);
    ASSERT_NEAR(in, expected_in, 1e-12 * expected_in) << "step " << s;
    ASSERT_NEAR(gas.diagnostics().mass_imbalance_kg_s / in_kg, 0.0, tolerance) << "step " << s;
    ASSERT_LT(gas.diagnostics().max_divergence_1_s * o.height_m / o.background_velocity_m_s,
              tolerance * 1e3)
        << "step " << s;
  }
  (void)area;
  std::printf(
      "%s: max |in - out - storage| / in = %.3e over 300 steps; max |storage| / in = "
      "%.3f\n%s\n",
      solver == PoissonSolver::kDirectLDLT ? "LDLT" : "CG", max_relative, max_storage,
      gas.diagnostics().BriefReport().c_str());
  EXPECT_LT(max_relative, tolerance);
  EXPECT_GT(max_storage, 0.05) << "the test must exercise the d eps/dt term";
}

TEST(GasMass, InflowEqualsOutflowPlusStorageDirect) {
  RunBalance(PoissonSolver::kDirectLDLT, 1e-12);
}

TEST(GasMass, InflowEqualsOutflowPlusStorageConjugateGradient) {
  RunBalance(PoissonSolver::kConjugateGradient, 1e-7);
}

TEST(GasMass, BadInputNamesTheField) {
  auto expect_bad = [](const GasOptions& o, const std::string& field) {
    std::string why;
    EXPECT_FALSE(o.IsValid(&why)) << field;
    EXPECT_NE(why.find(field), std::string::npos) << why;
    try {
      GasPhase gas(o);
      ADD_FAILURE() << "no throw for " << field;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  GasOptions o = BedOptions();
  EXPECT_TRUE(o.IsValid());
  o.rho_g = 0.0;
  expect_bad(o, "rho_g");
  o = BedOptions();
  o.mu_g = -1.0;
  expect_bad(o, "mu_g");
  o = BedOptions();
  o.jet_width_m = 0.2;  // wider than the bed
  expect_bad(o, "jet_width_m");
  o = BedOptions();
  o.nx = 1;
  expect_bad(o, "nx");

  GasPhase gas(BedOptions());
  Eigen::ArrayXXd eps = Eigen::ArrayXXd::Ones(20, 40), zero = Eigen::ArrayXXd::Zero(20, 40);
  eps(3, 4) = 0.0;
  try {
    gas.SetSolids(eps, zero, zero, zero);
    ADD_FAILURE() << "eps = 0 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("eps(3, 4)"), std::string::npos) << e.what();
  }
  // A time step above the stability limit is refused, naming dt and the remedy.
  try {
    gas.Step(10.0);
    ADD_FAILURE() << "dt = 10 s accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("dt"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
