// KTGF closures (consumers/ktgf.h) against independent references.
//
// (1) g0 of the four radial distributions against the published-formula table of
//     data/ktgf_radial_distribution_reference.csv (tolerance: half a unit of the printed digit).
// (2) The Gidaspow set against Gidaspow's book forms written out here in their own grouping
//     (Gidaspow 1994; Ding & Gidaspow 1990):
//       P_s   = rho phi theta [1 + 2 (1 + e) phi g0]
//       mu_s  = (4/5) phi^2 rho d g0 (1 + e) sqrt(theta/pi)
//               + 10 rho d sqrt(pi theta) / (96 (1 + e) g0) [1 + (4/5) g0 phi (1 + e)]^2
//       kappa = 150 rho d sqrt(pi theta) / (384 (1 + e) g0) [1 + (6/5) phi g0 (1 + e)]^2
//               + 2 phi^2 rho d g0 (1 + e) sqrt(theta/pi)
//       gamma = 12 (1 - e^2) phi^2 rho g0 theta^1.5 / (d sqrt(pi)),
//     to round-off (1e-12 relative): ktgf.cc groups them by eta = (1 + e)/2.
// (3) The Nieuwland set differs from Gidaspow's only by the Chapman-Cowling factors 1.01600
//     and 1.02513 of the dilute parts of mu and kappa and by the -div v term of gamma.
// (4) Limits: elastic particles (e = 1) do not dissipate; the Knudsen limiter changes a dense
//     state by < 0.5 % (its factor on the dilute part is 1 - mfp/L ~ 1 - 1.2 % at phi = 0.55,
//     and the dilute part is a quarter of mu there) and makes the dilute viscosity
//     proportional to phi; the
//     Johnson-Jackson pressure and the Schaeffer viscosity follow their formulas (the latter
//     capped); dP/dphi matches a finite difference of P; OpenFOAM's JohnsonJackson viscosity
//     (v1912 frictionalStressModels/JohnsonJackson: nu = 0.5 s P_f/rho sin(angle) in a stress
//     alpha rho nu) is phi 0.5 s P_f sin(angle) at any shear rate.
// (5) Local-equilibrium theta (the algebraic option) in simple shear at rate G (D':D' = G^2/2,
//     div v = 0) with the Gidaspow book forms of (2): mu = M sqrt(theta), gamma = Q theta^1.5
//     and a drag sink s theta give Q x^2 + s x - M G^2 = 0 for x = sqrt(theta), solved here by
//     the textbook root; without the sink theta = M G^2 / Q (with the collisional viscosity
//     alone this is the classical dense-limit d^2 G^2 / (15 (1 - e))).
//     Under compression and expansion with the Nieuwland set the returned theta balances the
//     Eq. 15 source terms evaluated at that theta (residual 1e-10 of the production), the
//     expansion work counted where div v > 0 only (ktgf.h says why).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "draglab/error.h"
#include "tfm/ktgf.h"

namespace draglab {
namespace consumers {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kD = 2.5e-3, kRho = 2526.0;

TEST(Ktgf, RadialDistributionsMatchThePublishedTable) {
  std::ifstream in(std::string(DRAGLAB_DATA_DIR) + "/ktgf_radial_distribution_reference.csv");
  ASSERT_TRUE(in) << "data/ktgf_radial_distribution_reference.csv";
  std::string line;
  int rows = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("radial,", 0) == 0) continue;
    std::stringstream s(line);
    std::string name, field;
    std::vector<double> v;
    std::getline(s, name, ',');
    while (std::getline(s, field, ',')) v.push_back(std::stod(field));
    ASSERT_EQ(v.size(), 4u) << line;
    KtgfOptions o;
    ASSERT_TRUE(parse_radial_distribution(name, &o.radial)) << name;
    o.packing_limit = v[0];
    o.g0_margin = 1e-3;  // the cap stays above every tabulated phi
    const KtgfClosures k(o, kD, kRho);
    EXPECT_NEAR(k.RadialDistributionAt(v[1]), v[2], v[3]) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 22);
}

