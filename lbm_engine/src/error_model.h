// error_model.h: a-priori estimates the driver needs: the BVK 2007 drag (first body force, and
// the sensitivity of F to the wall position) and the discretisation error estimate of a run.
#pragma once

#include "draglab/lbm/lbm.h"
#include "draglab/lbm/resolution.h"

namespace draglab {
namespace lbm {

/// Beetstra, van der Hoef & Kuipers (2007) drag-only F(phi, Re) (lbm.md 4.1), phi in (0, 1),
/// Re >= 0 (Re = 0: the van der Hoef 2005 Stokes fit).
double bvk2007_estimate(double phi, double re);

struct ErrorModelInput {
  Boundary boundary = Boundary::kInterpolated;
  Collision collision = Collision::kTrt;
  double tau = 1.0;
  double magic = 3.0 / 16.0;  ///< Lambda; (tau - 1/2)^2 for BGK, (tau - 1/2)/2 regularized.
  /// Regularized with TRT's wall correction (magic then TRT's): adds its remaining wall shift.
  bool wall_corrected = false;
  double d = 16.0;  ///< Nodes per diameter (the voxelization's, not a calibrated one).
  double phi = 0.1;
  double re = 0.0;
  Precision precision = Precision::kDouble;
};

/// Relative discretisation error of F estimated from the boundary scheme's order and the
/// resolution (see error_model.cc for the model and where its constants come from).
double discretisation_error_estimate(const ErrorModelInput& in);

/// How a run below the accuracy rules of resolution.h widens its discretisation estimate.
struct ResolutionWidening {
  /// (bound / d)^order with bound the larger of the gap and boundary-layer rules (order 1 for
  /// halfway bounce-back, 2 for an interpolated wall); 1 when d meets both.
  double factor = 1.0;
  /// (layer / d)^2 - 1 below the boundary-layer rule, else 0: the least relative error such a
  /// run can claim (error_model.cc says why).
  double floor = 0.0;
  double error = 0.0;           ///< max(error x factor, floor).
  bool boundary_layer = false;  ///< The boundary layer, not the pores, is what d misses most.
};

/// `error`, the estimate of discretisation_error_estimate, widened for a run at resolution d
/// below `need` (resolution_needed of the run's phi, Re and operator).
ResolutionWidening widen_for_resolution(double error, double d, const ResolutionNeed& need,
                                        Boundary boundary);

}  // namespace lbm
}  // namespace draglab
