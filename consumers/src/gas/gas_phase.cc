// Volume-averaged gas phase (seed Eqs. 8-9) on a 2-D MAC grid: explicit upwind advection and
// explicit viscosity, implicit drag, and a pressure projection that is exact for the continuity
// equation d eps/dt + div(eps u) = 0 (see docs/gas_phase.md).
//
// Why incompressible: in these beds the gas speed is a few m/s (Mach << 0.01) and the pressure
// drop over a 0.2-0.5 m bed is ~ 1-5 kPa, so the gas density changes by < 5e-2 % over the bed
// height (< 1e-3 relative); an acoustic (compressible) time step would be ~ 1e-6 s for nothing.
// The gas density is therefore constant and continuity becomes a constraint on eps u, enforced
// by a pressure projection.
//
// Why implicit drag: the gas-side relaxation time eps rho_g / beta is ~ 1e-4 s in a dense bed of
// 2.5 mm glass (and 1e-6 s for fine powders); forward Euler is unstable for dt > 2 tau. Putting
// beta on the diagonal of the momentum update (a = eps rho + dt beta) makes the update
// unconditionally stable for the drag term; the pressure equation then uses the same a, so the
// projected velocity satisfies the implicit momentum equation and continuity together.
#include "draglab/consumers/gas_phase.h"

#include "gas/mac_pressure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "draglab/error.h"
#include "gas/mac_operators.h"

