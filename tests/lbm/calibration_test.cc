// Sangani-Acrivos series and hydrodynamic-diameter calibration (lbm/calibration.h).
//
// References:
//  - data/sangani_acrivos_sc_series.csv: the 31 coefficients of Sangani & Acrivos (1982) Eq. 60
//    (the library embeds its own copy; they must be the same numbers);
//  - data/zick_homsy_sc_dilute.csv: Zick & Homsy (1982) Table 2, K of SC arrays in Stokes flow,
//    an independent solution of the same problem (boundary-integral, not a series);
//  - Hasimoto (1959): K^-1 = 1 - 1.7601 phi^(1/3) + phi - 1.5593 phi^2 + O(phi^(8/3)), the dilute
//    limit the series must approach.
// Physical check (fast, small lattice): TRT with halfway bounce-back at d = 6 lattice units,
// calibrated on a dilute SC array (phi ~ 0.01), then an SC array at phi ~ 0.11: normalising with
// the calibrated d_h must bring F closer to the series than the input d does (the purpose of the
// seed's calibration: staircase spheres act like spheres of a shifted diameter).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "draglab/error.h"
#include "draglab/lbm/calibration.h"

#ifndef DRAGLAB_DATA_DIR
#error "DRAGLAB_DATA_DIR must name the repository's data/ folder"
#endif

namespace draglab {
namespace lbm {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Numeric rows of a data/ CSV ('#' header lines and the column-name line skipped).
std::vector<std::vector<double>> read_csv(const std::string& name) {
  std::ifstream in(std::string(DRAGLAB_DATA_DIR) + "/" + name);
  EXPECT_TRUE(in.good()) << name;
  std::vector<std::vector<double>> rows;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::vector<double> row;
    std::stringstream s(line);
    std::string field;
    while (std::getline(s, field, ',')) row.push_back(std::stod(field));
    rows.push_back(row);
  }
  return rows;
}

TEST(SanganiAcrivos, EmbeddedCoefficientsAreTheDataFile) {
  const auto rows = read_csv("sangani_acrivos_sc_series.csv");
  ASSERT_EQ(rows.size(), static_cast<std::size_t>(kSanganiAcrivosTerms));
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 2u);
    const int s = static_cast<int>(row[0]);
    // Same decimal transcription on both sides: equal to the last bit after parsing.
    EXPECT_EQ(sangani_acrivos_coefficients()[static_cast<std::size_t>(s)], row[1]) << "q_" << s;
  }
}

TEST(SanganiAcrivos, AgreesWithZickHomsy) {
  const auto rows = read_csv("zick_homsy_sc_dilute.csv");
  ASSERT_EQ(rows.size(), 4u);
  for (const auto& row : rows) {
    const double phi = row[0], K = row[1];
    // Documented agreement of the 31-term series with Z&H: <= 0.1 % for phi <= 0.216; Z&H print
    // 4 digits (rounding <= 0.025 %).
    EXPECT_NEAR(sangani_acrivos_sc_K(phi) / K, 1.0, 1e-3) << "phi = " << phi;
    EXPECT_DOUBLE_EQ(sangani_acrivos_sc_F(phi), (1.0 - phi) * sangani_acrivos_sc_K(phi));
  }
}

TEST(SanganiAcrivos, ApproachesHasimotoWhenDilute) {
  for (double phi : {1e-6, 1e-5, 1e-4}) {
    const double c = std::cbrt(phi);
    const double hasimoto = 1.0 / (1.0 - 1.7601 * c + phi - 1.5593 * phi * phi);
    // Hasimoto's coefficient 1.7601 is given to 5 digits: 5e-5 * phi^(1/3) <= 2.5e-6 relative
    // here; the omitted O(phi^(8/3)) terms are far smaller.
    EXPECT_NEAR(sangani_acrivos_sc_K(phi) / hasimoto, 1.0, 5e-5 * c + 1e-9) << "phi = " << phi;
  }
}

