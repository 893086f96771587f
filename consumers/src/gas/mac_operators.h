// MAC (staggered-grid) operators of the gas momentum equation shared by the bed models (the
// DPM's GasPhase, the TFM, later the DBM): the advective acceleration u.grad u (first-order
// upwind) and the viscous force div(eps mu grad u) on one x- or z-face, with the ghost values of
// the boundary conditions. Each model assembles its own predictor from them (its time level,
// its drag coupling, its body forces) and shares the pressure equation (mac_pressure.h).
//
// Layout (gas_phase.h): u(i, j) on x-faces, (nx + 1) x nz; w(i, j) on z-faces, nx x (nz + 1);
// eps(i, j) at the cell centres, nx x nz. Ghost values: the tangential u below the bottom plate
// is -u (no slip), above the outlet u (zero gradient); the tangential w beyond a side wall is -w
// (no slip) or +w (free slip); eps is continued by its boundary cell. With `periodic` the
// vertical direction wraps (the DPM's validation boxes).
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace draglab {
namespace consumers {
namespace internal {

/// The advective acceleration [m/s^2] and the viscous force per volume [N/m^3] on one face.
struct FaceMomentumTerms {
  double advection = 0.0;  ///< (u . grad) u of the face's component.
  double viscous = 0.0;    ///< div(eps mu grad u) of the face's component.
};

class MacGasOperators {
 public:
  /// u, w: the face velocities; eps: the gas fraction the viscous term weights with. The arrays
  /// must outlive the operators.
  MacGasOperators(const Eigen::ArrayXXd& u, const Eigen::ArrayXXd& w, const Eigen::ArrayXXd& eps,
                  double dx, double dz, double mu, bool side_noslip, bool periodic)
      : u_(u),
        w_(w),
        eps_(eps),
        nx_(static_cast<int>(eps.rows())),
        nz_(static_cast<int>(eps.cols())),
        dx_(dx),
        dz_(dz),
        mu_(mu),
        noslip_(side_noslip),
        periodic_(periodic) {}

  /// The x-face between cells (i - 1, j) and (i, j), 0 < i < nx.
  FaceMomentumTerms XFace(int i, int j) const {
    FaceMomentumTerms t;
    const double uc = u_(i, j);
    const double wc = 0.25 * (w_(i - 1, j) + w_(i, j) + w_(i - 1, j + 1) + w_(i, j + 1));
    const double dudx = uc > 0 ? (uc - u_(i - 1, j)) / dx_ : (u_(i + 1, j) - uc) / dx_;
    const double dudz = wc > 0 ? (uc - UAt(i, j - 1)) / dz_ : (UAt(i, j + 1) - uc) / dz_;
    t.advection = uc * dudx + wc * dudz;
    // eps at the cell centres (x) and the corners (z).
    const double e_e = Eps(i, j), e_w = Eps(i - 1, j);
    const double e_n = 0.25 * (Eps(i - 1, j) + Eps(i, j) + Eps(i - 1, j + 1) + Eps(i, j + 1));
    const double e_s = 0.25 * (Eps(i - 1, j) + Eps(i, j) + Eps(i - 1, j - 1) + Eps(i, j - 1));
    const double flux_n = (!periodic_ && j == nz_ - 1) ? 0.0 : e_n * (UAt(i, j + 1) - uc) / dz_;
    const double flux_s = e_s * (uc - UAt(i, j - 1)) / dz_;
    t.viscous = mu_ * ((e_e * (u_(i + 1, j) - uc) - e_w * (uc - u_(i - 1, j))) / (dx_ * dx_) +
                       (flux_n - flux_s) / dz_);
    return t;
  }

  /// The z-face between cells (i, j - 1) and (i, j); j = nz is the outlet face (non-periodic),
  /// with the velocity above it continued (zero gradient).
  FaceMomentumTerms ZFace(int i, int j) const {
    FaceMomentumTerms t;
    const bool top = !periodic_ && j == nz_;
    const double wc = w_(i, j);
    const int jc0 = Wrap(j - 1), jc1 = top ? nz_ - 1 : Wrap(j);
    const double uc = 0.25 * (u_(i, jc0) + u_(i + 1, jc0) + u_(i, jc1) + u_(i + 1, jc1));
    const double w_below = WAt(i, j - 1);
    const double w_above = top ? wc : WAt(i, j + 1);
    const double dwdz = wc > 0 ? (wc - w_below) / dz_ : (w_above - wc) / dz_;
    const double dwdx = uc > 0 ? (wc - WAt(i - 1, j)) / dx_ : (WAt(i + 1, j) - wc) / dx_;
    t.advection = uc * dwdx + wc * dwdz;
    const double e_up = top ? Eps(i, nz_ - 1) : Eps(i, j);
    const double e_dn = Eps(i, j - 1);
    const double e_e =
        0.25 * (Eps(i, j - 1) + Eps(i + 1, j - 1) + e_up + Eps(i + 1, top ? nz_ - 1 : j));
    const double e_w =
        0.25 * (Eps(i, j - 1) + Eps(i - 1, j - 1) + e_up + Eps(i - 1, top ? nz_ - 1 : j));
    // Side walls: the ghost value encodes no slip (-w) or free slip (+w, zero flux).
    t.viscous = mu_ * ((e_e * (WAt(i + 1, j) - wc) - e_w * (wc - WAt(i - 1, j))) / (dx_ * dx_) +
                       (e_up * (w_above - wc) - e_dn * (wc - w_below)) / (dz_ * dz_));
    return t;
  }

 private:
  int Wrap(int j) const { return periodic_ ? (j + nz_) % nz_ : std::clamp(j, 0, nz_ - 1); }
  double Eps(int i, int j) const { return eps_(std::clamp(i, 0, nx_ - 1), Wrap(j)); }
  /// Tangential u next to the bottom plate: no slip (ghost -u); at the outlet: zero gradient.
  double UAt(int i, int j) const {
    if (periodic_) return u_(i, (j + nz_) % nz_);
    if (j < 0) return -u_(i, 0);
    if (j >= nz_) return u_(i, nz_ - 1);
    return u_(i, j);
  }
  /// Tangential w next to the side walls: ghost -w (no slip) or +w (free slip).
  double WAt(int i, int j) const {
    if (periodic_) j = (j + nz_) % nz_;
    j = std::clamp(j, 0, nz_);
    if (i < 0) return noslip_ ? -w_(0, j) : w_(0, j);
    if (i >= nx_) return noslip_ ? -w_(nx_ - 1, j) : w_(nx_ - 1, j);
    return w_(i, j);
  }

  const Eigen::ArrayXXd& u_;
  const Eigen::ArrayXXd& w_;
  const Eigen::ArrayXXd& eps_;
  int nx_, nz_;
  double dx_, dz_, mu_;
  bool noslip_, periodic_;
};

}  // namespace internal
}  // namespace consumers
}  // namespace draglab