namespace draglab {
namespace consumers {
namespace {

std::string Fmt(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

[[noreturn]] void Bad(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

}  // namespace

bool GasOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& text) {
    if (why != nullptr) *why = text;
    return false;
  };
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (nx < 2 || nx > 100000) return fail("gas.nx = " + std::to_string(nx) + " must be in [2, 1e5]");
  if (nz < 2 || nz > 100000) return fail("gas.nz = " + std::to_string(nz) + " must be in [2, 1e5]");
  if (!positive(width_m)) return fail("gas.width_m = " + Fmt("%g", width_m) + " must be > 0");
  if (!positive(height_m)) return fail("gas.height_m = " + Fmt("%g", height_m) + " must be > 0");
  if (!positive(depth_m)) return fail("gas.depth_m = " + Fmt("%g", depth_m) + " must be > 0");
  if (!positive(rho_g)) return fail("gas.rho_g = " + Fmt("%g", rho_g) + " kg/m^3 must be > 0");
  if (!positive(mu_g)) return fail("gas.mu_g = " + Fmt("%g", mu_g) + " Pa s must be > 0");
  if (!std::isfinite(gravity_z)) return fail("gas.gravity_z must be finite");
  if (!std::isfinite(body_force_z) || !std::isfinite(body_force_x)) {
    return fail("gas.body_force_x/z must be finite");
  }
  if (!std::isfinite(outlet_pressure_pa)) return fail("gas.outlet_pressure_pa must be finite");
  if (!std::isfinite(background_velocity_m_s)) {
    return fail("gas.background_velocity_m_s must be finite");
  }
  if (!std::isfinite(jet_width_m) || jet_width_m < 0.0 || jet_width_m > width_m) {
    return fail("gas.jet_width_m = " + Fmt("%g", jet_width_m) +
                " m must be in [0, width_m = " + Fmt("%g", width_m) + "]");
  }
  if (!std::isfinite(jet_velocity_m_s)) return fail("gas.jet_velocity_m_s must be finite");
  if (!std::isfinite(jet_start_s) || jet_start_s < 0.0) {
    return fail("gas.jet_start_s = " + Fmt("%g", jet_start_s) + " s must be >= 0");
  }
  if (!std::isfinite(inflow_ramp_s) || inflow_ramp_s < 0.0) {
    return fail("gas.inflow_ramp_s = " + Fmt("%g", inflow_ramp_s) + " s must be >= 0");
  }
  if (!std::isfinite(jet_duration_s) || jet_duration_s < 0.0) {
    return fail("gas.jet_duration_s = " + Fmt("%g", jet_duration_s) + " s must be >= 0");
  }
  if (!(cg_tolerance > 0.0 && cg_tolerance <= 1e-3)) {
    return fail("gas.cg_tolerance = " + Fmt("%g", cg_tolerance) + " must be in (0, 1e-3]");
  }
  if (cg_max_iterations < 1) return fail("gas.cg_max_iterations must be >= 1");
  if (!(cfl_max > 0.0 && cfl_max <= 1.0)) {
    return fail("gas.cfl_max = " + Fmt("%g", cfl_max) + " must be in (0, 1]");
  }
  if (vertical == VerticalBoundary::kPeriodic &&
      (background_velocity_m_s != 0.0 || jet_width_m > 0.0)) {
    return fail(
        "gas.vertical = periodic takes no inflow: background_velocity_m_s and "
        "jet_width_m must be 0");
  }
  return true;
}

std::string GasDiagnostics::BriefReport() const {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer,
                "gas t = %.6g s (%ld steps): mass in %.6g kg/s, out %.6g kg/s, storage %.6g kg/s, "
                "imbalance %.3g kg/s; max |div| %.3g 1/s; CFL %.3g; Poisson residual %.3g (%d it)",
                time_s, steps, mass_in_kg_s, mass_out_kg_s, storage_kg_s, mass_imbalance_kg_s,
                max_divergence_1_s, cfl, poisson_residual, poisson_iterations);
  return buffer;
}

GasPhase::GasPhase(const GasOptions& options) : opt_(options) {
  std::string why;
  if (!opt_.IsValid(&why)) Bad(why);
  dx_ = opt_.width_m / opt_.nx;
  dz_ = opt_.height_m / opt_.nz;
  u_ = Eigen::ArrayXXd::Zero(opt_.nx + 1, opt_.nz);
  w_ = Eigen::ArrayXXd::Zero(opt_.nx, opt_.nz + 1);
  p_ = Eigen::ArrayXXd::Constant(opt_.nx, opt_.nz, opt_.outlet_pressure_pa);
  UpdatePressureGradient();
  eps_ = Eigen::ArrayXXd::Ones(opt_.nx, opt_.nz);
  eps_next_ = eps_;
  beta_ = Eigen::ArrayXXd::Zero(opt_.nx, opt_.nz);
  upx_ = beta_;
  upz_ = beta_;
  MacPressureOptions po;
  po.nx = opt_.nx;
  po.nz = opt_.nz;
  po.dx = dx_;
  po.dz = dz_;
  po.vertical = opt_.vertical;
  po.solver = opt_.poisson;
  po.cg_tolerance = opt_.cg_tolerance;
  po.cg_max_iterations = opt_.cg_max_iterations;
  pressure_ = std::make_unique<MacPressureSolver>(po);
}

GasPhase::~GasPhase() = default;
GasPhase::GasPhase(GasPhase&&) noexcept = default;
GasPhase& GasPhase::operator=(GasPhase&&) noexcept = default;

void GasPhase::Check(const Eigen::ArrayXXd& a, int rows, int cols, const char* name, double lo,
                     double hi, bool lo_open) const {
  if (a.rows() != rows || a.cols() != cols) {
    Bad(std::string("gas field ") + name + " has " + std::to_string(a.rows()) + " x " +
        std::to_string(a.cols()) + " entries, expected nx x nz = " + std::to_string(rows) + " x " +
        std::to_string(cols));
  }
  for (int j = 0; j < cols; ++j) {
    for (int i = 0; i < rows; ++i) {
      const double v = a(i, j);
      if (!std::isfinite(v) || v > hi || v < lo || (lo_open && v == lo)) {
        Bad(std::string("gas field ") + name + "(" + std::to_string(i) + ", " + std::to_string(j) +
            ") = " + Fmt("%g", v) + " must be in " + (lo_open ? "(" : "[") + Fmt("%g", lo) + ", " +
            Fmt("%g", hi) + "]");
      }
    }
  }
}

void GasPhase::SetSolids(const Eigen::ArrayXXd& eps_next, const Eigen::ArrayXXd& beta,
                         const Eigen::ArrayXXd& up_x, const Eigen::ArrayXXd& up_z) {
  const double inf = std::numeric_limits<double>::max();
  Check(eps_next, opt_.nx, opt_.nz, "eps", 0.0, 1.0, true);
  Check(beta, opt_.nx, opt_.nz, "beta", 0.0, inf, false);
  Check(up_x, opt_.nx, opt_.nz, "up_x", -inf, inf, false);
  Check(up_z, opt_.nx, opt_.nz, "up_z", -inf, inf, false);
  eps_next_ = eps_next;
  beta_ = beta;
  upx_ = up_x;
  upz_ = up_z;
}

void GasPhase::SetVoidFraction(const Eigen::ArrayXXd& eps) {
  Check(eps, opt_.nx, opt_.nz, "eps", 0.0, 1.0, true);
  eps_ = eps;
  eps_next_ = eps;
}

void GasPhase::SetUniformVelocity(double u_x, double u_z) {
  if (!std::isfinite(u_x) || !std::isfinite(u_z)) Bad("gas initial velocity must be finite");
  u_.setConstant(u_x);
  u_.row(0).setZero();  // walls
  u_.row(opt_.nx).setZero();
  w_.setConstant(u_z);
}

double inflow_superficial_velocity(const GasOptions& o, double dx, int i, double t) {
  if (o.vertical != VerticalBoundary::kInflowOutlet) return 0.0;
  const double ramp = o.inflow_ramp_s;
  // Linear ramp 0 -> 1 over [a, a + ramp] (a step at a when ramp = 0).
  auto opened = [ramp](double t_now, double a) {
    if (ramp <= 0.0) return t_now >= a ? 1.0 : 0.0;
    return std::clamp((t_now - a) / ramp, 0.0, 1.0);
  };
  double velocity = o.background_velocity_m_s * opened(t, 0.0);
  const double jet_fraction =
      o.jet_width_m > 0.0 ? opened(t, o.jet_start_s) - opened(t, o.jet_start_s + o.jet_duration_s)
                          : 0.0;
  if (jet_fraction > 0.0) {
    // The slot is centred; a partly covered face gets the area-weighted mean so the injected
    // volume flow is exactly jet_width * jet_velocity per unit depth on any grid.
    const double x0 = 0.5 * (o.width_m - o.jet_width_m);
    const double x1 = x0 + o.jet_width_m;
    const double overlap = std::max(0.0, std::min(x1, (i + 1) * dx) - std::max(x0, i * dx));
    velocity += jet_fraction * (o.jet_velocity_m_s - o.background_velocity_m_s) * overlap / dx;
  }
  return velocity;
}

double GasPhase::InflowSuperficialVelocity(int i, double t) const {
  return inflow_superficial_velocity(opt_, dx_, i, t);
}

double GasPhase::StableTimeStep(double cfl) const {
  double rate = 0.0;  // max (|u|/dx + |w|/dz) over cells
  for (int j = 0; j < opt_.nz; ++j) {
    for (int i = 0; i < opt_.nx; ++i) {
      const double uc = 0.5 * (std::abs(u_(i, j)) + std::abs(u_(i + 1, j)));
      const double wc = 0.5 * (std::abs(w_(i, j)) + std::abs(w_(i, j + 1)));
      rate = std::max(rate, uc / dx_ + wc / dz_);
    }
  }
  const double viscous = opt_.rho_g / (2.0 * opt_.mu_g * (1.0 / (dx_ * dx_) + 1.0 / (dz_ * dz_)));
  return rate > 0.0 ? std::min(cfl / rate, viscous) : viscous;
}

void GasPhase::Step(double dt) {
  const int nx = opt_.nx, nz = opt_.nz;
  const bool periodic = opt_.vertical == VerticalBoundary::kPeriodic;
  const bool noslip = opt_.side_walls == WallSlip::kNoSlip;
  const double rho = opt_.rho_g, mu = opt_.mu_g;
  if (!std::isfinite(dt) || dt <= 0.0) Bad("gas dt = " + Fmt("%g", dt) + " s must be > 0");

  // Stability limits of the explicit parts (checked before the step, on the current state).
  const double viscous_limit = rho / (2.0 * mu * (1.0 / (dx_ * dx_) + 1.0 / (dz_ * dz_)));
  if (dt > viscous_limit) {
    Bad("gas dt = " + Fmt("%g", dt) + " s is above the explicit viscous stability limit " +
        Fmt("%g", viscous_limit) + " s (rho dx^2 dz^2 / (2 mu (dx^2 + dz^2))); remedy: lower dt");
  }
  double cfl = 0.0, max_speed = 0.0;
  for (int j = 0; j < nz; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double uc = 0.5 * (std::abs(u_(i, j)) + std::abs(u_(i + 1, j)));
      const double wc = 0.5 * (std::abs(w_(i, j)) + std::abs(w_(i, j + 1)));
      cfl = std::max(cfl, dt * (uc / dx_ + wc / dz_));
      max_speed = std::max(max_speed, std::hypot(uc, wc));
    }
  }
  if (!(cfl <= opt_.cfl_max)) {
    // Name the likely cause: forward-Euler drag is unstable for dt > 2 tau, tau = eps rho / beta.
    double tau_min = std::numeric_limits<double>::infinity();
    for (int j = 0; j < nz; ++j) {
      for (int i = 0; i < nx; ++i) {
        if (beta_(i, j) > 0.0) tau_min = std::min(tau_min, eps_(i, j) * rho / beta_(i, j));
      }
    }
    std::string cause;
    if (opt_.drag == DragCoupling::kExplicit && dt > 2.0 * tau_min) {
      cause =
          "; the gas velocity is diverging because the explicit drag coupling is unstable "
          "for dt > 2 tau = " +
          Fmt("%g", 2.0 * tau_min) + " s (tau = eps rho_g / beta): use the implicit drag coupling";
    } else if (max_speed > 1e3) {
      cause = "; the gas velocity is diverging";
    }
    Bad("gas dt = " + Fmt("%g", dt) + " s gives CFL " + Fmt("%.3g", cfl) + " > cfl_max " +
        Fmt("%g", opt_.cfl_max) + " (max gas speed " + Fmt("%.3g", max_speed) +
        " m/s at t = " + Fmt("%g", time_) + " s" + cause +
        "); remedy: lower dt to StableTimeStep(0.5) = " + Fmt("%g", StableTimeStep(0.5)) + " s");
  }