TEST(Ktgf, RadialDistributionIsCappedBelowThePackingLimit) {
  KtgfOptions o;
  o.packing_limit = 0.62;
  o.g0_margin = 0.02;
  o.radial = RadialDistribution::kSinclairJackson;
  const KtgfClosures k(o, kD, kRho);
  const double at_cap = k.RadialDistributionAt(0.60);
  EXPECT_TRUE(std::isfinite(k.RadialDistributionAt(0.62)));
  EXPECT_DOUBLE_EQ(k.RadialDistributionAt(0.62), at_cap);
  EXPECT_DOUBLE_EQ(k.RadialDistributionAt(0.70), at_cap);
}

struct State {
  double phi, theta, e;
};

TEST(Ktgf, GidaspowSetMatchesTheBookForms) {
  for (const State st : {State{0.05, 1e-3, 0.9}, State{0.3, 1e-2, 0.97}, State{0.55, 0.2, 0.8}}) {
    KtgfOptions o;
    o.closures = KtgfClosureSet::kGidaspow;
    o.restitution = st.e;
    const KtgfClosures k(o, kD, kRho);
    const double g0 = k.RadialDistributionAt(st.phi), e = st.e, phi = st.phi, th = st.theta;
    const KtgfCoefficients c = k.Evaluate(phi, th, 0.0, 0.0);
    const double p = kRho * phi * th * (1.0 + 2.0 * (1.0 + e) * phi * g0);
    const double mu = 0.8 * phi * phi * kRho * kD * g0 * (1.0 + e) * std::sqrt(th / kPi) +
                      10.0 * kRho * kD * std::sqrt(kPi * th) / (96.0 * (1.0 + e) * g0) *
                          std::pow(1.0 + 0.8 * g0 * phi * (1.0 + e), 2);
    const double kappa = 150.0 * kRho * kD * std::sqrt(kPi * th) / (384.0 * (1.0 + e) * g0) *
                             std::pow(1.0 + 1.2 * phi * g0 * (1.0 + e), 2) +
                         2.0 * phi * phi * kRho * kD * g0 * (1.0 + e) * std::sqrt(th / kPi);
    const double gamma =
        12.0 * (1.0 - e * e) * phi * phi * kRho * g0 * std::pow(th, 1.5) / (kD * std::sqrt(kPi));
    EXPECT_NEAR(c.pressure_pa, p, 1e-12 * p);
    EXPECT_NEAR(c.kinetic_pressure_per_theta * th, p, 1e-12 * p);
    EXPECT_NEAR(c.shear_viscosity_pa_s, mu, 1e-12 * mu);
    EXPECT_NEAR(c.bulk_viscosity_pa_s,
                4.0 / 3.0 * phi * phi * kRho * kD * g0 * (1.0 + e) * std::sqrt(th / kPi),
                1e-12 * mu);
    EXPECT_NEAR(c.conductivity, kappa, 1e-12 * kappa);
    EXPECT_NEAR(c.dissipation_rate_coefficient * th, gamma, 1e-12 * gamma);
  }
}