TEST(SanganiAcrivos, RefusesPhiOutsideTheSeriesRange) {
  EXPECT_THROW(sangani_acrivos_sc_K(0.0), Error);
  EXPECT_THROW(sangani_acrivos_sc_K(0.3), Error);  // the series drifts above 0.22
  EXPECT_THROW(sangani_acrivos_sc_K(std::nan("")), Error);
  EXPECT_NO_THROW(sangani_acrivos_sc_K(kSanganiAcrivosMaxPhi));
}

TEST(HydrodynamicDiameter, InvertsTheSeries) {
  // A drag that is exactly the series for a sphere of diameter d_true, measured (normalised)
  // with d, must give back d_true; Newton converges to 1e-13, so 1e-11 relative is safe.
  const double L = 40.0, d = 10.0;
  for (double d_true : {9.3, 10.0, 10.6, 14.0}) {
    const double phi_true = kPi / 6.0 * std::pow(d_true / L, 3);
    const double F_measured = sangani_acrivos_sc_F(phi_true) * d_true / d;
    int iterations = 0;
    const double d_h = solve_hydrodynamic_diameter(L, d, F_measured, &iterations);
    EXPECT_NEAR(d_h / d_true, 1.0, 1e-11) << d_true;
    EXPECT_LE(iterations, 20);
  }
}

TEST(HydrodynamicDiameter, RefusesImpossibleDrag) {
  EXPECT_THROW(solve_hydrodynamic_diameter(40.0, 10.0, -1.0), Error);
  EXPECT_THROW(solve_hydrodynamic_diameter(0.0, 10.0, 1.5), Error);
  // A drag larger than the series allows for any diameter up to phi = 0.22.
  EXPECT_THROW(solve_hydrodynamic_diameter(40.0, 10.0, 1e3), Error);
}

TEST(Calibration, OptionsAreChecked) {
  CalibrationOptions o;
  std::string error;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  o.diameter = 2.0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("diameter"), std::string::npos) << error;
  o = CalibrationOptions();
  o.phi = 0.2;  // not dilute
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("phi"), std::string::npos) << error;
  o = CalibrationOptions();
  o.check_phi = 0.3;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THROW(calibrate_hydrodynamic_diameter(o), Error);
}

TEST(Calibration, BounceBackHydrodynamicDiameterMovesFTowardTheSeries) {
  CalibrationOptions o;
  o.diameter = 6.0;  // coarse on purpose: the staircase error is large (several per cent)
  o.phi = 0.01;      // box of 22 nodes
  o.check_phi = 0.1;
  o.run.collision = Collision::kTrt;
  o.run.boundary = Boundary::kHalfwayBounceBack;
  o.run.tolerance = 1e-7;
  o.run.threads =
      1;  // 22^3 nodes: threads add only barrier cost (and ctest runs tests in parallel)
  const CalibrationResult r = calibrate_hydrodynamic_diameter(o);
  ASSERT_TRUE(r.has_check);
  EXPECT_TRUE(r.calibration.run.converged);
  EXPECT_TRUE(r.check.run.converged);
  // The defining equation holds at the calibration point (up to the Newton tolerance).
  EXPECT_NEAR(r.calibration.F_hydrodynamic / r.calibration.F_reference_hydrodynamic, 1.0, 1e-9);
  // Bounce-back shifts the effective wall by a fraction of a link, not more.
  EXPECT_LT(std::fabs(r.hydrodynamic_diameter - r.diameter), 1.0) << r.Report();
  // The point of the calibration: at a denser array the d_h normalisation is closer to the
  // series than the input-d one. Strictly closer, and by a real margin (factor 1.5), so that
  // round-off cannot pass the test.
  EXPECT_LT(1.5 * std::fabs(r.check.error_hydrodynamic), std::fabs(r.check.error_input))
      << r.Report();
}

}  // namespace
}  // namespace lbm
}  // namespace draglab
