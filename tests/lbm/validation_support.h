// Shared helpers of the LBM validation tests (validation_short_test.cc, *_validation.cc):
// reference values (Sangani-Acrivos series, Zick & Homsy table, van der Hoef 2005 fit), the
// geometries of the validation cases, and the small statistics the tests need (Richardson
// extrapolation, log-log slopes, realization error bars).
//
// Conventions (those of lbm.h): lattice units dx = dt = 1; node (i, j, k) at (i + 1/2, j + 1/2,
// k + 1/2); flow along +x; F is the drag-only canonical force <F_d>/(3 pi mu d U) with U the
// superficial velocity. Reference values in the total-force convention K = F_tot/(6 pi mu a U)
// (Zick & Homsy, Sangani & Acrivos) convert as F = (1 - phi) K.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "draglab/arrays/packing.h"
#include "draglab/arrays/voxelization.h"
#include "draglab/lbm/lbm.h"

#ifndef DRAGLAB_DATA_DIR
#error "DRAGLAB_DATA_DIR must name the repository's data/ folder"
#endif

namespace draglab {
namespace lbm {
namespace validation {

constexpr double kPi = 3.14159265358979323846;

// ------------------------------------------------------------------------------------------------
// Reference data.

/// Rows of a data/ CSV file: '#' lines are the citation header, the first other line names the
/// columns and is skipped. Throws std::runtime_error if the file cannot be read.
inline std::vector<std::vector<double>> read_data_csv(const std::string& file_name) {
  const std::string path = std::string(DRAGLAB_DATA_DIR) + "/" + file_name;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read reference data file " + path);
  std::vector<std::vector<double>> rows;
  std::string line;
  bool column_names_seen = false;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (!column_names_seen) {
      column_names_seen = true;
      continue;
    }
    std::vector<double> row;
    std::stringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) row.push_back(field.empty() ? NAN : std::stod(field));
    rows.push_back(row);
  }
  return rows;
}

/// The 31 coefficients q_0..q_30 of the Sangani & Acrivos (1982) simple-cubic series.
inline const std::vector<double>& sangani_acrivos_coefficients() {
  static const std::vector<double> coefficients = [] {
    std::vector<double> q;
    for (const auto& row : read_data_csv("sangani_acrivos_sc_series.csv")) {
      if (row.size() != 2 || static_cast<std::size_t>(row[0]) != q.size()) {
        throw std::runtime_error("sangani_acrivos_sc_series.csv: rows must be s = 0, 1, ...");
      }
      q.push_back(row[1]);
    }
    if (q.size() != 31) throw std::runtime_error("sangani_acrivos_sc_series.csv: need 31 terms");
    return q;
  }();
  return coefficients;
}

/// Stokes drag on a simple-cubic array, total-force convention: K = F_tot/(6 pi mu a U), U
/// superficial, K = sum_s q_s chi^s with chi = d/L = (6 phi/pi)^(1/3). Sangani & Acrivos 1982,
/// Eq. 60. Valid (within 0.1 % of Zick & Homsy) for phi in (0, 0.22]; throws outside.
inline double sangani_acrivos_K(double phi) {
  if (!(phi > 0.0 && phi <= 0.22)) {
    throw std::invalid_argument("Sangani-Acrivos series used outside phi in (0, 0.22]");
  }
  const double chi = std::cbrt(6.0 * phi / kPi);
  double sum = 0.0;
  double power = 1.0;
  for (double q : sangani_acrivos_coefficients()) {
    sum += q * power;
    power *= chi;
  }
  return sum;
}

/// The same in the canonical drag-only convention of the engine: F = (1 - phi) K.
inline double sangani_acrivos_F(double phi) { return (1.0 - phi) * sangani_acrivos_K(phi); }

/// d ln F / d ln a of the series at fixed cell size (phi ~ a^3): 3 phi d ln F/d phi, by a central
/// difference (step 1e-5, truncation error ~1e-10). A relative drag error e then corresponds to a
/// wall displaced by e a / (d ln F/d ln a): the hydrodynamic-radius offset.
inline double sangani_acrivos_radius_sensitivity(double phi) {
  const double h = 1e-5;
  return 3.0 * phi * (std::log(sangani_acrivos_F(phi + h)) - std::log(sangani_acrivos_F(phi - h))) /
         (2.0 * h);
}

/// van der Hoef, Beetstra & Kuipers 2005 (JFM 528:233) Stokes fit for random monodisperse arrays,
/// drag-only superficial F = 10 phi/(1-phi)^2 + (1-phi)^2 (1 + 1.5 sqrt(phi)). The fit represents
/// their (resolution-extrapolated) LB data to a few per cent for phi in [0.1, 0.6].
inline double van_der_hoef_2005_F(double phi) {
  const double eps = 1.0 - phi;
  return 10.0 * phi / (eps * eps) + eps * eps * (1.0 + 1.5 * std::sqrt(phi));
}

// ------------------------------------------------------------------------------------------------
// Geometries.

/// Two plane walls normal to y, flow along x: solid node rows j = 0 and j = ny - 1, fluid rows
/// j = 1 .. ny - 2 (channel_nodes of them), periodic in x and z (width_nodes each). Body 0 is the
/// bottom wall (links from row 1 with c_y = -1), body 1 the top wall (links from row ny - 2 with
/// c_y = +1), every link with q = 1/2: the walls lie exactly halfway between the last fluid and
/// the first solid node, at y = 1 and y = ny - 1 (node j sits at y = j + 1/2). The reference
/// length d_ref is the channel width H = channel_nodes, i.e. dx = 1/H.
inline arrays::VoxelGrid make_plates(int channel_nodes, int width_nodes) {
  arrays::VoxelGrid grid;
  const std::int64_t ny = channel_nodes + 2;
  grid.dims = {width_nodes, ny, width_nodes};
  grid.dx = 1.0 / channel_nodes;
  grid.solid.assign(static_cast<std::size_t>(grid.num_nodes()), 0);
  for (std::int64_t k = 0; k < width_nodes; ++k) {
    for (std::int64_t i = 0; i < width_nodes; ++i) {
      grid.solid[grid.index(i, 0, k)] = 1;
      grid.solid[grid.index(i, ny - 1, k)] = 1;
    }
  }
  grid.links.assign(2, {});
  // Sorted by fluid node, then direction, as arrays::voxelize() lists them.
  for (int body = 0; body < 2; ++body) {
    const std::int64_t row = body == 0 ? 1 : ny - 2;
    const int towards_wall = body == 0 ? -1 : +1;
    for (std::int64_t k = 0; k < width_nodes; ++k) {
      for (std::int64_t i = 0; i < width_nodes; ++i) {
        for (int q = 0; q < arrays::kD3Q19; ++q) {
          if (arrays::kD3Q19Velocities[q][1] != towards_wall) continue;
          arrays::BoundaryLink link;
          link.fluid_node = static_cast<std::uint64_t>(grid.index(i, row, k));
          link.q = 0.5;
          link.direction = static_cast<std::uint8_t>(q);
          grid.links[body].push_back(link);
        }
      }
    }
  }
  return grid;
}

/// One sphere in a periodic cube: a simple-cubic array.
struct ScArray {
  arrays::Packing packing;
  arrays::VoxelGrid grid;
  double d = 0.0;  ///< Lattice units per diameter actually used (the box is a whole number of
                   ///< nodes, so this is the requested diameter rounded to an even node count).
};

/// Simple-cubic array of solids fraction phi at about `requested_d` nodes per diameter, built by
/// arrays::generate_ordered_packing (one unit cell). The node count per edge is rounded to an even
/// number and the sphere centred in the box, i.e. on a lattice cell corner, then moved by
/// `offset_nodes` (lattice units). With no offset the sphere has the full cubic symmetry of the
/// lattice at every resolution; offsets sample other placements of the staircase (see
/// placement_offset).
inline ScArray make_sc_array(double phi, double requested_d,
                             const arrays::Vec3& offset_nodes = {0.0, 0.0, 0.0}) {
  ScArray sc;
  arrays::OrderedPackingOptions options;
  options.lattice = arrays::Lattice::kSimpleCubic;
  options.phi = phi;
  options.cells = 1;
  sc.packing = arrays::generate_ordered_packing(options);
  const double edge = sc.packing.box_length[0];
  const long nodes = std::max(2L, 2 * std::lround(edge * requested_d / 2.0));
  const double dx = edge / static_cast<double>(nodes);
  for (int axis = 0; axis < 3; ++axis) {
    sc.packing.centers[0][axis] = edge / 2.0 + offset_nodes[axis] * dx;
  }
  arrays::VoxelizationOptions voxelization;
  voxelization.resolution = static_cast<double>(nodes) / edge;
  sc.grid = arrays::voxelize(sc.packing, voxelization);
  sc.d = sc.grid.resolution();
  return sc;
}

/// The k-th sub-node placement offset (lattice units, each component in [-1/2, 1/2)): the R3
/// low-discrepancy sequence (Roberts 2018: additive recurrence with the inverse powers of the
/// plastic number 1.32471795724...), deterministic and evenly spread over the unit cell, k = 0
/// giving the symmetric placement.
inline arrays::Vec3 placement_offset(int k) {
  const double g = 1.32471795724474602596;
  const double alpha[3] = {1.0 / g, 1.0 / (g * g), 1.0 / (g * g * g)};
  arrays::Vec3 offset;
  for (int axis = 0; axis < 3; ++axis) {
    const double u = std::fmod(0.5 + k * alpha[axis], 1.0);
    offset[axis] = u - 0.5;
  }
  return offset;
}

/// Random monodisperse hard-sphere packing (arrays::generate_random_packing, default
/// equilibration), n spheres at solids fraction phi.
inline arrays::Packing make_random_packing(double phi, int n, std::uint64_t seed,
                                           double min_gap = 0.0) {
  arrays::RandomPackingOptions options;
  options.phi = phi;
  options.n = n;
  options.seed = seed;
  options.min_gap = min_gap;
  return arrays::generate_random_packing(options);
}

// ------------------------------------------------------------------------------------------------
// Body-force Poiseuille flow between the plates of make_plates().
//
// The steady lattice solution with halfway bounce-back is, node by node and exactly (up to
// round-off), the parabola with a uniform slip s:
//   u(y) = g/(2 nu) (y - y0)(y1 - y) + s,   s = g (16 Lambda - 3)/(24 nu),
// with walls y0 = 1, y1 = H + 1, Lambda = (tau+ - 1/2)(tau- - 1/2) the TRT magic parameter and
// Lambda = (tau - 1/2)^2 for BGK (tau+ = tau- = tau) and Lambda = (tau - 1/2)/2 for the
// regularized collision (it keeps no odd non-equilibrium moment beyond the first, i.e. its odd
// part relaxes with tau- = 1). In the bulk the TRT recurrence is solved
// exactly by any parabola (its discrete Laplacian has no truncation error); the bounce-back
// closure fixes the slip, which vanishes for Lambda = 3/16 (Ginzburg & d'Humieres 2003, PRE
// 68:066614; for BGK, He, Zou, Luo & Dembo 1997, J. Stat. Phys. 87:115). The slip formula was
// checked independently of the engine with a separate few-line D3Q19 TRT program (linear and
// quadratic equilibrium, Guo forcing, u = sum f c + g/2): slip * nu/g = (16 Lambda - 3)/24 to
// 1e-11 for Lambda = 0.01 ... 1, and the regularized collision's slip to (8 (tau - 1/2) - 3)/24
// at tau = 0.6, 1, 1.5. Consequences used by the tests:
//   sum over the H fluid nodes of a column = g H (2 H^2 + 1)/(24 nu) + H s   (sum of the parabola
//   at y - y0 = m + 1/2, m = 0 .. H - 1), so the superficial velocity is that sum / (H + 2);
//   relative deviation of U from the no-slip parabola: (16 Lambda - 3)/(2 H^2 + 1).

struct PlatesOutcome {
  RunResult result;
  double lambda = NAN;  ///< (Effective) magic parameter of the run.
  /// (U - U_parabola)/U_parabola, U_parabola the superficial velocity of the no-slip parabola.
  double mean_error_vs_parabola = NAN;
  /// (U - U_lattice)/U_lattice, U_lattice that of the parabola plus the predicted slip s.
  double mean_error_vs_lattice_solution = NAN;
  /// max over nodes |u_x - (parabola + s)| / u_centre, from the (single precision) fields.
  double profile_error_vs_lattice_solution = NAN;
  /// max over nodes |u_x - parabola| / u_centre.
  double profile_error_vs_parabola = NAN;
  /// max over nodes of |u_y|, |u_z| / u_centre (the flow must stay parallel to the walls).
  double cross_flow = NAN;
};

inline PlatesOutcome run_plates(int channel_nodes, const RunOptions& options) {
  const int width = 4;
  const arrays::VoxelGrid grid = make_plates(channel_nodes, width);
  PlatesOutcome out;
  Fields fields;
  out.result = run_with_fields(grid, -1.0, options, &fields);
  const RunResult& r = out.result;
  if (!r.converged) return out;
  const double H = channel_nodes;
  const double g = r.body_force;
  const double nu = r.nu;
  if (options.collision == Collision::kTrt) out.lambda = options.magic;
  if (options.collision == Collision::kBgk) out.lambda = (r.tau - 0.5) * (r.tau - 0.5);
  if (options.collision == Collision::kRegularized) out.lambda = 0.5 * (r.tau - 0.5);
  const double slip = std::isnan(out.lambda) ? 0.0 : g * (16.0 * out.lambda - 3.0) / (24.0 * nu);
  const double column_sum_parabola = g * H * (2.0 * H * H + 1.0) / (24.0 * nu);
  const double u_parabola = column_sum_parabola / (H + 2.0);
  const double u_lattice = (column_sum_parabola + H * slip) / (H + 2.0);
  out.mean_error_vs_parabola = (r.superficial_velocity - u_parabola) / u_parabola;
  out.mean_error_vs_lattice_solution = (r.superficial_velocity - u_lattice) / u_lattice;
  const double u_centre = g * H * H / (8.0 * nu);
  double worst_lattice = 0.0, worst_parabola = 0.0, worst_cross = 0.0;
  const std::int64_t ny = grid.dims[1];
  for (std::int64_t k = 0; k < grid.dims[2]; ++k) {
    for (std::int64_t j = 1; j < ny - 1; ++j) {
      for (std::int64_t i = 0; i < grid.dims[0]; ++i) {
        const std::size_t n = static_cast<std::size_t>(grid.index(i, j, k));
        const double y = j + 0.5;
        const double parabola = g / (2.0 * nu) * (y - 1.0) * (H + 1.0 - y);
        const double ux = fields.velocity.at(3 * n);
        worst_parabola = std::max(worst_parabola, std::fabs(ux - parabola) / u_centre);
        worst_lattice = std::max(worst_lattice, std::fabs(ux - parabola - slip) / u_centre);
        worst_cross = std::max({worst_cross, std::fabs(fields.velocity.at(3 * n + 1)) / u_centre,
                                std::fabs(fields.velocity.at(3 * n + 2)) / u_centre});
      }
    }
  }
  out.profile_error_vs_parabola = worst_parabola;
  out.profile_error_vs_lattice_solution = std::isnan(out.lambda) ? NAN : worst_lattice;
  out.cross_flow = worst_cross;
  return out;
}

// ------------------------------------------------------------------------------------------------
// Run options.

/// Relaxation time of the TRT Stokes runs. At fixed Lambda the steady TRT solution does not
/// depend on tau (checked by sc_stokes_validation.cc and validation_short_test.cc at tau = 0.6 ...
/// 3), and the slowest transient of a fixed bed, the Darcy relaxation of the mean flow with time
/// constant kappa/nu (kappa the permeability, about d^2/(18 phi F)), shortens as nu grows: tau = 3
/// (nu = 5/6) reaches the steady state 2.5 times sooner than the engine's default tau = 1.5.
constexpr double kFastStokesTau = 3.0;

/// Stokes flow (Re = 0, linear equilibrium) with the given scheme at relaxation time tau.
inline RunOptions stokes_options(Collision collision, Boundary boundary, double tau) {
  RunOptions options;
  options.collision = collision;
  options.boundary = boundary;
  options.re = 0.0;
  options.tau = tau;
  // Failures come back as converged = false with the diagnosis, which the tests print.
  options.throw_on_failure = false;
  return options;
}

// ------------------------------------------------------------------------------------------------
// Statistics.

inline double mean_of(const std::vector<double>& values) {
  double sum = 0.0;
  for (double v : values) sum += v;
  return values.empty() ? NAN : sum / static_cast<double>(values.size());
}

/// Standard error of the mean (sample standard deviation / sqrt(n)); NaN for fewer than 2 values.
inline double standard_error_of(const std::vector<double>& values) {
  if (values.size() < 2) return NAN;
  const double m = mean_of(values);
  double sum = 0.0;
  for (double v : values) sum += (v - m) * (v - m);
  const double n = static_cast<double>(values.size());
  return std::sqrt(sum / (n - 1.0) / n);
}

/// Least-squares slope of ln y against ln x (y > 0): with y = |error| and x = d, minus the
/// observed convergence order.
inline double log_log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = std::min(x.size(), y.size());
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double lx = std::log(x[i]);
    const double ly = std::log(y[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  const double m = static_cast<double>(n);
  return (m * sxy - sx * sy) / (m * sxx - sx * sx);
}

/// Richardson extrapolation from three resolutions d1 < d2 < d3 with the error model
/// F(d) = F_inf + C d^-p: p solves (F1 - F2)/(F2 - F3) = (d1^-p - d2^-p)/(d2^-p - d3^-p) (the
/// right side increases monotonically with p). valid = false when the differences change sign
/// (no monotone convergence: no order can be observed) or p falls outside [0.1, 8].
struct Richardson {
  bool valid = false;
  double order = NAN;
  double extrapolated = NAN;
  /// |F3 - F_inf| / |F_inf|: the estimated relative error of the finest run.
  double finest_error = NAN;
};

inline Richardson richardson_three(const double d[3], const double F[3]) {
  Richardson result;
  const double ratio = (F[0] - F[1]) / (F[1] - F[2]);
  if (!(ratio > 0.0) || !std::isfinite(ratio)) return result;
  const auto model_ratio = [&](double p) {
    return (std::pow(d[0], -p) - std::pow(d[1], -p)) / (std::pow(d[1], -p) - std::pow(d[2], -p));
  };
  double lo = 0.1, hi = 8.0;
  if (ratio < model_ratio(lo) || ratio > model_ratio(hi)) return result;
  for (int iteration = 0; iteration < 200; ++iteration) {
    const double mid = 0.5 * (lo + hi);
    (model_ratio(mid) < ratio ? lo : hi) = mid;
  }
  const double p = 0.5 * (lo + hi);
  const double c = (F[0] - F[1]) / (std::pow(d[0], -p) - std::pow(d[1], -p));
  result.valid = true;
  result.order = p;
  result.extrapolated = F[2] - c * std::pow(d[2], -p);
  result.finest_error = std::fabs(F[2] - result.extrapolated) / std::fabs(result.extrapolated);
  return result;
}

// ------------------------------------------------------------------------------------------------
// Reporting: every measured figure goes to stdout (ctest --output-on-failure / -V shows it).

inline std::string format_run(const RunResult& r) {
  char line[512];
  std::snprintf(line, sizeof(line),
                "converged=%d steps=%lld wall=%.2fs mflups=%.1f F=%.6g re=%.4g tau=%.4g "
                "balance=%.2e mach=%.3g phi=%.4f phi_lattice=%.4f d=%.3f",
                r.converged ? 1 : 0, static_cast<long long>(r.steps), r.wall_s, r.mflups, r.F, r.re,
                r.tau, r.momentum_balance_rel, r.mach_max, r.phi, r.phi_lattice, r.d);
  return line;
}

inline std::string scientific(double x) {
  char text[32];
  std::snprintf(text, sizeof(text), "%+.4e", x);
  return text;
}

/// One line on a Poiseuille run: its errors against the parabola and the lattice solution.
inline std::string describe(const PlatesOutcome& o) {
  char line[256];
  std::snprintf(line, sizeof(line),
                "lambda=%.4g U-error vs parabola=%.3e, vs lattice solution=%.3e; profile vs "
                "parabola=%.3e, vs lattice=%.3e; cross=%.1e | ",
                o.lambda, o.mean_error_vs_parabola, o.mean_error_vs_lattice_solution,
                o.profile_error_vs_parabola, o.profile_error_vs_lattice_solution, o.cross_flow);
  return line + format_run(o.result);
}

inline void report(const std::string& label, const std::string& text) {
  std::printf("[validation] %s: %s\n", label.c_str(), text.c_str());
  std::fflush(stdout);
}

}  // namespace validation
}  // namespace lbm
}  // namespace draglab