  const bool implicit = opt_.drag == DragCoupling::kImplicit;
  const double t_new = time_ + dt;
  auto wrap = [&](int j) { return periodic ? (j + nz) % nz : std::clamp(j, 0, nz - 1); };
  auto eps_new = [&](int i, int j) { return eps_next_(std::clamp(i, 0, nx - 1), wrap(j)); };

  // ---- momentum predictor: u_hat = rhs / a, with u^{n+1} = u_hat - (dt eps / a) dp/dn ----
  // Advective form eps rho (du/dt + u.grad u): equal to the conservative form of Eq. 9 when
  // continuity holds, and it keeps a uniform flow uniform where eps varies.
  Eigen::ArrayXXd u_hat = Eigen::ArrayXXd::Zero(nx + 1, nz),
                  a_u = Eigen::ArrayXXd::Ones(nx + 1, nz);
  Eigen::ArrayXXd w_hat = Eigen::ArrayXXd::Zero(nx, nz + 1),
                  a_w = Eigen::ArrayXXd::Ones(nx, nz + 1);
  const internal::MacGasOperators ops(u_, w_, eps_, dx_, dz_, mu, noslip, periodic);
  for (int j = 0; j < nz; ++j) {
    for (int i = 1; i < nx; ++i) {
      const double ef = 0.5 * (eps_new(i - 1, j) + eps_new(i, j));
      const double bf = 0.5 * (beta_(i - 1, j) + beta_(i, j));
      const double upf = 0.5 * (upx_(i - 1, j) + upx_(i, j));
      const double uc = u_(i, j);
      const internal::FaceMomentumTerms terms = ops.XFace(i, j);
      double rhs = ef * rho * uc +
                   dt * (-ef * rho * terms.advection + terms.viscous + ef * opt_.body_force_x);
      double a = ef * rho;
      if (implicit) {
        rhs += dt * bf * upf;
        a += dt * bf;
      } else {
        rhs += dt * bf * (upf - uc);
      }
      a_u(i, j) = a;
      u_hat(i, j) = rhs / a;
    }
  }
  // Fixed z-faces: the bottom inflow (non-periodic); the top outlet face is computed.
  const int j_first = periodic ? 0 : 1;
  const int j_last = periodic ? nz - 1 : nz;
  for (int j = j_first; j <= j_last; ++j) {
    for (int i = 0; i < nx; ++i) {
      const bool top = !periodic && j == nz;
      const double ef = top ? eps_new(i, nz - 1) : 0.5 * (eps_new(i, j - 1) + eps_new(i, j));
      const double bf = top ? beta_(i, nz - 1) : 0.5 * (beta_(i, wrap(j - 1)) + beta_(i, wrap(j)));
      const double upf = top ? upz_(i, nz - 1) : 0.5 * (upz_(i, wrap(j - 1)) + upz_(i, wrap(j)));
      const double wc = w_(i, j);
      const internal::FaceMomentumTerms terms = ops.ZFace(i, j);
      double rhs = ef * rho * wc + dt * (-ef * rho * terms.advection + terms.viscous +
                                         ef * rho * opt_.gravity_z + ef * opt_.body_force_z);
      double a = ef * rho;
      if (implicit) {
        rhs += dt * bf * upf;
        a += dt * bf;
      } else {
        rhs += dt * bf * (upf - wc);
      }
      a_w(i, j) = a;
      w_hat(i, j) = rhs / a;
    }
  }
  std::vector<double> w_in(nx, 0.0);
  if (!periodic) {
    for (int i = 0; i < nx; ++i) {
      w_in[i] = InflowSuperficialVelocity(i, t_new);
      w_hat(i, 0) = w_in[i] / eps_new(i, 0);  // interstitial velocity of the prescribed flux
    }
  }

