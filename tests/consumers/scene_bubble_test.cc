// Bubble metrics (consumers/bubble.h) on synthetic void-fraction fields.
// References (analytical): a disc of radius R in a bed at eps 0.42 -> D = 2R within the
// discretisation bound |D - 2R| <= h (cells of size h; derivation in bubble.h: the traced
// boundary is off by <= h/2 along the perimeter, dA <= pi D h / 2, dD = dA/(pi D/2) <= h);
// centroid at the disc centre within h/2; a rectangle of cells gives its exact area; two
// separated blobs are told apart; the threshold is strict (eps > threshold).
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "draglab/consumers/bubble.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// A bed 0.15 x 0.45 m, eps 0.42 below `bed_m`, 1 above; discs (x, y, R) with eps 1 inside.
GridField2D bed(int nx, int ny, double bed_m, std::initializer_list<std::array<double, 3>> discs) {
  GridField2D f;
  f.nx = nx;
  f.ny = ny;
  f.width_m = 0.15;
  f.height_m = 0.45;
  f.values.assign(static_cast<std::size_t>(nx) * ny, 0.42);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double x = (i + 0.5) * f.dx(), y = (j + 0.5) * f.dy();
      double& v = f.values[static_cast<std::size_t>(j) * nx + i];
      if (y > bed_m) v = 1.0;
      for (const auto& d : discs) {
        if (std::hypot(x - d[0], y - d[1]) < d[2]) v = 0.99;
      }
    }
  }
  return f;
}

TEST(SceneBubble, DiscDiameterWithinTheDiscretisationBound) {
  for (int n : {1, 2, 4}) {  // 5 mm, 2.5 mm, 1.25 mm cells
    const int nx = 30 * n, ny = 90 * n;
    const double h = 0.15 / nx;
    for (double r : {0.02, 0.03, 0.0317}) {
      const GridField2D f = bed(nx, ny, 0.22, {{0.075, 0.1, r}});
      BubbleOptions o;
      o.seed_x_m = 0.075;
      o.seed_y_m = 0.1;
      o.bed_height_initial_m = 0.22;
      const BubbleMetrics m = measure_bubble(f, o);
      ASSERT_TRUE(m.found);
      EXPECT_NEAR(m.diameter_m, 2 * r, h) << "h " << h << " R " << r;
      EXPECT_NEAR(m.centroid_x_m, 0.075, 0.5 * h);
      EXPECT_NEAR(m.centroid_y_m, 0.1, 0.5 * h);
      EXPECT_NEAR(m.bed_height_m, 0.22, h);  // bed top within one cell
      EXPECT_NEAR(m.bed_expansion, 1.0, h / 0.22);
      EXPECT_FALSE(m.touches_surface);
      EXPECT_EQ(m.regions_above_threshold, 1);
    }
  }
}

TEST(SceneBubble, ErrorShrinksWithTheGrid) {
  // The error bound is O(h): the error on a 4x finer grid must be at most the coarse bound / 2.
  const double r = 0.0317;
  BubbleOptions o;
  o.seed_x_m = 0.075;
  o.seed_y_m = 0.1;
  const double coarse =
      std::fabs(measure_bubble(bed(30, 90, 0.22, {{0.075, 0.1, r}}), o).diameter_m - 2 * r);
  const double fine =
      std::fabs(measure_bubble(bed(120, 360, 0.22, {{0.075, 0.1, r}}), o).diameter_m - 2 * r);
  EXPECT_LT(fine, 0.5 * 0.15 / 30);
  EXPECT_LE(fine, coarse + 1e-12);
}

