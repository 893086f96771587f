// draglab/consumers/bubble.h: bubble metrics from a gas-fraction (void-fraction) field on a 2-D
// grid of a pseudo-2D bed.
//
// The bubble is the 4-connected region of cells with eps > threshold that contains a seed cell
// (the jet's bubble), or, without a seed, the largest such region that touches the jet column
// (cells whose centre lies in [jet_x_min, jet_x_max]). Metrics: area A (sum of cell areas),
// equivalent diameter D = sqrt(4 A / pi), centroid, extent, and the bed height (top of the highest
// row whose width-averaged eps is <= BubbleOptions::bed_eps) with the expansion. Only cells below
// the bed surface are searched, so the freeboard (eps = 1) is never taken for a bubble; a bubble
// that reaches the surface row is flagged as erupting.
//
// Discretisation error of D: a region traced on cells of size h misplaces its boundary by at
// most ~h/2 along the perimeter, so |A - A_true| <~ P h / 2 and |D - D_true| <~ h (for a disc:
// P = pi D, dD = dA / (pi D / 2) = h). The tests check this bound.
#pragma once

#include <string>
#include <vector>

namespace draglab {
namespace consumers {

/// A cell-centred scalar field on a uniform nx x ny grid over [0, width] x [0, height] [m],
/// stored row by row from the bottom: value(i, j) = values[j * nx + i], i across, j up.
struct GridField2D {
  int nx = 0;
  int ny = 0;
  double width_m = 0.0;
  double height_m = 0.0;
  std::vector<double> values;

  double dx() const { return width_m / nx; }
  double dy() const { return height_m / ny; }
  double at(int i, int j) const { return values[static_cast<std::size_t>(j) * nx + i]; }
  /// Checks sizes and finiteness; *error names the field.
  bool IsValid(std::string* error) const;
};

/// How the bubble is found.
struct BubbleOptions {
  double eps_threshold = 0.8;  ///< A cell is bubble if eps > eps_threshold; in (0, 1).
  /// Seed point [m] (x, y); if seed_y_m < 0 the seed is not used and the largest region that
  /// touches the jet column [jet_x_min_m, jet_x_max_m] is taken.
  double seed_x_m = 0.0;
  double seed_y_m = -1.0;
  double jet_x_min_m = 0.0;
  double jet_x_max_m = 0.0;
  /// Bed surface: the top of the highest row whose width-averaged eps is <= bed_eps, in (0, 1).
  double bed_eps = 0.9;
  double bed_height_initial_m = 0.0;  ///< For the expansion ratio; 0: not reported.
  bool IsValid(std::string* error) const;
};

/// Bubble metrics of one field.
struct BubbleMetrics {
  bool found = false;  ///< False if no cell of the seed/jet column exceeds the threshold.
  int cells = 0;       ///< Cells in the bubble region.
  double area_m2 = 0.0;
  double diameter_m = 0.0;  ///< sqrt(4 A / pi).
  double centroid_x_m = 0.0;
  double centroid_y_m = 0.0;
  double top_m = 0.0;  ///< Highest and lowest cell faces of the region.
  double bottom_m = 0.0;
  bool touches_surface = false;     ///< The region reaches the bed surface (bubble erupting).
  int regions_above_threshold = 0;  ///< All 4-connected regions above the threshold.
  double bed_height_m = 0.0;        ///< See BubbleOptions::bed_eps.
  double bed_expansion = 0.0;       ///< bed_height / bed_height_initial (0 if not given).
  std::string BriefReport() const;
};

/// Measures the bubble in `eps_field`. Throws Error(kInvalidArgument) naming the field for a bad
/// field or options.
BubbleMetrics measure_bubble(const GridField2D& eps_field, const BubbleOptions& options);

/// One sample of the bubble time series.
struct BubbleSample {
  double t_s = 0.0;  ///< Time after jet start.
  BubbleMetrics metrics;
};

/// One sample of a bed model's bubble time series (t after the jet start; negative before it).
struct BedSample {
  double t_s = 0.0;
  double bubble_diameter_m = 0.0;  ///< 0 when no bubble is found.
  double bubble_centroid_m = 0.0;  ///< Height of the bubble centroid [m].
  double bed_height_m = 0.0;       ///< From the width-averaged gas fraction.
  double pressure_drop_pa = 0.0;   ///< Width-averaged p(first cell centre) - p(outlet).
  /// Beds of several sizes (the DPM): (mean height of the smallest size class - that of the
  /// largest) / mean height of all particles, heights of the centres above the floor; 0 mixed,
  /// > 0 the small particles above the large. 0 for a bed of one size.
  double segregation_index = 0.0;
};

/// A bed model's state at one instant, for figures: the gas fraction on the scene's grid, the
/// bubble measured in it and, for a particle model, the particles (empty for a continuum model,
/// whose figure draws the solids fraction instead).
struct BedSnapshot {
  double t_s = 0.0;              ///< After jet start [s].
  std::vector<double> x, y, z;   ///< Particle centres [m] (x width, y height, z depth).
  std::vector<double> diameter;  ///< [m].
  std::vector<int> layer;        ///< Initial layer, 0 (bottom) .. layers - 1.
  int layers = 0;                ///< Initial layers the particles are coloured by (0: none).
  GridField2D void_fraction;     ///< Gas fraction (x, height).
  BubbleMetrics bubble;          ///< measure_bubble on void_fraction.
};

}  // namespace consumers
}  // namespace draglab