  // ---- pressure equation: -div(C grad p) = -(div(eps u_hat) + d eps/dt), C = dt eps^2 / a ----
  Eigen::ArrayXXd c_u = Eigen::ArrayXXd::Zero(nx + 1, nz), c_w = Eigen::ArrayXXd::Zero(nx, nz + 1);
  for (int j = 0; j < nz; ++j) {
    for (int i = 1; i < nx; ++i) {
      const double ef = 0.5 * (eps_new(i - 1, j) + eps_new(i, j));
      c_u(i, j) = dt * ef * ef / a_u(i, j);
    }
  }
  for (int j = j_first; j <= j_last; ++j) {
    for (int i = 0; i < nx; ++i) {
      const bool top = !periodic && j == nz;
      const double ef = top ? eps_new(i, nz - 1) : 0.5 * (eps_new(i, j - 1) + eps_new(i, j));
      c_w(i, j) = dt * ef * ef / a_w(i, j);
    }
  }
  if (periodic) c_w.col(nz) = c_w.col(0);

  Eigen::ArrayXXd continuity(nx, nz);
  const double volume = dx_ * dz_;
  for (int j = 0; j < nz; ++j) {
    for (int i = 0; i < nx; ++i) {
      // Net outflow of eps u_hat (per unit depth) plus the storage term.
      double out = 0.0;
      if (i > 0) out -= 0.5 * (eps_new(i - 1, j) + eps_new(i, j)) * u_hat(i, j) * dz_;
      if (i < nx - 1) out += 0.5 * (eps_new(i, j) + eps_new(i + 1, j)) * u_hat(i + 1, j) * dz_;
      if (periodic || j > 0) {
        out -= 0.5 * (eps_new(i, j - 1) + eps_new(i, j)) * w_hat(i, j) * dx_;
      } else {
        out -= w_in[i] * dx_;
      }
      if (periodic || j < nz - 1) {
        out += 0.5 * (eps_new(i, j) + eps_new(i, j + 1)) *
               w_hat(i, (j + 1) % (periodic ? nz : nz + 1)) * dx_;
      } else {
        out += eps_new(i, j) * w_hat(i, nz) * dx_;
      }
      continuity(i, j) = out + (eps_next_(i, j) - eps_(i, j)) * volume / dt;
    }
  }
  try {
    p_ = pressure_->Solve(c_u, c_w, continuity, opt_.outlet_pressure_pa, p_);
  } catch (const Error& e) {
    throw Error(e.code(), std::string("gas ") + e.what());
  }
  diag_.poisson_residual = pressure_->diagnostics().relative_residual;
  diag_.poisson_iterations = pressure_->diagnostics().iterations;
  UpdatePressureGradient();

