// draglab/lbm/calibration.h: the Stokes drag of simple-cubic (SC) sphere arrays (Sangani &
// Acrivos series) and the hydrodynamic-diameter calibration of bounce-back boundaries.
//
// Reference. Sangani & Acrivos (1982), Int. J. Multiphase Flow 8:343, Eq. 60 / Table 1: Stokes
// drag on an SC array, K = F_tot/(3 pi mu d U) = sum_{s=0}^{30} q_s chi^s with chi = d/L =
// (6 phi/pi)^(1/3), U the superficial velocity and F_tot the total force (mean-pressure part
// included). The drag-only canonical F = (1 - phi) K (drag_db/conventions.h). The series agrees
// with Zick & Homsy (1982) to 0.1 % for phi <= 0.216 and drifts above: it is accepted for
// phi <= kSanganiAcrivosMaxPhi only.
//
// Calibration (the procedure of Ladd 1994 and van der Hoef et al. 2005 for halfway bounce-back).
// A staircase sphere of input diameter d (lattice units) acts on the flow like a smooth sphere of
// a slightly different hydrodynamic diameter d_h, which depends on d, tau and the collision
// model. One Stokes run of a dilute SC array (one sphere in a periodic cube of edge L lattice
// units), averaged over several sub-grid positions of the sphere, measures the drag-only force
// per sphere F_d and the superficial velocity U; d_h is the diameter for which the series
// reproduces that force:
//   3 pi mu d_h U (1 - phi_h) K(phi_h) = F_d,   phi_h = (pi/6) (d_h/L)^3,
// solved by Newton's method on d_h (the left side grows monotonically with d_h). At a dilute
// phi the result hardly depends on the array, so d_h/d carries over to other packings at the
// same d, tau and scheme (RunOptions::use_hydrodynamic_diameter).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "draglab/lbm/lbm.h"

namespace draglab {
namespace lbm {

/// Number of terms and the largest phi for which the Sangani-Acrivos series is accepted.
constexpr int kSanganiAcrivosTerms = 31;
constexpr double kSanganiAcrivosMaxPhi = 0.22;

/// The coefficients q_0 .. q_30 of Sangani & Acrivos (1982) Eq. 60 (as transcribed in waLBerla's
/// DragForceSphereMEM test).
const std::array<double, kSanganiAcrivosTerms>& sangani_acrivos_coefficients();

/// K = F_tot/(3 pi mu d U) of an SC array in Stokes flow at solids fraction phi, in
/// (0, kSanganiAcrivosMaxPhi]; throws Error(kInvalidArgument) outside.
double sangani_acrivos_sc_K(double phi);
/// Drag-only canonical F = (1 - phi) K of an SC array in Stokes flow; same range.
double sangani_acrivos_sc_F(double phi);

/// Solves (pi/6 (d_h/L)^3 = phi_h)  d_h F_SA(phi_h) = diameter * F_measured for d_h, i.e. the
/// diameter that makes the measured drag equal the series. box_edge L and diameter d in lattice
/// units (> 0), F_measured the canonical F normalised with d (> 0). Throws Error(kInvalidArgument)
/// if no d_h with phi_h <= kSanganiAcrivosMaxPhi matches (the measured drag is far too large).
/// *iterations (optional) receives the Newton steps used (converged to 1e-13 relative).
double solve_hydrodynamic_diameter(double box_edge, double diameter, double F_measured,
                                   int* iterations = nullptr);

struct CalibrationOptions {
  double diameter = 16.0;  ///< Input sphere diameter d in lattice units, [4, 128].
  double phi = 0.01;       ///< Solids fraction of the dilute SC array, [0.001, 0.05].
  /// Collision, boundary, tau, magic, tolerance, step limit, threads, precision of the runs.
  /// The runs are Stokes runs: re is forced to 0; use_hydrodynamic_diameter is ignored.
  RunOptions run;
  /// Sub-grid positions of the sphere centre averaged over, [1, 64]: a bounce-back sphere's
  /// staircase (and drag, by about +-1 % at d = 8) depends on where its centre sits between
  /// nodes; a random packing samples all positions. Position k is offset from the box centre by
  /// the k-th point of a low-discrepancy sequence in the unit cell (k = 0: no offset).
  int positions = 4;
  /// Optional check: a second SC run at this phi in (0, kSanganiAcrivosMaxPhi] at the same d,
  /// compared with the series with d and with d_h (0 = no check).
  double check_phi = 0.0;
  /// True if valid; otherwise *error names the field and its allowed range.
  bool IsValid(std::string* error) const;
};

/// One SC array compared with the series, normalised with d and with d_h.
struct CalibrationCheck {
  double phi = 0.0;                       ///< Exact solids fraction with the input diameter.
  double phi_hydrodynamic = 0.0;          ///< (d_h/d)^3 phi.
  double F_input = 0.0;                   ///< Measured F normalised with d.
  double F_hydrodynamic = 0.0;            ///< Measured F normalised with d_h: F_input d/d_h.
  double F_reference = 0.0;               ///< Series at phi.
  double F_reference_hydrodynamic = 0.0;  ///< Series at phi_hydrodynamic.
  double error_input = 0.0;               ///< F_input/F_reference - 1.
  double error_hydrodynamic = 0.0;        ///< F_hydrodynamic/F_reference_hydrodynamic - 1.
  int positions = 0;                      ///< Sphere positions averaged over (F_input is the mean).
  double F_position_spread = 0.0;         ///< Standard deviation of F over the positions / mean.
  std::int64_t steps = 0;                 ///< Total over the positions.
  double wall_s = 0.0;                    ///< Total over the positions.
  RunResult run;                          ///< The run at the first position.
};

struct CalibrationResult {
  double diameter = 0.0;               ///< Input d as realised on the lattice (lattice units).
  std::int64_t box_nodes = 0;          ///< Edge L of the periodic cube, lattice units.
  double hydrodynamic_diameter = 0.0;  ///< d_h, lattice units.
  double ratio = 0.0;                  ///< d_h/d.
  int newton_iterations = 0;
  /// The calibration array itself (F_hydrodynamic equals F_reference_hydrodynamic there).
  CalibrationCheck calibration;
  bool has_check = false;
  CalibrationCheck check;  ///< Only when CalibrationOptions::check_phi > 0.
  double wall_s = 0.0;
  /// Multi-line summary: d_h/d, and what it changes (F and phi at the calibration and check
  /// points).
  std::string Report() const;
};

/// Runs the calibration (`positions` Stokes runs, twice that with the check). Throws
/// Error(kInvalidArgument) for invalid options and draglab::Error when a run fails (diverged or not
/// converged: no calibration is ever derived from an unconverged drag). `progress` receives the
/// fraction of the whole calibration and a status line.
CalibrationResult calibrate_hydrodynamic_diameter(const CalibrationOptions& options,
                                                  const ProgressCallback& progress = nullptr);

}  // namespace lbm
}  // namespace draglab