TEST(Ktgf, NieuwlandDiffersByTheChapmanCowlingFactorsAndTheDivergenceTerm) {
  const double phi = 0.4, th = 5e-3, e = 0.95, div = 3.0;
  KtgfOptions o;
  o.restitution = e;
  const KtgfClosures nieuwland(o, kD, kRho);
  o.closures = KtgfClosureSet::kGidaspow;
  const KtgfClosures gidaspow(o, kD, kRho);
  const KtgfCoefficients n = nieuwland.Evaluate(phi, th, div, 0.0);
  const KtgfCoefficients g = gidaspow.Evaluate(phi, th, div, 0.0);
  const double g0 = nieuwland.RadialDistributionAt(phi), eta = 0.5 * (1.0 + e);
  const double dilute = kRho * kD * std::sqrt(kPi * th) / (eta * g0);
  const double mu_dilute = 5.0 / 96.0 * dilute * std::pow(1.0 + 1.6 * eta * phi * g0, 2);
  const double kappa_dilute = 75.0 / 384.0 * dilute * std::pow(1.0 + 2.4 * eta * phi * g0, 2);
  EXPECT_NEAR(n.shear_viscosity_pa_s - g.shear_viscosity_pa_s, 0.016 * mu_dilute,
              1e-10 * n.shear_viscosity_pa_s);
  EXPECT_NEAR(n.conductivity - g.conductivity, 0.02513 * kappa_dilute, 1e-10 * n.conductivity);
  EXPECT_DOUBLE_EQ(n.pressure_pa, g.pressure_pa);
  EXPECT_DOUBLE_EQ(n.bulk_viscosity_pa_s, g.bulk_viscosity_pa_s);
  // gamma = 3 (1 - e^2) phi^2 rho g0 theta [(4/d) sqrt(theta/pi) - div v]
  const double base = 3.0 * (1.0 - e * e) * phi * phi * kRho * g0;
  EXPECT_NEAR(n.dissipation_rate_coefficient - g.dissipation_rate_coefficient, -base * div,
              1e-10 * base * div);
}

TEST(Ktgf, ElasticParticlesDoNotDissipate) {
  KtgfOptions o;
  o.restitution = 1.0;
  for (auto set : {KtgfClosureSet::kNieuwland, KtgfClosureSet::kGidaspow}) {
    o.closures = set;
    EXPECT_EQ(KtgfClosures(o, kD, kRho).Evaluate(0.4, 1e-2, 2.0, 0.0).dissipation_rate_coefficient,
              0.0);
  }
}

TEST(Ktgf, KnudsenLimiterLeavesDenseStatesAndBoundsTheDiluteViscosity) {
  KtgfOptions plain;
  KtgfOptions limited = plain;
  limited.knudsen_length_m = 5e-3;  // two diameters, the TFM's cells
  const KtgfClosures a(plain, kD, kRho), b(limited, kD, kRho);
  // Dense: the mean free path d / (6 sqrt(2) phi g0) is ~1.2 % of L.
  const double dense = b.Evaluate(0.55, 1e-2, 0, 0).shear_viscosity_pa_s /
                       a.Evaluate(0.55, 1e-2, 0, 0).shear_viscosity_pa_s;
  EXPECT_NEAR(dense, 1.0, 5e-3);
  // Dilute: without the limiter mu does not vanish with phi; with it mu ~ phi.
  const double mu1 = b.Evaluate(1e-4, 1e-2, 0, 0).shear_viscosity_pa_s;
  const double mu2 = b.Evaluate(2e-4, 1e-2, 0, 0).shear_viscosity_pa_s;
  EXPECT_NEAR(mu2 / mu1, 2.0, 0.01);
  EXPECT_GT(a.Evaluate(1e-4, 1e-2, 0, 0).shear_viscosity_pa_s, 100.0 * mu1);
}