  // ---- projection ----
  for (int j = 0; j < nz; ++j) {
    for (int i = 1; i < nx; ++i) {
      const double ef = 0.5 * (eps_new(i - 1, j) + eps_new(i, j));
      u_(i, j) = u_hat(i, j) - dt * ef / a_u(i, j) * (p_(i, j) - p_(i - 1, j)) / dx_;
    }
  }
  for (int j = j_first; j <= j_last; ++j) {
    for (int i = 0; i < nx; ++i) {
      const bool top = !periodic && j == nz;
      const double ef = top ? eps_new(i, nz - 1) : 0.5 * (eps_new(i, j - 1) + eps_new(i, j));
      const double dpdz = top ? (opt_.outlet_pressure_pa - p_(i, nz - 1)) / (0.5 * dz_)
                              : (p_(i, wrap(j)) - p_(i, wrap(j - 1))) / dz_;
      w_(i, j) = w_hat(i, j) - dt * ef / a_w(i, j) * dpdz;
    }
  }
  if (periodic) {
    w_.col(nz) = w_.col(0);
  } else {
    w_.col(0) = w_hat.col(0);
  }

  // ---- divergence check, mass balance ----
  if (!u_.allFinite() || !w_.allFinite() || !p_.allFinite()) {
    Bad("gas diverged at t = " + Fmt("%g", t_new) +
        " s: non-finite velocity or pressure with dt = " + Fmt("%g", dt) +
        " s; remedy: lower dt (CFL <= 0.5) and use the implicit drag coupling");
  }
  double max_div = 0.0, storage = 0.0, in = 0.0, out_flow = 0.0;
  for (int j = 0; j < nz; ++j) {
    for (int i = 0; i < nx; ++i) {
      double out = 0.0;
      if (i > 0) out -= 0.5 * (eps_next_(i - 1, j) + eps_next_(i, j)) * u_(i, j) * dz_;
      if (i < nx - 1) out += 0.5 * (eps_next_(i, j) + eps_next_(i + 1, j)) * u_(i + 1, j) * dz_;
      const double e_lo =
          (periodic || j > 0) ? 0.5 * (eps_new(i, j - 1) + eps_new(i, j)) : eps_new(i, 0);
      const double e_hi =
          (periodic || j < nz - 1) ? 0.5 * (eps_new(i, j) + eps_new(i, j + 1)) : eps_new(i, j);
      out += e_hi * w_(i, j + 1) * dx_ - e_lo * w_(i, j) * dx_;
      const double stored = (eps_next_(i, j) - eps_(i, j)) * volume / dt;
      max_div = std::max(max_div, std::abs(out + stored) / volume);
      storage += stored;
    }
  }
  if (!periodic) {
    for (int i = 0; i < nx; ++i) {
      in += w_in[i] * dx_;
      out_flow += eps_next_(i, nz - 1) * w_(i, nz) * dx_;
    }
  }
  const double mass_scale = rho * opt_.depth_m;
  diag_.mass_in_kg_s = mass_scale * in;
  diag_.mass_out_kg_s = mass_scale * out_flow;
  diag_.storage_kg_s = mass_scale * storage;
  diag_.mass_imbalance_kg_s = mass_scale * (in - out_flow - storage);
  diag_.max_divergence_1_s = max_div;

