// Shared sampling of the bed models (bed/bed_sampling.h).
#include "bed/bed_sampling.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace draglab {
namespace consumers {
namespace internal {

GasOptions scene_gas_options(const Scene& s, double background_m_s, bool with_jet) {
  GasOptions g;
  g.nx = s.grid.cells_x;
  g.nz = s.grid.cells_y;
  g.width_m = s.geometry.width_m;
  g.height_m = s.geometry.height_m;
  g.depth_m = s.geometry.depth_m;
  g.rho_g = s.gas.density_kg_m3;
  g.mu_g = s.gas.viscosity_pa_s;
  g.gravity_z = -s.gas.gravity_m_s2;
  g.side_walls = WallSlip::kNoSlip;
  g.background_velocity_m_s = background_m_s;
  if (with_jet) {
    g.jet_width_m = s.jet.slot_width_m;
    g.jet_velocity_m_s = s.jet.velocity_m_s;
    g.jet_start_s = s.jet.start_s;
    g.jet_duration_s = s.jet.duration_s;
  }
  g.inflow_ramp_s = s.jet.ramp_s;
  return g;
}

BubbleOptions scene_bubble_options(const Scene& s, double initial_bed_height_m) {
  BubbleOptions bo;
  bo.eps_threshold = s.bubble.eps_threshold;
  const double dx = s.geometry.width_m / s.grid.cells_x;
  const double half = std::max(0.5 * s.jet.slot_width_m, 0.5 * dx);
  bo.jet_x_min_m = s.jet_center_m() - half;
  bo.jet_x_max_m = s.jet_center_m() + half;
  bo.bed_height_initial_m = initial_bed_height_m;
  return bo;
}

GridField2D scene_grid_field(const Scene& scene, const Eigen::ArrayXXd& values) {
  GridField2D f;
  f.nx = scene.grid.cells_x;
  f.ny = scene.grid.cells_y;
  f.width_m = scene.geometry.width_m;
  f.height_m = scene.geometry.height_m;
  f.values.resize(static_cast<std::size_t>(f.nx) * f.ny);
  for (int j = 0; j < f.ny; ++j)
    for (int i = 0; i < f.nx; ++i) f.values[static_cast<std::size_t>(j) * f.nx + i] = values(i, j);
  return f;
}

BedSampler::BedSampler(const Scene& scene, double initial_bed_height_m)
    : scene_(scene),
      bubble_(scene_bubble_options(scene, initial_bed_height_m)),
      t_ref_abs_(scene.jet.start_s + scene.time.t_ref_s),
      best_gap_(0.5 * scene.bubble.sample_interval_s + 1e-12) {}

BedSampler::Taken BedSampler::Take(double t_abs, const Eigen::ArrayXXd& gas_fraction,
                                   double pressure_drop_pa) {
  Taken t;
  t.bubble = measure_bubble(scene_grid_field(scene_, gas_fraction), bubble_);
  t.sample.t_s = t_abs - scene_.jet.start_s;
  t.sample.bubble_diameter_m = t.bubble.found ? t.bubble.diameter_m : 0.0;
  t.sample.bubble_centroid_m = t.bubble.found ? t.bubble.centroid_y_m : 0.0;
  t.sample.bed_height_m = t.bubble.bed_height_m;
  t.sample.pressure_drop_pa = pressure_drop_pa;
  const double gap = std::abs(t_abs - t_ref_abs_);
  if (gap < best_gap_) {
    best_gap_ = gap;
    t.nearest_to_ref = true;
  }
  return t;
}

std::string scene_output_directory(const Scene& scene, const std::string& override_directory) {
  if (!override_directory.empty()) return override_directory;
  if (!scene.outputs.directory.empty()) return scene.outputs.directory;
  return "out/" + scene.name;
}

BedResult result_header(const std::string& model, const Scene& scene,
                        const std::string& law_reference, const std::string& background_mode) {
  BedResult out;
  out.model = model;
  out.law = law_reference;
  out.scene = scene.name;
  out.scene_hash = scene.hash();
  out.eps_mf = scene.eps_mf;
  out.background_mode = background_mode;
  return out;
}

std::vector<double> sample_times(double duration_s, double interval_s) {
  const int samples = static_cast<int>(std::floor(duration_s / interval_s + 1e-9));
  std::vector<double> times;
  times.reserve(static_cast<std::size_t>(std::max(samples, 0)));
  for (int n = 1; n <= samples; ++n) times.push_back(std::min(n * interval_s, duration_s));
  return times;
}

nlohmann::json snapshot_json(double t_s, const BubbleMetrics& b) {
  return {{"t_s", t_s},
          {"bubble_found", b.found},
          {"bubble_diameter_m", b.diameter_m},
          {"bubble_centroid_x_m", b.centroid_x_m},
          {"bubble_centroid_y_m", b.centroid_y_m},
          {"bubble_top_m", b.top_m},
          {"bubble_bottom_m", b.bottom_m},
          {"bubble_erupting", b.touches_surface},
          {"bed_height_m", b.bed_height_m}};
}

}  // namespace internal
}  // namespace consumers
}  // namespace draglab