TEST(SceneBubble, RectangleOfCellsHasItsExactArea) {
  GridField2D f = bed(30, 90, 0.22, {});
  for (int j = 10; j < 16; ++j) {
    for (int i = 12; i < 20; ++i) f.values[static_cast<std::size_t>(j) * 30 + i] = 0.9;
  }
  BubbleOptions o;
  o.jet_x_min_m = 0.07;
  o.jet_x_max_m = 0.08;
  const BubbleMetrics m = measure_bubble(f, o);
  ASSERT_TRUE(m.found);
  EXPECT_EQ(m.cells, 48);
  EXPECT_NEAR(m.area_m2, 48 * 0.005 * 0.005, 1e-15);
  EXPECT_NEAR(m.diameter_m, std::sqrt(4 * 48 * 25e-6 / kPi), 1e-12);
  EXPECT_NEAR(m.bottom_m, 0.05, 1e-12);
  EXPECT_NEAR(m.top_m, 0.08, 1e-12);
  EXPECT_NEAR(m.centroid_x_m, 0.08, 1e-12);
}

TEST(SceneBubble, TwoSeparatedBlobs) {
  // Jet bubble (R 3 cm, centre) and a smaller one off the jet column (R 1 cm, x = 0.02).
  const GridField2D f = bed(60, 180, 0.22, {{0.075, 0.08, 0.03}, {0.02, 0.17, 0.01}});
  BubbleOptions o;
  o.jet_x_min_m = 0.07;
  o.jet_x_max_m = 0.08;
  const BubbleMetrics m = measure_bubble(f, o);
  EXPECT_EQ(m.regions_above_threshold, 2);
  EXPECT_NEAR(m.diameter_m, 0.06, 0.0025);
  EXPECT_NEAR(m.centroid_x_m, 0.075, 0.00125);
  // Seeded on the small one: that one is measured.
  o.seed_x_m = 0.02;
  o.seed_y_m = 0.17;
  const BubbleMetrics s = measure_bubble(f, o);
  EXPECT_NEAR(s.diameter_m, 0.02, 0.0025);
  // Off the jet column with no seed: the largest region touching the column is the jet bubble
  // even when the other one is larger.
  const GridField2D g = bed(60, 180, 0.22, {{0.075, 0.05, 0.015}, {0.03, 0.15, 0.02}});
  o.seed_y_m = -1.0;
  EXPECT_NEAR(measure_bubble(g, o).diameter_m, 0.03, 0.0025);
}

TEST(SceneBubble, ThresholdIsStrictAndFreeboardIsNotABubble) {
  GridField2D f = bed(30, 90, 0.22, {});
  f.values[static_cast<std::size_t>(20) * 30 + 15] = 0.8;  // exactly at the threshold
  BubbleOptions o;
  o.seed_x_m = 0.0775;
  o.seed_y_m = 0.1025;
  EXPECT_FALSE(measure_bubble(f, o).found);
  f.values[static_cast<std::size_t>(20) * 30 + 15] = 0.8000001;
  const BubbleMetrics m = measure_bubble(f, o);
  ASSERT_TRUE(m.found);
  EXPECT_EQ(m.cells, 1);
  o.eps_threshold = 0.85;
  EXPECT_FALSE(measure_bubble(f, o).found);
  // No bubble in the bed: the freeboard above it (eps = 1) is not taken for one.
  BubbleOptions jet;
  jet.jet_x_min_m = 0.0;
  jet.jet_x_max_m = 0.15;
  const BubbleMetrics none = measure_bubble(bed(30, 90, 0.22, {}), jet);
  EXPECT_FALSE(none.found);
  EXPECT_NEAR(none.bed_height_m, 0.22, 0.005);
  // An erupting bubble reaching the bed surface is flagged.
  const BubbleMetrics erupt = measure_bubble(bed(30, 90, 0.22, {{0.075, 0.21, 0.03}}), jet);
  ASSERT_TRUE(erupt.found);
  EXPECT_TRUE(erupt.touches_surface);
}

TEST(SceneBubble, BadInput) {
  GridField2D f = bed(30, 90, 0.22, {});
  BubbleOptions o;
  o.eps_threshold = 1.0;
  EXPECT_THROW(measure_bubble(f, o), Error);
  o = BubbleOptions();
  f.values[3] = std::nan("");
  try {
    measure_bubble(f, o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("values[3]"), std::string::npos);
  }
  f = bed(30, 90, 0.22, {});
  f.values.pop_back();
  EXPECT_THROW(measure_bubble(f, o), Error);
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
