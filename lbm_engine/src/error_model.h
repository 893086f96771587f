// error_model.h: a-priori estimates the driver needs: the BVK 2007 drag (first body force, and
// the sensitivity of F to the wall position) and the discretisation error estimate of a run.
#pragma once

#include "draglab/lbm/lbm.h"

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

}  // namespace lbm
}  // namespace draglab