  eps_ = eps_next_;
  time_ = t_new;
  ++steps_;
  diag_.time_s = time_;
  diag_.steps = steps_;
  double cfl_after = 0.0;
  for (int j = 0; j < nz; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double uc = 0.5 * (std::abs(u_(i, j)) + std::abs(u_(i + 1, j)));
      const double wc = 0.5 * (std::abs(w_(i, j)) + std::abs(w_(i, j + 1)));
      cfl_after = std::max(cfl_after, dt * (uc / dx_ + wc / dz_));
    }
  }
  diag_.cfl = cfl_after;
}

namespace {

// Bilinear interpolation of a field sampled at (x0 + i h_x, z0 + j h_z), clamped at the edges.
double Bilinear(const Eigen::ArrayXXd& f, double x0, double z0, double hx, double hz, double x,
                double z) {
  const double sx = std::clamp((x - x0) / hx, 0.0, static_cast<double>(f.rows() - 1));
  const double sz = std::clamp((z - z0) / hz, 0.0, static_cast<double>(f.cols() - 1));
  const int i = std::min(static_cast<int>(sx), static_cast<int>(f.rows()) - 2);
  const int j = std::min(static_cast<int>(sz), static_cast<int>(f.cols()) - 2);
  const double fx = sx - i, fz = sz - j;
  return (1 - fx) * (1 - fz) * f(i, j) + fx * (1 - fz) * f(i + 1, j) + (1 - fx) * fz * f(i, j + 1) +
         fx * fz * f(i + 1, j + 1);
}

}  // namespace