TEST(Ktgf, JohnsonJacksonSchaefferFriction) {
  KtgfOptions o;
  o.friction = FrictionModel::kJohnsonJacksonSchaeffer;
  const KtgfClosures k(o, kD, kRho);
  const double phi = 0.6, rate = 200.0;  // mu_f = 5.8 Pa s, below the 10 Pa s cap
  const KtgfCoefficients c = k.Evaluate(phi, 0.0, 0.0, rate);
  const double pf = 0.05 * std::pow(phi - 0.5, 2) / std::pow(0.64 - phi, 5);
  EXPECT_NEAR(c.frictional_pressure_pa, pf, 1e-12 * pf);
  EXPECT_NEAR(c.pressure_pa, pf, 1e-12 * pf) << "theta = 0: no kinetic pressure";
  const double mu_f = pf * std::sin(28.5 * kPi / 180.0) / (2.0 * rate);
  ASSERT_LT(mu_f, 10.0);
  EXPECT_NEAR(c.frictional_viscosity_pa_s, mu_f, 1e-12 * mu_f);
  EXPECT_DOUBLE_EQ(k.Evaluate(phi, 0.0, 0.0, 1e-9).frictional_viscosity_pa_s, 10.0) << "capped";
  EXPECT_EQ(k.Evaluate(0.45, 0.0, 0.0, rate).frictional_pressure_pa, 0.0) << "below phi_min";
  // The delta clip keeps P_f finite at and beyond the packing limit.
  EXPECT_TRUE(std::isfinite(k.Evaluate(0.64, 0.0, 0.0, rate).frictional_pressure_pa));
  // dP/dphi against a central difference of P (with theta).
  const double h = 1e-5, th = 1e-2;
  const double fd = (k.Evaluate(0.58 + h, th, 0, rate).pressure_pa -
                     k.Evaluate(0.58 - h, th, 0, rate).pressure_pa) /
                    (2.0 * h);
  EXPECT_NEAR(k.Evaluate(0.58, th, 0, rate).pressure_derivative_pa, fd, 1e-5 * fd);
}

TEST(Ktgf, JohnsonJacksonOpenFoamFrictionViscosityIgnoresTheShearRate) {
  KtgfOptions o;
  o.friction = FrictionModel::kJohnsonJacksonOpenFoam;
  o.friction_max_viscosity_pa_s = 5000.0;
  const KtgfClosures k(o, kD, kRho);
  const double phi = 0.6;
  const double pf = 0.05 * std::pow(phi - 0.5, 2) / std::pow(0.64 - phi, 5);
  const double mu_f = phi * 0.5 * pf * std::sin(28.5 * kPi / 180.0);
  for (double rate : {1e-9, 1.0, 200.0}) {
    const KtgfCoefficients c = k.Evaluate(phi, 0.0, 0.0, rate);
    EXPECT_NEAR(c.frictional_pressure_pa, pf, 1e-12 * pf);
    EXPECT_NEAR(c.frictional_viscosity_pa_s, mu_f, 1e-12 * mu_f) << rate;
  }
  o.friction_max_viscosity_pa_s = 10.0;
  EXPECT_DOUBLE_EQ(KtgfClosures(o, kD, kRho).Evaluate(phi, 0.0, 0.0, 1.0).frictional_viscosity_pa_s,
                   10.0)
      << "capped";
  FrictionModel parsed = FrictionModel::kNone;
  EXPECT_TRUE(parse_friction_model("johnson_jackson_openfoam", &parsed));
  EXPECT_EQ(parsed, FrictionModel::kJohnsonJacksonOpenFoam);
}

TEST(Ktgf, EquilibriumThetaInSimpleShearMatchesTheClosedForm) {
  const double rate = 10.0;
  for (const State st : {State{0.1, 0.0, 0.9}, State{0.35, 0.0, 0.97}, State{0.55, 0.0, 0.8}}) {
    KtgfOptions o;
    o.closures = KtgfClosureSet::kGidaspow;
    o.restitution = st.e;
    const KtgfClosures k(o, kD, kRho);
    const double g0 = k.RadialDistributionAt(st.phi), e = st.e, phi = st.phi;
    const double m = 0.8 * phi * phi * kRho * kD * g0 * (1.0 + e) / std::sqrt(kPi) +
                     10.0 * kRho * kD * std::sqrt(kPi) / (96.0 * (1.0 + e) * g0) *
                         std::pow(1.0 + 0.8 * g0 * phi * (1.0 + e), 2);
    const double q = 12.0 * (1.0 - e * e) * phi * phi * kRho * g0 / (kD * std::sqrt(kPi));
    const double dev2 = 0.5 * rate * rate;
    const double theta = k.EquilibriumTheta(phi, 0.0, dev2, 0.0);
    EXPECT_NEAR(theta, m * rate * rate / q, 1e-12 * theta) << "phi = " << phi;
    const double sink = 3.0 * 2e4;  // 3 beta of a dense gas-fluidised bed [kg m^-3 s^-1]
    const double x = (-sink + std::sqrt(sink * sink + 4.0 * q * m * rate * rate)) / (2.0 * q);
    EXPECT_NEAR(k.EquilibriumTheta(phi, 0.0, dev2, sink), x * x, 1e-10 * x * x);
  }
}

