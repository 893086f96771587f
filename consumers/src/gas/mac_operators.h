// MAC (staggered-grid) operators of the momentum equations shared by the bed models (the DPM's
// GasPhase, the TFM, the DBM's emulsion): the advective acceleration u.grad u (first-order
// upwind) and the viscous force div(eps mu grad u) on one face, with the ghost values of the
// boundary conditions. Each model assembles its own predictor from them (its time level, its
// drag coupling, its body forces) and shares the pressure equation (mac_pressure.h).
// MacGasOperators is the 2-D (x, z) form of the pseudo-2D models; MacOperators3D the 3-D form,
// which with one cell across the depth and free-slip depth walls gives the same terms (tested).
//
// Layout (gas_phase.h): u(i, j) on x-faces, (nx + 1) x nz; w(i, j) on z-faces, nx x (nz + 1);
// eps(i, j) at the cell centres, nx x nz. Ghost values: the tangential u below the bottom plate
// is -u (no slip), above the outlet u (zero gradient); the tangential w beyond a side wall is -w
// (no slip) or +w (free slip); eps is continued by its boundary cell. With `periodic` the
// vertical direction wraps (the DPM's validation boxes).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>

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

/// The 3-D form on the layout of mac_pressure.h: axis 0 = x (width), 1 = z (up), 2 = y (depth);
/// cell (a0, a1, a2) at a0 + n0 (a1 + n1 a2); the faces normal to axis c have n_c + 1 entries
/// along c. Boundaries: the x and y walls are no-slip or free-slip each (ghost -v or +v of the
/// tangential component), the bottom is a no-slip wall (no flow through it), the top an outlet
/// (tangential velocity and the normal velocity above the top face continued). The faces on the
/// walls are not evaluated; the top face is.
class MacOperators3D {
 public:
  /// velocity[c]: the face velocities normal to axis c; eps: cell values. They must outlive
  /// the operators. n: cells per axis; h: cell size per axis [m].
  MacOperators3D(const std::array<const Eigen::VectorXd*, 3>& velocity, const Eigen::VectorXd& eps,
                 const std::array<int, 3>& n, const std::array<double, 3>& h, double mu,
                 bool x_walls_noslip, bool y_walls_noslip)
      : v_(velocity), eps_(eps), n_(n), h_(h), mu_(mu) {
    wall_sign_[0] = x_walls_noslip ? -1.0 : 1.0;
    wall_sign_[2] = y_walls_noslip ? -1.0 : 1.0;
  }

  /// Index of the face normal to axis c at position p.
  int FaceIndex(int c, const std::array<int, 3>& p) const {
    const int n0 = n_[0] + (c == 0), n1 = n_[1] + (c == 1);
    return p[0] + n0 * (p[1] + n1 * p[2]);
  }
  int CellIndex(int a0, int a1, int a2) const { return a0 + n_[0] * (a1 + n_[1] * a2); }

  /// The terms on the face normal to axis c at p (an interior face, or the top face for c = 1).
  FaceMomentumTerms Face(int c, const std::array<int, 3>& p) const {
    FaceMomentumTerms t;
    const double vc = V(c, p);
    for (int d = 0; d < 3; ++d) {
      const double h = h_[d];
      std::array<int, 3> up = p, dn = p;
      ++up[d];
      --dn[d];
      const double v_up = V(c, up), v_dn = V(c, dn);
      const double a = d == c ? vc : Advecting(c, d, p);
      t.advection += a * (a > 0 ? (vc - v_dn) / h : (v_up - vc) / h);
      double e_up, e_dn;
      if (d == c) {
        e_up = Eps(p, c, d, 0);
        e_dn = Eps(p, c, d, -1);
      } else {
        e_up = EdgeEps(p, c, d, 1);
        e_dn = EdgeEps(p, c, d, 0);
      }
      t.viscous += (e_up * (v_up - vc) - e_dn * (vc - v_dn)) / (h * h);
    }
    t.viscous *= mu_;
    return t;
  }

 private:
  /// Face velocity of component c at p with the boundary ghosts.
  double V(int c, std::array<int, 3> p) const {
    double sign = 1.0;
    for (int a = 0; a < 3; ++a) {
      const int last = n_[a] - (a == c ? 0 : 1);
      if (p[a] > last) {
        // Above the top (a = 1): continued. Beyond a side wall: the wall's ghost.
        if (a != 1 && a != c) sign *= wall_sign_[a];
        p[a] = last;
      } else if (p[a] < 0) {
        // Below the bottom plate: no slip; beyond a side wall: the wall's ghost.
        if (a != c) sign *= a == 1 ? -1.0 : wall_sign_[a];
        p[a] = 0;
      }
    }
    return sign * (*v_[c])(FaceIndex(c, p));
  }
  /// The velocity of component d (!= c) at the face (c, p): the mean of the four d-faces around.
  double Advecting(int c, int d, const std::array<int, 3>& p) const {
    double sum = 0.0;
    for (int s = -1; s <= 0; ++s) {
      for (int e = 0; e <= 1; ++e) {
        std::array<int, 3> q = p;
        q[c] = std::clamp(p[c] + s, 0, n_[c] - 1);
        q[d] = p[d] + e;
        sum += (*v_[d])(FaceIndex(d, q));
      }
    }
    return 0.25 * sum;
  }
  double CellEps(std::array<int, 3> q) const {
    for (int a = 0; a < 3; ++a) q[a] = std::clamp(q[a], 0, n_[a] - 1);
    return eps_(CellIndex(q[0], q[1], q[2]));
  }
  /// eps of the cell along the face's own axis: offset 0 above the face, -1 below.
  double Eps(const std::array<int, 3>& p, int c, int, int offset) const {
    std::array<int, 3> q = p;
    q[c] += offset;
    return CellEps(q);
  }
  /// eps on the edge between the face (c, p) and its neighbour along d (side 1: +d, 0: -d): the
  /// mean of the four cells around the edge.
  double EdgeEps(const std::array<int, 3>& p, int c, int d, int side) const {
    double sum = 0.0;
    for (int s = -1; s <= 0; ++s) {
      for (int e = -1; e <= 0; ++e) {
        std::array<int, 3> q = p;
        q[c] = p[c] + s;
        q[d] = p[d] + side + e;
        sum += CellEps(q);
      }
    }
    return 0.25 * sum;
  }

  std::array<const Eigen::VectorXd*, 3> v_;
  const Eigen::VectorXd& eps_;
  std::array<int, 3> n_;
  std::array<double, 3> h_;
  double mu_;
  std::array<double, 3> wall_sign_{-1.0, -1.0, -1.0};
};

}  // namespace internal
}  // namespace consumers
}  // namespace draglab