Eigen::Vector2d GasPhase::VelocityAt(double x, double z) const {
  return {Bilinear(u_, 0.0, 0.5 * dz_, dx_, dz_, x, z),
          Bilinear(w_, 0.5 * dx_, 0.0, dx_, dz_, x, z)};
}

void GasPhase::UpdatePressureGradient() {
  const int nx = opt_.nx, nz = opt_.nz;
  const bool periodic = opt_.vertical == VerticalBoundary::kPeriodic;
  grad_px_.resize(nx, nz);
  grad_pz_.resize(nx, nz);
  for (int j = 0; j < nz; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int il = std::max(i - 1, 0), ir = std::min(i + 1, nx - 1);
      grad_px_(i, j) = (p_(ir, j) - p_(il, j)) / ((ir - il) * dx_);
      if (periodic) {
        grad_pz_(i, j) = (p_(i, (j + 1) % nz) - p_(i, (j + nz - 1) % nz)) / (2 * dz_);
      } else if (j == nz - 1) {
        // Outlet value half a cell above the last centre.
        grad_pz_(i, j) = (opt_.outlet_pressure_pa - p_(i, j - 1)) / (1.5 * dz_);
      } else {
        const int jl = std::max(j - 1, 0);
        grad_pz_(i, j) = (p_(i, j + 1) - p_(i, jl)) / ((j + 1 - jl) * dz_);
      }
    }
  }
}

Eigen::Vector2d GasPhase::PressureGradientAt(double x, double z) const {
  return {Bilinear(grad_px_, 0.5 * dx_, 0.5 * dz_, dx_, dz_, x, z),
          Bilinear(grad_pz_, 0.5 * dx_, 0.5 * dz_, dx_, dz_, x, z)};
}

double width_averaged_pressure(const Eigen::ArrayXXd& p, double dz, double z, bool outlet,
                               double outlet_pressure_pa) {
  const int nz = static_cast<int>(p.cols());
  Eigen::ArrayXd mean = p.colwise().mean().transpose();
  const double s = z / dz - 0.5;  // position in cell-centre index units
  if (outlet && s > nz - 1) {
    const double f = std::min((s - (nz - 1)) / 0.5, 1.0);
    return (1 - f) * mean(nz - 1) + f * outlet_pressure_pa;
  }
  // Linear between centres; below the first centre, extrapolated from the first two.
  const int j = std::clamp(static_cast<int>(std::floor(s)), 0, nz - 2);
  const double f = s - j;
  return (1 - f) * mean(j) + f * mean(j + 1);
}

double GasPhase::WidthAveragedPressure(double z) const {
  return width_averaged_pressure(p_, dz_, z, opt_.vertical == VerticalBoundary::kInflowOutlet,
                                 opt_.outlet_pressure_pa);
}

double GasPhase::PressureDrop(double z_low, double z_high) const {
  return WidthAveragedPressure(z_low) - WidthAveragedPressure(z_high);
}

}  // namespace consumers
}  // namespace draglab