TEST(Ktgf, EquilibriumThetaBalancesTheSourcesUnderCompressionAndExpansion) {
  KtgfOptions o;  // Nieuwland: the dissipation has its -div v term
  o.restitution = 0.9;
  o.friction = FrictionModel::kJohnsonJacksonSchaeffer;  // friction produces no fluctuations
  const KtgfClosures k(o, kD, kRho);
  for (const double div : {-20.0, -1.0, 0.0, 5.0})
    for (const double phi : {0.05, 0.4, 0.6}) {
      const double dev2 = 50.0, sink = 3.0 * 1e4;
      const double theta = k.EquilibriumTheta(phi, div, dev2, sink);
      ASSERT_GT(theta, 0.0);
      const KtgfCoefficients c = k.Evaluate(phi, theta, div, std::sqrt(0.5 * dev2));
      const double mu_kinetic = c.shear_viscosity_pa_s - c.frictional_viscosity_pa_s;
      const double production = 2.0 * mu_kinetic * dev2 + c.bulk_viscosity_pa_s * div * div;
      const double sinks = c.kinetic_pressure_per_theta * theta * std::max(div, 0.0) +
                           c.dissipation_rate_coefficient * theta + sink * theta;
      EXPECT_NEAR(production, sinks, 1e-10 * production) << "phi " << phi << " div " << div;
    }
  EXPECT_EQ(k.EquilibriumTheta(0.4, 0.0, 0.0, 0.0), 0.0) << "no shear, no compression";
  EXPECT_EQ(k.EquilibriumTheta(0.0, 0.0, 50.0, 0.0), 0.0) << "no solids";
}

TEST(Ktgf, EquilibriumThetaOfElasticParticlesNeedsADragSink) {
  KtgfOptions o;
  o.restitution = 1.0;
  const KtgfClosures k(o, kD, kRho);
  try {
    k.EquilibriumTheta(0.4, 0.0, 50.0, 0.0);
    ADD_FAILURE() << "elastic, sheared, no gas: nothing bounds theta";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("restitution"), std::string::npos) << e.what();
  }
  EXPECT_GT(k.EquilibriumTheta(0.4, 0.0, 50.0, 3e4), 0.0);
  EXPECT_THROW(k.EquilibriumTheta(0.4, 0.0, -1.0, 0.0), Error);
  EXPECT_THROW(k.EquilibriumTheta(0.4, std::nan(""), 1.0, 0.0), Error);
}

TEST(Ktgf, BadOptionsNameTheField) {
  auto bad = [](KtgfOptions o, const char* field) {
    try {
      KtgfClosures k(o, kD, kRho);
      ADD_FAILURE() << "accepted; expected an error naming " << field;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  KtgfOptions o;
  o.restitution = 0.0;
  bad(o, "restitution");
  o = KtgfOptions();
  o.restitution = 1.01;
  bad(o, "restitution");
  o = KtgfOptions();
  o.packing_limit = 0.8;
  bad(o, "packing_limit");
  o = KtgfOptions();
  o.friction = FrictionModel::kJohnsonJacksonSchaeffer;
  o.friction_min_solids = 0.7;
  bad(o, "friction_min_solids");
  o = KtgfOptions();
  o.knudsen_length_m = -1.0;
  bad(o, "knudsen_length_m");
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
