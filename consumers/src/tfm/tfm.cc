// The two-fluid model (consumers/src/tfm/tfm.h, docs/tfm.md).
//
// Why partial elimination: the drag relaxation time of the gas, eps rho_g / beta, is ~1e-4 s in
// a bed of 2.5 mm glass and ~1e-7 s for 100 um powders; solving the 2 x 2 drag system of a face
// exactly makes the step independent of it, and the pressure equation then sees the coupled
// response of both phases (C = eps c_g + phi c_s).
// Why a mixture pressure equation: both phases are incompressible, so eps + phi = 1 turns the
// two continuity equations into div(eps u + phi v) = 0 plus the transport of phi; the gas volume
// follows from the mixture flux, so both phases are conserved exactly.
// Why the flux limiter: upwind transport keeps phi >= 0 only under a CFL condition and never
// keeps phi <= packing_limit by itself (only the solids pressure does, and it is explicit here);
// limiting the solids flux into a full cell, and letting the gas take the limited volume on the
// same face, bounds phi without breaking either conservation law.
#include "tfm/tfm.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <vector>

#include "draglab/error.h"
#include "gas/mac_operators.h"
#include "gas/mac_pressure.h"
#include "scene/scene_util.h"

namespace draglab {
namespace consumers {
namespace {

using scene_util::fmt;
using Array = Eigen::ArrayXXd;

[[noreturn]] void Bad(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

bool fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

/// Closure coefficients of every cell (below residual_solids: all zero).
struct CellClosures {
  Array pressure, pressure_derivative, kinetic_pressure_per_theta, mu, mu_kinetic, lambda, kappa,
      dissipation;
};

}  // namespace

const char* to_string(TfmStepLimit limit) {
  switch (limit) {
    case TfmStepLimit::kGasCfl:
      return "gas CFL";
    case TfmStepLimit::kSolidsCfl:
      return "solids CFL";
    case TfmStepLimit::kPressureWave:
      return "granular pressure wave";
    case TfmStepLimit::kSolidsViscosity:
      return "solids viscosity";
    case TfmStepLimit::kFixed:
      return "fixed";
    case TfmStepLimit::kLanding:
      return "landing on an output time";
    case TfmStepLimit::kMaximum:
      break;
  }
  return "dt_max";
}

bool TfmOptions::IsValid(std::string* error) const {
  if (!gas.IsValid(error)) return false;
  if (!(std::isfinite(particle_diameter_m) && particle_diameter_m > 0.0 &&
        particle_diameter_m < 0.1))
    return fail(error,
                "tfm particle_diameter_m = " + fmt(particle_diameter_m) + " is outside (0, 0.1) m");
  if (!(std::isfinite(particle_density_kg_m3) && particle_density_kg_m3 > gas.rho_g &&
        particle_density_kg_m3 <= 30000.0))
    return fail(error, "tfm particle_density_kg_m3 = " + fmt(particle_density_kg_m3) +
                           " must exceed the gas density " + fmt(gas.rho_g) +
                           " and be <= 30000 kg/m^3");
  if (!ktgf.IsValid(error)) return false;
  if (!(std::isfinite(initial_solids) && initial_solids >= 0.0 &&
        initial_solids < ktgf.packing_limit))
    return fail(error, "[tfm] initial solids fraction = " + fmt(initial_solids) +
                           " must be in [0, packing_limit = " + fmt(ktgf.packing_limit) +
                           "): the packing limit must exceed the bed's solids fraction");
  if (!(std::isfinite(initial_bed_height_m) && initial_bed_height_m >= 0.0 &&
        initial_bed_height_m <= gas.height_m))
    return fail(error, "tfm initial_bed_height_m = " + fmt(initial_bed_height_m) +
                           " is outside [0, height = " + fmt(gas.height_m) + "] m");
  if (!(std::isfinite(initial_theta_m2_s2) && initial_theta_m2_s2 >= 0.0 &&
        initial_theta_m2_s2 <= 100.0))
    return fail(error, "[tfm] theta_initial_m2_s2 = " + fmt(initial_theta_m2_s2) +
                           " is outside [0, 100] m^2/s^2 (a granular temperature is >= 0)");
  if (!(std::isfinite(residual_solids) && residual_solids > 0.0 && residual_solids <= 1e-2))
    return fail(error, "[tfm] residual_solids = " + fmt(residual_solids) + " is outside (0, 1e-2]");
  if (!(std::isfinite(cfl) && cfl > 0.0 && cfl <= 0.5))
    return fail(error, "[tfm] cfl = " + fmt(cfl) + " is outside (0, 0.5]");
  if (!(std::isfinite(dt_max_s) && dt_max_s > 0.0 && dt_max_s <= 0.1))
    return fail(error, "[tfm] dt_max_s = " + fmt(dt_max_s) + " is outside (0, 0.1] s");
  if (!(std::isfinite(dt_min_s) && dt_min_s > 0.0 && dt_min_s <= dt_max_s))
    return fail(error, "[tfm] dt_min_s = " + fmt(dt_min_s) +
                           " is outside (0, dt_max_s = " + fmt(dt_max_s) + "]");
  if (!(std::isfinite(fixed_dt_s) && fixed_dt_s >= 0.0 && fixed_dt_s <= dt_max_s))
    return fail(error,
                "[time] gas_dt_s = " + fmt(fixed_dt_s) +
                    " s (the two-fluid model's fixed step) is outside [0, [tfm] dt_max_s = " +
                    fmt(dt_max_s) + " s]");
  if (!(std::isfinite(algebraic_theta_min_solids) && algebraic_theta_min_solids >= 0.0 &&
        algebraic_theta_min_solids < ktgf.packing_limit))
    return fail(error, "tfm: algebraic_theta_min_solids = " + fmt(algebraic_theta_min_solids) +
                           " is outside [0, packing_limit = " + fmt(ktgf.packing_limit) + ")");
  if (!(initial_solids <= ktgf.packing_limit * (1.0 - 1e-2)))
    return fail(error, "[tfm] the bed's solids fraction " + fmt(initial_solids) +
                           " is within 1 % of packing_limit = " + fmt(ktgf.packing_limit) +
                           ": such a bed cannot move (raise packing_limit or eps_mf)");
  if (gas.vertical != VerticalBoundary::kInflowOutlet)
    return fail(error, "tfm: only the inflow/outlet vertical boundary is supported");
  return true;
}

std::string TfmDiagnostics::BriefReport() const {
  std::ostringstream s;
  s.precision(4);
  s << "TFM t = " << time_s << " s, " << steps << " steps (dt last " << last_dt_s << " s, min "
    << min_dt_s << " s, limit: " << to_string(last_limit) << "); solids mass change "
    << (initial_solids_mass_kg > 0.0
            ? (solids_mass_kg - initial_solids_mass_kg) / initial_solids_mass_kg
            : 0.0)
    << " (rel.), gas mass imbalance " << gas_mass_imbalance_kg << " kg of " << gas_mass_in_kg
    << " kg in; max phi " << max_solids_fraction << ", max theta " << max_theta_m2_s2
    << " m^2/s^2, flux-limited faces " << flux_limited_faces << ", max wave speed "
    << max_wave_speed_m_s << " m/s";
  return s.str();
}

namespace {

/// An LDLT of matrices that share one sparsity pattern: the ordering is analysed on the first
/// factorisation only.
struct CachedLdlt {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  bool ordered = false;
  /// False if the factorisation failed.
  bool Factorize(const Eigen::SparseMatrix<double>& a) {
    if (!ordered) {
      ldlt.analyzePattern(a);
      ordered = true;
    }
    ldlt.factorize(a);
    return ldlt.info() == Eigen::Success;
  }
};

}  // namespace

struct TfmSimulation::Impl {
  int nx = 0, nz = 0;
  double dx = 0.0, dz = 0.0, depth = 0.0;
  double time = 0.0;
  Array phi, theta, p, beta;
  Array ug, wg, us, ws;  // faces: x (nx+1) x nz, z nx x (nz+1)
  std::unique_ptr<MacPressureSolver> pressure;
  std::unique_ptr<KtgfClosures> ktgf;
  // Granular energy matrix: its pattern is fixed (every neighbour entered), analysed once.
  CachedLdlt energy_solver;
  // Implicit solids pressure increment (SolidsPressure::kImplicit): fixed pattern, analysed once.
  CachedLdlt pressure_increment_solver;
  TfmDiagnostics diag;

  CellClosures Closures(const TfmOptions& o) const;
  double StableStep(const CellClosures& c, TfmStepLimit* limit, const TfmOptions& o) const;

  // The stages of one step (TfmSimulation::StepCapped), in order; Step holds what they share.
  struct Step;
  void ChooseStep(Step& s, double dt_cap) const;
  void DragCoefficients(Step& s, const Law& law);
  void SolidsStress(Step& s) const;
  void PredictXFaces(Step& s) const;
  void PredictZFaces(Step& s) const;
  void SolvePressure(Step& s);
  void Project(const Step& s);
  void SolidsFluxes(Step& s) const;
  void ImplicitSolidsPressure(Step& s);
  void LimitSolidsFluxes(Step& s) const;
  void CorrectLimitedFaces(Step& s);
  Array TransportedTheta(const Step& s);
  Array EquilibriumTheta(const Step& s) const;
  void Record(const Step& s, const Array& theta_new);

  // Pieces of the face predictors.
  double SolidsUAt(int i, int j, bool noslip) const;
  double SolidsWAt(int i, int j, bool noslip) const;
  double ImplicitViscosity(Step& s, int i0, int i1, int j0, int j1, double a_s) const;
};

namespace {

/// A face after the partial elimination of the drag: the velocities without the new pressure
/// gradient and their response to it (u = u_hat - c_g dp/dn, v = v_hat - c_s dp/dn).
struct Face {
  double u_hat = 0.0, v_hat = 0.0, c_g = 0.0, c_s = 0.0, eps = 1.0, phi = 0.0;
  double phi_flux = 0.0;  // the donor cell's phi: the solids fraction the face transports
  // Solids velocity per unit solids force [m/s per N/m^3] with the mixture flux held:
  // a_s dv + beta (dv - du) = f with du = -(phi/eps) dv gives dv = f / (a_s + beta / eps).
  double solids_response = 0.0;
};

double Upwind(double speed, double centre, double behind, double ahead, double h) {
  return speed > 0.0 ? (centre - behind) / h : (ahead - centre) / h;
}

/// Partial elimination of the drag on one face (the 2 x 2 system of both momentum equations).
Face Eliminate(const TfmOptions& o, double eps_f, double phi_f, double beta_f, double rhs_g,
               double rhs_s, double a_g, double a_s) {
  Face f;
  f.eps = eps_f;
  f.phi = phi_f;
  if (o.freeze_solids) {
    f.u_hat = rhs_g / (a_g + beta_f);
    f.c_g = eps_f / (a_g + beta_f);
    return f;
  }
  const double det = a_g * a_s + beta_f * (a_g + a_s);
  f.u_hat = ((a_s + beta_f) * rhs_g + beta_f * rhs_s) / det;
  f.v_hat = (beta_f * rhs_g + (a_g + beta_f) * rhs_s) / det;
  f.c_g = ((a_s + beta_f) * eps_f + beta_f * phi_f) / det;
  f.c_s = (beta_f * eps_f + (a_g + beta_f) * phi_f) / det;
  return f;
}

/// The solids fraction a face carries. The volume fluxes carry the donor cell's fractions
/// (upwind by the predicted solids velocity), in the pressure equation as in the transport: at
/// the bed surface, particles that would fall out of an empty cell carry no volume, so the gas
/// is not asked to take their place. With the van Leer scheme the donor value is corrected
/// towards the acceptor by the harmonic mean of the two one-sided differences (zero at an
/// extremum), which keeps the face value between the donor's and the acceptor's (TVD); a
/// missing cell behind the donor (NaN: a wall) makes it upwind there.
double Donor(bool van_leer, double v, double behind_lower, double lower, double upper,
             double behind_upper, double central) {
  if (v == 0.0) return central;
  const double d = v > 0.0 ? lower : upper, a = v > 0.0 ? upper : lower;
  const double behind = v > 0.0 ? behind_lower : behind_upper;
  if (!van_leer || std::isnan(behind)) return d;
  const double back = d - behind, ahead = a - d;
  return back * ahead > 0.0 ? d + back * ahead / (back + ahead) : d;
}

/// Constraints on a face's solids (after the elimination, so the projection sees them):
///  - between two empty cells there are no solids: they move with the gas, so the neighbours
///    of a free surface see neither fictitious free-fall momentum nor slip;
///  - solids that would flow into a cell at the packing limit, or out of an empty cell (the
///    surface face of a bed at rest), are held (v = 0) as by a wall, the contact force of a
///    packed bed or the absence of anything to move; the gas alone answers the pressure.
///    Without the first, the projection would push solids volume into the full cell and the
///    flux limiter would hand it to the gas, a velocity spike that feeds back; without the
///    second, the surface face would carry the virtual particles' momentum into the bed.
/// The direction of a face's solids: the prediction with the previous step's pressure gradient
/// (v_hat alone lacks the whole pressure gradient, so in a dense bed it points down with
/// gravity even where the gas lifts the solids).
void Constrain(const TfmOptions& o, Face& f, double lower, double upper, double a_g, double beta_f,
               double rhs_g, double old_gradient) {
  if (o.freeze_solids) return;
  if (std::max(lower, upper) < o.residual_solids) {
    f.v_hat = f.u_hat;
    f.c_s = f.c_g;
    return;
  }
  const double packed = o.ktgf.packing_limit * (1.0 - 1e-3);
  const double v = f.v_hat - f.c_s * old_gradient;
  const double donor_phi = v > 0.0 ? lower : upper;
  const double acceptor_phi = v > 0.0 ? upper : lower;
  if (acceptor_phi < packed && donor_phi >= o.residual_solids) return;
  f.v_hat = 0.0;
  f.c_s = 0.0;
  f.u_hat = rhs_g / (a_g + beta_f);
  f.c_g = f.eps / (a_g + beta_f);
}

}  // namespace

struct TfmSimulation::Impl::Step {
  explicit Step(const TfmOptions& options, int nx, int nz, double time)
      : o(options),
        at("TFM stopped at t = " + fmt(time) + " s: "),
        fx(static_cast<std::size_t>((nx + 1) * nz)),
        fz(static_cast<std::size_t>(nx * (nz + 1))),
        nx_(nx) {}
  const TfmOptions& o;
  const std::string at;  ///< Prefix of every diagnosis.
  // ChooseStep
  CellClosures c;
  double dt = 0.0;
  TfmStepLimit why = TfmStepLimit::kMaximum;
  bool landing = false;
  // DragCoefficients: the gas fraction and beta / eps
  Array eps, resistance;
  // SolidsStress: normal stresses at cell centres, shear at corners
  Array sxx, szz, sxz;
  // PredictXFaces, PredictZFaces
  std::vector<Face> fx, fz;
  long implicit_faces = 0;
  // SolvePressure: the inflow of the new time
  double t_new = 0.0;
  std::vector<double> w_in;
  // SolidsFluxes, ImplicitSolidsPressure, LimitSolidsFluxes
  Array fs_x, fs_z, mix_x, mix_z, limited_x, limited_z;
  Array phi_new;
  double phi_new_max = 0.0;
  long positivity_limited = 0, packing_limited = 0, limited = 0;

  Face& fx_at(int i, int j) { return fx[static_cast<std::size_t>(i + (nx_ + 1) * j)]; }
  const Face& fx_at(int i, int j) const { return fx[static_cast<std::size_t>(i + (nx_ + 1) * j)]; }
  Face& fz_at(int i, int j) { return fz[static_cast<std::size_t>(i + nx_ * j)]; }
  const Face& fz_at(int i, int j) const { return fz[static_cast<std::size_t>(i + nx_ * j)]; }

 private:
  int nx_;
};

TfmSimulation::TfmSimulation(const TfmOptions& options, std::shared_ptr<const Law> law)
    : opt_(options), law_(std::move(law)), impl_(std::make_unique<Impl>()) {
  std::string why;
  if (!opt_.IsValid(&why)) Bad(why);
  if (!law_) Bad("TfmSimulation: law is null (load it with Database::load)");
  Impl& m = *impl_;
  m.nx = opt_.gas.nx;
  m.nz = opt_.gas.nz;
  m.dx = opt_.gas.width_m / m.nx;
  m.dz = opt_.gas.height_m / m.nz;
  m.depth = opt_.gas.depth_m;
  // 0 in the options means "the cell size" here (ktgf.h's 0 = off is for direct use).
  if (opt_.ktgf.knudsen_length_m == 0.0) opt_.ktgf.knudsen_length_m = std::min(m.dx, m.dz);
  m.ktgf = std::make_unique<KtgfClosures>(opt_.ktgf, opt_.particle_diameter_m,
                                          opt_.particle_density_kg_m3);
  MacPressureOptions po;
  po.nx = m.nx;
  po.nz = m.nz;
  po.dx = m.dx;
  po.dz = m.dz;
  po.vertical = opt_.gas.vertical;
  po.solver = opt_.gas.poisson;
  po.cg_tolerance = opt_.gas.cg_tolerance;
  po.cg_max_iterations = opt_.gas.cg_max_iterations;
  m.pressure = std::make_unique<MacPressureSolver>(po);
  m.phi = Array::Zero(m.nx, m.nz);
  m.theta = Array::Zero(m.nx, m.nz);
  for (int j = 0; j < m.nz; ++j) {
    // The cell's covered fraction of the initial bed, so the bed height is exact on any grid.
    const double covered = std::clamp(opt_.initial_bed_height_m / m.dz - j, 0.0, 1.0);
    for (int i = 0; i < m.nx; ++i) {
      m.phi(i, j) = opt_.initial_solids * covered;
      m.theta(i, j) = m.phi(i, j) >= opt_.residual_solids ? opt_.initial_theta_m2_s2 : 0.0;
    }
  }
  m.p = Array::Constant(m.nx, m.nz, opt_.gas.outlet_pressure_pa);
  m.beta = Array::Zero(m.nx, m.nz);
  m.ug = m.us = Array::Zero(m.nx + 1, m.nz);
  m.wg = m.ws = Array::Zero(m.nx, m.nz + 1);
  m.diag.initial_solids_mass_kg = m.diag.solids_mass_kg =
      m.phi.sum() * m.dx * m.dz * m.depth * opt_.particle_density_kg_m3;
  m.diag.max_solids_fraction = m.phi.maxCoeff();
}

TfmSimulation::~TfmSimulation() = default;

void TfmSimulation::SetState(const Array& solids_fraction, const Array& theta) {
  Impl& m = *impl_;
  if (solids_fraction.rows() != m.nx || solids_fraction.cols() != m.nz || theta.rows() != m.nx ||
      theta.cols() != m.nz)
    Bad("TfmSimulation::SetState: fields must be nx x nz = " + std::to_string(m.nx) + " x " +
        std::to_string(m.nz));
  for (int j = 0; j < m.nz; ++j)
    for (int i = 0; i < m.nx; ++i) {
      const double f = solids_fraction(i, j), t = theta(i, j);
      if (!(std::isfinite(f) && f >= 0.0 && f <= opt_.ktgf.packing_limit))
        Bad("TfmSimulation::SetState: phi(" + std::to_string(i) + ", " + std::to_string(j) +
            ") = " + fmt(f) + " is outside [0, packing_limit = " + fmt(opt_.ktgf.packing_limit) +
            "]");
      if (!(std::isfinite(t) && t >= 0.0))
        Bad("TfmSimulation::SetState: theta(" + std::to_string(i) + ", " + std::to_string(j) +
            ") = " + fmt(t) + " must be >= 0 (a granular temperature)");
    }
  m.phi = solids_fraction;
  m.theta = theta;
  m.diag.initial_solids_mass_kg = m.diag.solids_mass_kg =
      m.phi.sum() * m.dx * m.dz * m.depth * opt_.particle_density_kg_m3;
  m.diag.max_solids_fraction = m.phi.maxCoeff();
}

void TfmSimulation::SetUniformVelocity(double gas_x, double gas_z, double solids_x,
                                       double solids_z) {
  Impl& m = *impl_;
  if (!std::isfinite(gas_x) || !std::isfinite(gas_z) || !std::isfinite(solids_x) ||
      !std::isfinite(solids_z))
    Bad("TfmSimulation::SetUniformVelocity: velocities must be finite");
  m.ug.setConstant(gas_x);
  m.us.setConstant(solids_x);
  m.wg.setConstant(gas_z);
  m.ws.setConstant(solids_z);
  for (Array* a : {&m.ug, &m.us}) {
    a->row(0).setZero();
    a->row(m.nx).setZero();
  }
  m.ws.col(0).setZero();
  m.ws.col(m.nz).setZero();
}

double TfmSimulation::time() const { return impl_->time; }
double TfmSimulation::dx() const { return impl_->dx; }
double TfmSimulation::dz() const { return impl_->dz; }
const Array& TfmSimulation::solids_fraction() const { return impl_->phi; }
Array TfmSimulation::gas_fraction() const { return 1.0 - impl_->phi; }
const Array& TfmSimulation::theta() const { return impl_->theta; }
const Array& TfmSimulation::pressure() const { return impl_->p; }
const Array& TfmSimulation::gas_u() const { return impl_->ug; }
const Array& TfmSimulation::gas_w() const { return impl_->wg; }
const Array& TfmSimulation::solids_u() const { return impl_->us; }
const Array& TfmSimulation::solids_w() const { return impl_->ws; }
const Array& TfmSimulation::beta() const { return impl_->beta; }
const TfmDiagnostics& TfmSimulation::diagnostics() const { return impl_->diag; }

double TfmSimulation::PressureDrop(double z_low, double z_high) const {
  const Impl& m = *impl_;
  return width_averaged_pressure(m.p, m.dz, z_low, true, opt_.gas.outlet_pressure_pa) -
         width_averaged_pressure(m.p, m.dz, z_high, true, opt_.gas.outlet_pressure_pa);
}

namespace {

/// Strain of the solids velocity at cell (i, j): normal rates, the cell-averaged shear rate
/// S_xz = (du/dz + dw/dx)/2 from the corners, divergence, the deviatoric D':D' and
/// sqrt(I_2D). On a free-slip wall the corner shear is zero; on a no-slip wall the tangential
/// velocity vanishes half a cell from the adjacent face centre (ghost = -inner value).
struct Strain {
  double div = 0.0, dev2 = 0.0, shear_rate = 0.0;
};

double CornerShear(const Array& us, const Array& ws, int i, int j, double dx, double dz,
                   WallSlip walls) {
  const int nx = static_cast<int>(ws.rows()), nz = static_cast<int>(us.cols());
  const bool side = i <= 0 || i >= nx, floor_or_top = j <= 0 || j >= nz;
  if (side && floor_or_top) return 0.0;  // a domain corner: both velocities vanish
  if (side || floor_or_top) {
    if (walls == WallSlip::kFreeSlip) return 0.0;
    if (i <= 0) return ws(0, j) / dx;  // 0.5 * (w - (-w)) / dx
    if (i >= nx) return -ws(nx - 1, j) / dx;
    if (j <= 0) return us(i, 0) / dz;
    return -us(i, nz - 1) / dz;
  }
  return 0.5 * ((us(i, j) - us(i, j - 1)) / dz + (ws(i, j) - ws(i - 1, j)) / dx);
}

Strain StrainAt(const Array& us, const Array& ws, int i, int j, double dx, double dz,
                WallSlip walls) {
  Strain s;
  const double uxx = (us(i + 1, j) - us(i, j)) / dx;
  const double wzz = (ws(i, j + 1) - ws(i, j)) / dz;
  const double sxz = 0.25 * (CornerShear(us, ws, i, j, dx, dz, walls) +
                             CornerShear(us, ws, i + 1, j, dx, dz, walls) +
                             CornerShear(us, ws, i, j + 1, dx, dz, walls) +
                             CornerShear(us, ws, i + 1, j + 1, dx, dz, walls));
  s.div = uxx + wzz;
  const double third = s.div / 3.0;
  // 3-D deviator of a plane strain (D_yy = 0).
  s.dev2 = (uxx - third) * (uxx - third) + (wzz - third) * (wzz - third) + third * third +
           2.0 * sxz * sxz;
  s.shear_rate = std::sqrt(0.5 * s.dev2);
  return s;
}

}  // namespace

CellClosures TfmSimulation::Impl::Closures(const TfmOptions& o) const {
  CellClosures c;
  for (Array* a : {&c.pressure, &c.pressure_derivative, &c.kinetic_pressure_per_theta, &c.mu,
                   &c.mu_kinetic, &c.lambda, &c.kappa, &c.dissipation})
    *a = Array::Zero(nx, nz);
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      if (phi(i, j) < o.residual_solids) continue;  // no solids stress in empty cells
      const Strain st = StrainAt(us, ws, i, j, dx, dz, o.solids_walls);
      const KtgfCoefficients k = ktgf->Evaluate(phi(i, j), theta(i, j), st.div, st.shear_rate);
      c.pressure(i, j) = k.pressure_pa;
      c.pressure_derivative(i, j) = k.pressure_derivative_pa;
      c.kinetic_pressure_per_theta(i, j) = k.kinetic_pressure_per_theta;
      c.mu(i, j) = k.shear_viscosity_pa_s;
      c.mu_kinetic(i, j) = k.shear_viscosity_pa_s - k.frictional_viscosity_pa_s;
      c.lambda(i, j) = k.bulk_viscosity_pa_s;
      c.kappa(i, j) = k.conductivity;
      c.dissipation(i, j) = k.dissipation_rate_coefficient;
    }
  return c;
}

double TfmSimulation::StableTimeStep(TfmStepLimit* limit) const {
  return impl_->StableStep(impl_->Closures(opt_), limit, opt_);
}

double TfmSimulation::Impl::StableStep(const CellClosures& c, TfmStepLimit* limit,
                                       const TfmOptions& o) const {
  const double rho_s = o.particle_density_kg_m3;
  const double inv_h2 = 1.0 / (dx * dx) + 1.0 / (dz * dz);
  const double h = std::min(dx, dz);
  double gas_rate = 0.0, solids_rate = 0.0, wave = 0.0, nu = 0.0;
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      gas_rate = std::max(gas_rate, 0.5 * (std::abs(ug(i, j)) + std::abs(ug(i + 1, j))) / dx +
                                        0.5 * (std::abs(wg(i, j)) + std::abs(wg(i, j + 1))) / dz);
      if (phi(i, j) <= 0.0) continue;
      // Outflow of a cell over a step must not exceed its content (positivity): sum of the
      // face speeds, not their mean.
      solids_rate = std::max(solids_rate, (std::abs(us(i, j)) + std::abs(us(i + 1, j))) / dx +
                                              (std::abs(ws(i, j)) + std::abs(ws(i, j + 1))) / dz);
      if (phi(i, j) < o.residual_solids) continue;
      wave = std::max(wave, std::sqrt(std::max(c.pressure_derivative(i, j), 0.0) / rho_s));
      nu = std::max(nu, (2.0 * c.mu(i, j) + c.lambda(i, j)) / (phi(i, j) * rho_s));
    }
  const double gas_viscous = o.gas.rho_g / (2.0 * o.gas.mu_g * inv_h2);
  struct Candidate {
    double dt;
    TfmStepLimit why;
  };
  const double inf = std::numeric_limits<double>::infinity();
  const Candidate candidates[] = {
      {std::min(gas_rate > 0.0 ? o.cfl / gas_rate : inf, gas_viscous), TfmStepLimit::kGasCfl},
      {solids_rate > 0.0 ? o.cfl / solids_rate : inf, TfmStepLimit::kSolidsCfl},
      {wave > 0.0 && o.solids_pressure == SolidsPressure::kExplicit ? o.cfl * h / wave : inf,
       TfmStepLimit::kPressureWave},
      {nu > 0.0 && o.solids_viscosity == SolidsViscosity::kExplicit ? 0.25 / (nu * inv_h2) : inf,
       TfmStepLimit::kSolidsViscosity},
      {o.dt_max_s, TfmStepLimit::kMaximum}};
  Candidate best = candidates[4];
  for (const Candidate& k : candidates)
    if (k.dt < best.dt) best = k;
  if (limit) *limit = best.why;
  return best.dt;
}

double TfmSimulation::Step() { return StepCapped(std::numeric_limits<double>::infinity()); }

void TfmSimulation::AdvanceTo(double t_end) {
  if (!std::isfinite(t_end)) Bad("TfmSimulation::AdvanceTo: t_end must be finite");
  while (impl_->time < t_end - 1e-12 * std::max(1.0, t_end)) StepCapped(t_end - impl_->time);
}

double TfmSimulation::StepCapped(double dt_cap) {
  TfmStepStages stages(*this, dt_cap);
  stages.ChooseStep();
  stages.DragCoefficients();
  stages.SolidsStress();
  stages.PredictFaces();
  stages.SolvePressure();
  stages.Project();
  stages.SolidsFluxes();
  stages.ImplicitSolidsPressure();
  stages.LimitSolidsFluxes();
  stages.CorrectLimitedFaces();
  stages.UpdateGranularTemperature();
  stages.Record();
  return stages.dt();
}

struct TfmStepStages::State {
  State(const TfmOptions& o, const TfmSimulation::Impl& m) : step(o, m.nx, m.nz, m.time) {}
  TfmSimulation::Impl::Step step;
  Array theta_new;
};

TfmStepStages::TfmStepStages(TfmSimulation& simulation, double dt_cap)
    : sim_(simulation),
      dt_cap_(dt_cap),
      state_(std::make_unique<State>(simulation.opt_, *simulation.impl_)) {}
TfmStepStages::~TfmStepStages() = default;

double TfmStepStages::ChooseStep() {
  sim_.impl_->ChooseStep(state_->step, dt_cap_);
  return state_->step.dt;
}
void TfmStepStages::DragCoefficients() { sim_.impl_->DragCoefficients(state_->step, *sim_.law_); }
void TfmStepStages::SolidsStress() { sim_.impl_->SolidsStress(state_->step); }
void TfmStepStages::PredictFaces() {
  sim_.impl_->PredictXFaces(state_->step);
  sim_.impl_->PredictZFaces(state_->step);
}
void TfmStepStages::SolvePressure() { sim_.impl_->SolvePressure(state_->step); }
void TfmStepStages::Project() { sim_.impl_->Project(state_->step); }
void TfmStepStages::SolidsFluxes() { sim_.impl_->SolidsFluxes(state_->step); }
void TfmStepStages::ImplicitSolidsPressure() {
  if (sim_.opt_.solids_pressure == SolidsPressure::kImplicit)
    sim_.impl_->ImplicitSolidsPressure(state_->step);
}
void TfmStepStages::LimitSolidsFluxes() { sim_.impl_->LimitSolidsFluxes(state_->step); }
void TfmStepStages::CorrectLimitedFaces() { sim_.impl_->CorrectLimitedFaces(state_->step); }
void TfmStepStages::UpdateGranularTemperature() {
  state_->theta_new = sim_.opt_.granular_temperature == GranularTemperature::kAlgebraic
                          ? sim_.impl_->EquilibriumTheta(state_->step)
                          : sim_.impl_->TransportedTheta(state_->step);
}
void TfmStepStages::Record() { sim_.impl_->Record(state_->step, state_->theta_new); }
double TfmStepStages::dt() const { return state_->step.dt; }
const Array& TfmStepStages::mixture_flux_x() const { return state_->step.mix_x; }
const Array& TfmStepStages::mixture_flux_z() const { return state_->step.mix_z; }
const Array& TfmStepStages::new_solids_fraction() const { return state_->step.phi_new; }

/// The closures and the time step: the stable step (or the fixed one, checked against it),
/// capped to land on an output time.
void TfmSimulation::Impl::ChooseStep(Step& s, double dt_cap) const {
  const TfmOptions& o = s.o;
  const std::string& at = s.at;
  s.c = Closures(o);
  TfmStepLimit why = TfmStepLimit::kMaximum;
  const double stable = StableStep(s.c, &why, o);
  double dt = 0.0;
  if (o.fixed_dt_s > 0.0) {
    if (o.fixed_dt_s > stable * (1.0 + 1e-9))
      Bad(at + "the fixed time step " + fmt(o.fixed_dt_s) + " s is above the stability limit " +
          fmt(stable) + " s set by the " + to_string(why) +
          "; remedy: lower the step or use 0 (adaptive)");
    dt = std::min(o.fixed_dt_s, dt_cap);
    why = TfmStepLimit::kFixed;
  } else {
    if (stable < o.dt_min_s)
      Bad(at + "the " + std::string(to_string(why)) + " limits the step to " + fmt(stable) +
          " s, below dt_min_s = " + fmt(o.dt_min_s) +
          " s (max gas-phase or solids speed, granular pressure wave speed or solids "
          "viscosity has run away); remedy: a coarser grid, a slower jet, or friction with a "
          "larger friction_delta");
    dt = std::min(stable, dt_cap);
  }
  if (!(dt > 0.0)) Bad(at + "time step " + fmt(dt) + " s must be > 0");
  // A step shortened to land on an output time says nothing about stability.
  s.landing = dt < (o.fixed_dt_s > 0.0 ? o.fixed_dt_s : stable);
  if (s.landing) why = TfmStepLimit::kLanding;
  s.dt = dt;
  s.why = why;
}

/// The drag coefficient of every cell from the law at the cell-centred slip.
void TfmSimulation::Impl::DragCoefficients(Step& s, const Law& law) {
  const TfmOptions& o = s.o;
  s.eps = 1.0 - phi;
  Array dga = Array::Zero(nx, nz);
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      if (!o.interphase_drag) continue;
      const double sx = 0.5 * (ug(i, j) + ug(i + 1, j) - us(i, j) - us(i + 1, j));
      const double sz = 0.5 * (wg(i, j) + wg(i, j + 1) - ws(i, j) - ws(i, j + 1));
      try {
        dga(i, j) = law.dga(s.eps(i, j), o.gas.mu_g, o.gas.rho_g, std::hypot(sx, sz),
                            o.particle_diameter_m);
      } catch (const Error& e) {
        throw Error(e.code(), s.at + "drag law in cell (" + std::to_string(i) + ", " +
                                  std::to_string(j) + ") at eps = " + fmt(s.eps(i, j)) + ": " +
                                  e.what());
      }
    }
  // Cells below residual_solids carry virtual particles of that fraction, so their solids
  // velocity stays a settling velocity instead of free fall; their drag on the gas is
  // negligible (residual_solids / phi of a real cell).
  beta = dga * phi.max(o.residual_solids);
  // A face's drag coefficient averages beta / eps, the resistance to the SUPERFICIAL velocity
  // (continuous across a face where eps jumps, as at the bed surface), times the face's eps:
  // a face half in the bed then gets the drag of its bed half, not half the bed's beta at the
  // mean of two very different interstitial velocities.
  s.resistance = beta / s.eps;
}

/// The solids stress sigma = -P I + tau: normal components at cell centres, shear at corners.
void TfmSimulation::Impl::SolidsStress(Step& s) const {
  const CellClosures& c = s.c;
  s.sxx = Array::Zero(nx, nz);
  s.szz = Array::Zero(nx, nz);
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      if (phi(i, j) < s.o.residual_solids) continue;
      const double uxx = (us(i + 1, j) - us(i, j)) / dx;
      const double wzz = (ws(i, j + 1) - ws(i, j)) / dz;
      const double bulk = (c.lambda(i, j) - 2.0 / 3.0 * c.mu(i, j)) * (uxx + wzz);
      s.sxx(i, j) = -c.pressure(i, j) + 2.0 * c.mu(i, j) * uxx + bulk;
      s.szz(i, j) = -c.pressure(i, j) + 2.0 * c.mu(i, j) * wzz + bulk;
    }
  // Corners: the viscosity averages the cells around the corner (two on a wall).
  s.sxz = Array::Zero(nx + 1, nz + 1);
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i <= nx; ++i) {
      const double shear = CornerShear(us, ws, i, j, dx, dz, s.o.solids_walls);
      if (shear == 0.0) continue;
      double mu_sum = 0.0;
      int cells = 0;
      for (int b = j - 1; b <= j; ++b)
        for (int a = i - 1; a <= i; ++a)
          if (a >= 0 && a < nx && b >= 0 && b < nz) {
            mu_sum += c.mu(a, b);
            ++cells;
          }
      s.sxz(i, j) = 2.0 * mu_sum / cells * shear;
    }
}

/// The solids' tangential velocities with their ghost values beyond the walls.
double TfmSimulation::Impl::SolidsUAt(int i, int j, bool noslip) const {
  if (j < 0) return noslip ? -us(i, 0) : us(i, 0);
  if (j >= nz) return noslip ? -us(i, nz - 1) : us(i, nz - 1);
  return us(i, j);
}

double TfmSimulation::Impl::SolidsWAt(int i, int j, bool noslip) const {
  if (i < 0) return noslip ? -ws(0, j) : ws(0, j);
  if (i >= nx) return noslip ? -ws(nx - 1, j) : ws(nx - 1, j);
  return ws(i, j);
}

/// Point-implicit solids viscosity (SolidsViscosity): a face's self-coefficient in the explicit
/// viscous term is at most 4 M (1/dx^2 + 1/dz^2), M the largest 2 mu + lambda of the cells its
/// stencil touches. Where a_s is below that bound, (a_s + D) v_new = (a_s + D) v + S(v) with
/// D = bound - a_s keeps the most oscillatory mode's amplification >= -1 (stable at any step);
/// elsewhere D = 0 and the term is the explicit one. Returns D.
double TfmSimulation::Impl::ImplicitViscosity(Step& s, int i0, int i1, int j0, int j1,
                                              double a_s) const {
  if (s.o.solids_viscosity != SolidsViscosity::kPointImplicit) return 0.0;
  const double inv_h2 = 1.0 / (dx * dx) + 1.0 / (dz * dz);
  double largest = 0.0;
  for (int b = std::max(j0, 0); b <= std::min(j1, nz - 1); ++b)
    for (int a = std::max(i0, 0); a <= std::min(i1, nx - 1); ++a)
      largest = std::max(largest, 2.0 * s.c.mu(a, b) + s.c.lambda(a, b));
  const double d = std::max(0.0, 4.0 * largest * inv_h2 - a_s);
  if (d > 0.0) ++s.implicit_faces;
  return d;
}

/// Momentum predictors on the x-faces, the drag eliminated.
void TfmSimulation::Impl::PredictXFaces(Step& s) const {
  const TfmOptions& o = s.o;
  const double rho_g = o.gas.rho_g, rho_s = o.particle_density_kg_m3;
  const bool van_leer = o.fraction_scheme == FractionScheme::kVanLeer;
  const bool solids_noslip = o.solids_walls == WallSlip::kNoSlip;
  const double none = std::numeric_limits<double>::quiet_NaN();
  const Array& eps = s.eps;
  const internal::MacGasOperators gas_ops(ug, wg, eps, dx, dz, o.gas.mu_g,
                                          o.gas.side_walls == WallSlip::kNoSlip,
                                          /*periodic=*/false);
  for (int j = 0; j < nz; ++j)
    for (int i = 1; i < nx; ++i) {
      const double ef = 0.5 * (eps(i - 1, j) + eps(i, j));
      const double pf = 1.0 - ef;
      const double pm = std::max(pf, o.residual_solids);
      const double bf = ef * 0.5 * (s.resistance(i - 1, j) + s.resistance(i, j));
      // Gas: advective upwind, div(eps mu grad u) (the shared MAC operators).
      const double uc = ug(i, j);
      const internal::FaceMomentumTerms gas = gas_ops.XFace(i, j);
      const double a_g = ef * rho_g / s.dt;
      const double rhs_g =
          a_g * uc - ef * rho_g * gas.advection + gas.viscous + ef * o.gas.body_force_x;
      // Solids: advective upwind, the stress divergence.
      const double vc = us(i, j);
      const double wsc = 0.25 * (ws(i - 1, j) + ws(i, j) + ws(i - 1, j + 1) + ws(i, j + 1));
      const double adv_s = vc * Upwind(vc, vc, us(i - 1, j), us(i + 1, j), dx) +
                           wsc * Upwind(wsc, vc, SolidsUAt(i, j - 1, solids_noslip),
                                        SolidsUAt(i, j + 1, solids_noslip), dz);
      const double stress =
          (s.sxx(i, j) - s.sxx(i - 1, j)) / dx + (s.sxz(i, j + 1) - s.sxz(i, j)) / dz;
      const double a_s0 = pm * rho_s / s.dt;
      const double a_s = a_s0 + ImplicitViscosity(s, i - 1, i, j - 1, j + 1, a_s0);
      const double rhs_s = a_s * vc - pm * rho_s * adv_s + stress;
      Face& f = s.fx_at(i, j);
      f = Eliminate(o, ef, pf, bf, rhs_g, rhs_s, a_g, a_s);
      const double old_gradient = (p(i, j) - p(i - 1, j)) / dx;
      f.phi_flux = Donor(van_leer, f.v_hat - f.c_s * old_gradient, i >= 2 ? phi(i - 2, j) : none,
                         phi(i - 1, j), phi(i, j), i + 1 < nx ? phi(i + 1, j) : none, pf);
      Constrain(o, f, phi(i - 1, j), phi(i, j), a_g, bf, rhs_g, old_gradient);
      f.solids_response = f.c_s != 0.0 ? 1.0 / (a_s + bf / ef) : 0.0;
    }
}

/// Momentum predictors on the z-faces (interior and the outlet), the drag eliminated.
void TfmSimulation::Impl::PredictZFaces(Step& s) const {
  const TfmOptions& o = s.o;
  const double rho_g = o.gas.rho_g, rho_s = o.particle_density_kg_m3, g_z = o.gas.gravity_z;
  const bool van_leer = o.fraction_scheme == FractionScheme::kVanLeer;
  const bool solids_noslip = o.solids_walls == WallSlip::kNoSlip;
  const double none = std::numeric_limits<double>::quiet_NaN();
  const Array& eps = s.eps;
  const internal::MacGasOperators gas_ops(ug, wg, eps, dx, dz, o.gas.mu_g,
                                          o.gas.side_walls == WallSlip::kNoSlip,
                                          /*periodic=*/false);
  for (int j = 1; j <= nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const bool top = j == nz;
      const double ef = top ? eps(i, nz - 1) : 0.5 * (eps(i, j - 1) + eps(i, j));
      const double pf = top ? 0.0 : 1.0 - ef;
      const double pm = std::max(pf, o.residual_solids);
      const double bf =
          top ? beta(i, nz - 1) : ef * 0.5 * (s.resistance(i, j - 1) + s.resistance(i, j));
      const double wc = wg(i, j);
      const internal::FaceMomentumTerms gas = gas_ops.ZFace(i, j);
      const double a_g = ef * rho_g / s.dt;
      const double rhs_g = a_g * wc - ef * rho_g * gas.advection + gas.viscous + ef * rho_g * g_z +
                           ef * o.gas.body_force_z;
      if (top) {  // the outlet: gas only (the solids see a wall)
        Face f;
        f.eps = ef;
        f.phi_flux = 1.0 - ef;  // the mixture flux is the gas's alone: eps u
        f.u_hat = rhs_g / (a_g + bf);
        f.c_g = ef / (a_g + bf);
        s.fz_at(i, j) = f;
        continue;
      }
      const double vc = ws(i, j);
      const double usc = 0.25 * (us(i, j - 1) + us(i + 1, j - 1) + us(i, j) + us(i + 1, j));
      const double adv_s = vc * Upwind(vc, vc, ws(i, j - 1), ws(i, j + 1), dz) +
                           usc * Upwind(usc, vc, SolidsWAt(i - 1, j, solids_noslip),
                                        SolidsWAt(i + 1, j, solids_noslip), dx);
      const double stress =
          (s.szz(i, j) - s.szz(i, j - 1)) / dz + (s.sxz(i + 1, j) - s.sxz(i, j)) / dx;
      const double a_s0 = pm * rho_s / s.dt;
      const double a_s = a_s0 + ImplicitViscosity(s, i - 1, i + 1, j - 1, j, a_s0);
      const double rhs_s = a_s * vc - pm * rho_s * adv_s + stress + pm * rho_s * g_z;
      Face& f = s.fz_at(i, j);
      f = Eliminate(o, ef, pf, bf, rhs_g, rhs_s, a_g, a_s);
      const double old_gradient = (p(i, j) - p(i, j - 1)) / dz;
      f.phi_flux = Donor(van_leer, f.v_hat - f.c_s * old_gradient, j >= 2 ? phi(i, j - 2) : none,
                         phi(i, j - 1), phi(i, j), j + 1 < nz ? phi(i, j + 1) : none, pf);
      Constrain(o, f, phi(i, j - 1), phi(i, j), a_g, bf, rhs_g, old_gradient);
      f.solids_response = f.c_s != 0.0 ? 1.0 / (a_s + bf / ef) : 0.0;
    }
}

/// The mixture pressure equation div(eps u + phi v) = 0 with the predicted faces.
void TfmSimulation::Impl::SolvePressure(Step& s) {
  const TfmOptions& o = s.o;
  s.t_new = time + s.dt;
  s.w_in.assign(static_cast<std::size_t>(nx), 0.0);
  for (int i = 0; i < nx; ++i)
    s.w_in[static_cast<std::size_t>(i)] = inflow_superficial_velocity(o.gas, dx, i, s.t_new);
  Array c_u = Array::Zero(nx + 1, nz), c_w = Array::Zero(nx, nz + 1);
  Array flux_x = Array::Zero(nx + 1, nz), flux_z = Array::Zero(nx, nz + 1);  // predicted, m^2/s
  for (int j = 0; j < nz; ++j)
    for (int i = 1; i < nx; ++i) {
      const Face& f = s.fx_at(i, j);
      c_u(i, j) = (1.0 - f.phi_flux) * f.c_g + f.phi_flux * f.c_s;
      flux_x(i, j) = ((1.0 - f.phi_flux) * f.u_hat + f.phi_flux * f.v_hat) * dz;
    }
  for (int j = 1; j <= nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const Face& f = s.fz_at(i, j);
      c_w(i, j) = (1.0 - f.phi_flux) * f.c_g + f.phi_flux * f.c_s;
      flux_z(i, j) = ((1.0 - f.phi_flux) * f.u_hat + f.phi_flux * f.v_hat) * dx;
    }
  for (int i = 0; i < nx; ++i) flux_z(i, 0) = s.w_in[static_cast<std::size_t>(i)] * dx;
  Array continuity(nx, nz);
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i)
      continuity(i, j) = flux_x(i + 1, j) - flux_x(i, j) + flux_z(i, j + 1) - flux_z(i, j);
  try {
    p = pressure->Solve(c_u, c_w, continuity, o.gas.outlet_pressure_pa, p);
  } catch (const Error& e) {
    throw Error(e.code(), s.at + e.what());
  }
}

/// Both phases' face velocities from the new pressure gradient.
void TfmSimulation::Impl::Project(const Step& s) {
  const TfmOptions& o = s.o;
  for (int j = 0; j < nz; ++j)
    for (int i = 1; i < nx; ++i) {
      const Face& f = s.fx_at(i, j);
      const double grad = (p(i, j) - p(i - 1, j)) / dx;
      ug(i, j) = f.u_hat - f.c_g * grad;
      us(i, j) = f.v_hat - f.c_s * grad;
    }
  for (int j = 1; j <= nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const Face& f = s.fz_at(i, j);
      const double grad = j == nz ? (o.gas.outlet_pressure_pa - p(i, nz - 1)) / (0.5 * dz)
                                  : (p(i, j) - p(i, j - 1)) / dz;
      wg(i, j) = f.u_hat - f.c_g * grad;
      ws(i, j) = f.v_hat - f.c_s * grad;
    }
  for (int i = 0; i < nx; ++i) {
    wg(i, 0) = s.w_in[static_cast<std::size_t>(i)] / s.eps(i, 0);
    ws(i, 0) = 0.0;
    ws(i, nz) = 0.0;
  }
  if (!ug.allFinite() || !wg.allFinite() || !us.allFinite() || !ws.allFinite() || !p.allFinite())
    Bad(s.at + "non-finite velocity or pressure after a step of " + fmt(s.dt) +
        " s (limit: " + to_string(s.why) + "); remedy: lower cfl or dt_max_s");
}

/// The solids fluxes (the faces' phi) and the mixture fluxes.
void TfmSimulation::Impl::SolidsFluxes(Step& s) const {
  s.fs_x = Array::Zero(nx + 1, nz);
  s.fs_z = Array::Zero(nx, nz + 1);
  s.mix_x = Array::Zero(nx + 1, nz);
  s.mix_z = Array::Zero(nx, nz + 1);
  for (int j = 0; j < nz; ++j)
    for (int i = 1; i < nx; ++i) {
      const double v = us(i, j), pf = s.fx_at(i, j).phi_flux;
      s.fs_x(i, j) = v * pf * dz;
      s.mix_x(i, j) = ((1.0 - pf) * ug(i, j) + pf * v) * dz;
    }
  for (int j = 1; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const double v = ws(i, j), pf = s.fz_at(i, j).phi_flux;
      s.fs_z(i, j) = v * pf * dx;
      s.mix_z(i, j) = ((1.0 - pf) * wg(i, j) + pf * v) * dx;
    }
  for (int i = 0; i < nx; ++i) {
    s.mix_z(i, 0) = s.w_in[static_cast<std::size_t>(i)] * dx;
    s.mix_z(i, nz) = s.eps(i, nz - 1) * wg(i, nz) * dx;
  }
}

/// Implicit granular pressure increment (SolidsPressure::kImplicit): with psi = P'(phi)
/// (phi_new - phi) in the cells and the face flux correction dF = -g (psi_R - psi_L),
/// g = phi_d R A_t / h_n (R the face's solids response), phi_new - phi = b - dt/V sum_out dF
/// with b the explicit update, so
///   psi / P' + dt/V sum_nb g (psi - psi_nb) = b,
/// symmetric positive definite. Cells without solids pressure (P' = 0 or below residual_solids)
/// keep psi = 0 (their own update stays explicit); faces whose solids are held (g = 0) are
/// walls to it. The gas takes the difference on each face (mixture flux held).
void TfmSimulation::Impl::ImplicitSolidsPressure(Step& s) {
  const CellClosures& c = s.c;
  const double dt = s.dt, volume = dx * dz;
  Array& fs_x = s.fs_x;
  Array& fs_z = s.fs_z;
  const int cells = nx * nz;
  const int row = nx;
  auto id = [row](int i, int j) { return i + row * j; };
  auto active = [&](int i, int j) {
    return phi(i, j) >= s.o.residual_solids && c.pressure_derivative(i, j) > 0.0;
  };
  Array g_x = Array::Zero(nx + 1, nz), g_z = Array::Zero(nx, nz + 1);
  for (int j = 0; j < nz; ++j)
    for (int i = 1; i < nx; ++i)
      g_x(i, j) = s.fx_at(i, j).phi_flux * s.fx_at(i, j).solids_response * dz / dx;
  for (int j = 1; j < nz; ++j)
    for (int i = 0; i < nx; ++i)
      g_z(i, j) = s.fz_at(i, j).phi_flux * s.fz_at(i, j).solids_response * dx / dz;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(cells);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(5 * cells));
  const double scale = dt / volume;
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const int k = id(i, j);
      // Every coupling is entered (zero where inactive) so the pattern never changes.
      const bool on = active(i, j);
      const struct {
        int ni, nj;
        double g;
      } nbs[4] = {{i + 1, j, i + 1 < nx ? g_x(i + 1, j) : 0.0},
                  {i - 1, j, i > 0 ? g_x(i, j) : 0.0},
                  {i, j + 1, j + 1 < nz ? g_z(i, j + 1) : 0.0},
                  {i, j - 1, j > 0 ? g_z(i, j) : 0.0}};
      double diag = on ? 1.0 / c.pressure_derivative(i, j) : 1.0;
      for (const auto& nb : nbs) {
        if (nb.ni < 0 || nb.ni >= nx || nb.nj < 0 || nb.nj >= nz) continue;
        const bool couple = on && active(nb.ni, nb.nj);
        triplets.emplace_back(k, id(nb.ni, nb.nj), couple ? -scale * nb.g : 0.0);
        if (on) diag += scale * nb.g;  // an inactive neighbour holds psi = 0
      }
      triplets.emplace_back(k, k, diag);
      if (on) {
        b(k) = -dt * (fs_x(i + 1, j) - fs_x(i, j) + fs_z(i, j + 1) - fs_z(i, j)) / volume;
      }
    }
  Eigen::SparseMatrix<double> a(cells, cells);
  a.setFromTriplets(triplets.begin(), triplets.end());
  if (!pressure_increment_solver.Factorize(a))
    Bad(s.at +
        "the implicit solids-pressure matrix could not be factorised; remedy: "
        "solids_pressure = \"explicit\"");
  const Eigen::VectorXd psi = pressure_increment_solver.ldlt.solve(b);
  if (!psi.allFinite())
    Bad(s.at + "the implicit solids-pressure increment is not finite; remedy: lower cfl");
  auto psi_at = [&](int i, int j) { return active(i, j) ? psi(id(i, j)) : 0.0; };
  double largest = 0.0;
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i)
      if (active(i, j))
        largest =
            std::max(largest, std::abs(psi(id(i, j)) / c.pressure_derivative(i, j) - b(id(i, j))));
  diag.max_pressure_correction = std::max(diag.max_pressure_correction, largest);
  for (int j = 0; j < nz; ++j)
    for (int i = 1; i < nx; ++i) {
      const double df = -g_x(i, j) * (psi_at(i, j) - psi_at(i - 1, j));
      if (df == 0.0) continue;
      const double up = s.fx_at(i, j).phi_flux;
      fs_x(i, j) += df;
      us(i, j) += df / (up * dz);
      ug(i, j) -= df / ((1.0 - up) * dz);
    }
  for (int j = 1; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const double df = -g_z(i, j) * (psi_at(i, j) - psi_at(i, j - 1));
      if (df == 0.0) continue;
      const double up = s.fz_at(i, j).phi_flux;
      fs_z(i, j) += df;
      ws(i, j) += df / (up * dx);
      wg(i, j) -= df / ((1.0 - up) * dx);
    }
}

/// The flux limiter: a cell gives at most what it holds (positivity), and a full cell takes
/// only what it has room for (the packing limit); then the new solids fraction.
void TfmSimulation::Impl::LimitSolidsFluxes(Step& s) const {
  const double dt = s.dt, volume = dx * dz, phi_max = s.o.ktgf.packing_limit;
  Array& fs_x = s.fs_x;
  Array& fs_z = s.fs_z;
  s.limited_x = Array::Zero(nx + 1, nz);
  s.limited_z = Array::Zero(nx, nz + 1);
  Array& limited_x = s.limited_x;
  Array& limited_z = s.limited_z;
  // Net solids outflow of cell (i, j) over the step and its parts [m^2 per unit depth].
  auto outflow = [&](int i, int j) {
    return dt * (std::max(fs_x(i + 1, j), 0.0) + std::max(-fs_x(i, j), 0.0) +
                 std::max(fs_z(i, j + 1), 0.0) + std::max(-fs_z(i, j), 0.0));
  };
  auto inflow = [&](int i, int j) {
    return dt * (std::max(-fs_x(i + 1, j), 0.0) + std::max(fs_x(i, j), 0.0) +
                 std::max(-fs_z(i, j + 1), 0.0) + std::max(fs_z(i, j), 0.0));
  };
  // Positivity: a cell cannot give more than it holds.
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const double out = outflow(i, j), holds = phi(i, j) * volume;
      if (out <= holds) continue;
      const double r = holds / out;
      ++s.positivity_limited;
      if (fs_x(i + 1, j) > 0.0) fs_x(i + 1, j) *= r, limited_x(i + 1, j) = 1.0;
      if (fs_x(i, j) < 0.0) fs_x(i, j) *= r, limited_x(i, j) = 1.0;
      if (fs_z(i, j + 1) > 0.0) fs_z(i, j + 1) *= r, limited_z(i, j + 1) = 1.0;
      if (fs_z(i, j) < 0.0) fs_z(i, j) *= r, limited_z(i, j) = 1.0;
    }
  // Packing limit: a full cell takes only what it has room for (each pass only lowers fluxes,
  // so the passes converge; a donor that keeps more is checked in the next pass).
  Array& phi_new = s.phi_new;
  phi_new.resize(nx, nz);
  auto update_phi = [&]() {
    for (int j = 0; j < nz; ++j)
      for (int i = 0; i < nx; ++i)
        phi_new(i, j) = phi(i, j) + (inflow(i, j) - outflow(i, j)) / volume;
  };
  update_phi();
  const double bound_slack = 1e-12;
  bool over = true;
  for (int pass = 0; pass < 200 && over; ++pass) {
    over = false;
    for (int j = 0; j < nz; ++j)
      for (int i = 0; i < nx; ++i) {
        if (phi_new(i, j) <= phi_max + bound_slack) continue;
        over = true;
        ++s.packing_limited;
        const double in = inflow(i, j);
        const double room = std::max((phi_max - phi(i, j)) * volume + outflow(i, j), 0.0);
        const double r = in > 0.0 ? std::min(room / in, 1.0) : 0.0;
        if (fs_x(i + 1, j) < 0.0) fs_x(i + 1, j) *= r, limited_x(i + 1, j) = 1.0;
        if (fs_x(i, j) > 0.0) fs_x(i, j) *= r, limited_x(i, j) = 1.0;
        if (fs_z(i, j + 1) < 0.0) fs_z(i, j + 1) *= r, limited_z(i, j + 1) = 1.0;
        if (fs_z(i, j) > 0.0) fs_z(i, j) *= r, limited_z(i, j) = 1.0;
      }
    if (over) update_phi();
  }
  const double phi_new_max = phi_new.maxCoeff(), phi_new_min = phi_new.minCoeff();
  if (!(phi_new_max <= phi_max + bound_slack) || !(phi_new_min >= -bound_slack))
    Bad(s.at + "the solids fraction left [0, packing_limit = " + fmt(phi_max) + "] (min " +
        fmt(phi_new_min) + ", max " + fmt(phi_new_max) +
        ") although the flux limiter ran; remedy: lower cfl");
  phi_new = phi_new.max(0.0).min(phi_max);  // round-off only (bound_slack)
  s.phi_new_max = phi_new_max;
}

/// The limited faces: the solids velocity carries the limited flux, the gas the rest of the
/// unchanged mixture flux.
void TfmSimulation::Impl::CorrectLimitedFaces(Step& s) {
  for (int j = 0; j < nz; ++j)
    for (int i = 1; i < nx; ++i) {
      if (s.limited_x(i, j) == 0.0) continue;
      ++s.limited;
      const double up = s.fx_at(i, j).phi_flux;
      if (up > 0.0) us(i, j) = s.fs_x(i, j) / (up * dz);
      ug(i, j) = (s.mix_x(i, j) / dz - up * us(i, j)) / (1.0 - up);
    }
  for (int j = 1; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      if (s.limited_z(i, j) == 0.0) continue;
      ++s.limited;
      const double up = s.fz_at(i, j).phi_flux;
      if (up > 0.0) ws(i, j) = s.fs_z(i, j) / (up * dx);
      wg(i, j) = (s.mix_z(i, j) / dx - up * ws(i, j)) / (1.0 - up);
    }
}

/// The granular temperature (Eq. 15): transport and production explicit; conduction and the
/// sinks (dissipation, drag, expansion) implicit, an M-matrix, so theta >= 0 for any step.
/// Cells below residual_solids hold theta = 0 and no conduction reaches them.
Array TfmSimulation::Impl::TransportedTheta(const Step& s) {
  const TfmOptions& o = s.o;
  const CellClosures& c = s.c;
  const Array& phi_new = s.phi_new;
  const Array& fs_x = s.fs_x;
  const Array& fs_z = s.fs_z;
  const double dt = s.dt, volume = dx * dz, rho_s = o.particle_density_kg_m3;
  const double phi_res = o.residual_solids;
  Array kappa_x = Array::Zero(nx + 1, nz), kappa_z = Array::Zero(nx, nz + 1);
  auto active = [&](int i, int j) { return phi_new(i, j) >= phi_res && phi(i, j) >= phi_res; };
  // Harmonic face mean: a dilute cell next to a dense one exchanges at its own, small rate.
  auto harmonic = [](double a, double b) { return a + b > 0.0 ? 2.0 * a * b / (a + b) : 0.0; };
  for (int j = 0; j < nz; ++j)
    for (int i = 1; i < nx; ++i)
      if (active(i - 1, j) && active(i, j))
        kappa_x(i, j) = harmonic(c.kappa(i - 1, j), c.kappa(i, j));
  for (int j = 1; j < nz; ++j)
    for (int i = 0; i < nx; ++i)
      if (active(i, j - 1) && active(i, j))
        kappa_z(i, j) = harmonic(c.kappa(i, j - 1), c.kappa(i, j));
  const Array& th = theta;
  const int row = nx, last_i = nx - 1, last_j = nz - 1;
  auto theta_c = [&](int i, int j) {
    return th(std::clamp(i, 0, last_i), std::clamp(j, 0, last_j));
  };
  const int cells = nx * nz;
  auto id = [row](int i, int j) { return i + row * j; };
  Eigen::VectorXd energy_rhs = Eigen::VectorXd::Zero(cells);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<std::size_t>(5 * cells));
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      const int k = id(i, j);
      // Every coupling is entered (zero where inactive) so the pattern never changes.
      const double gx_e = i + 1 < nx ? kappa_x(i + 1, j) / (dx * dx) : 0.0;
      const double gx_w = i > 0 ? kappa_x(i, j) / (dx * dx) : 0.0;
      const double gz_n = j + 1 < nz ? kappa_z(i, j + 1) / (dz * dz) : 0.0;
      const double gz_s = j > 0 ? kappa_z(i, j) / (dz * dz) : 0.0;
      if (i + 1 < nx) triplets.emplace_back(k, id(i + 1, j), -gx_e);
      if (i > 0) triplets.emplace_back(k, id(i - 1, j), -gx_w);
      if (j + 1 < nz) triplets.emplace_back(k, id(i, j + 1), -gz_n);
      if (j > 0) triplets.emplace_back(k, id(i, j - 1), -gz_s);
      if (phi_new(i, j) < phi_res) {
        triplets.emplace_back(k, k, 1.0);  // theta = 0
        continue;
      }
      // Upwind transport of phi theta with the final solids fluxes (out: own theta, in: the
      // donor's).
      auto carried = [&](double flux_out, int ni, int nj) {
        return flux_out * (flux_out > 0.0 ? th(i, j) : theta_c(ni, nj));
      };
      const double adv = carried(fs_x(i + 1, j), i + 1, j) + carried(-fs_x(i, j), i - 1, j) +
                         carried(fs_z(i, j + 1), i, j + 1) + carried(-fs_z(i, j), i, j - 1);
      const Strain st = StrainAt(us, ws, i, j, dx, dz, o.solids_walls);
      const double production =
          2.0 * c.mu_kinetic(i, j) * st.dev2 + c.lambda(i, j) * st.div * st.div;
      const double expansion = c.kinetic_pressure_per_theta(i, j) * st.div;  // P_s div v / theta
      const double dissipation = c.dissipation(i, j);
      energy_rhs(k) = 1.5 * rho_s * (phi(i, j) * th(i, j) - dt * adv / volume) / dt + production +
                      std::max(-expansion, 0.0) * th(i, j) + std::max(-dissipation, 0.0) * th(i, j);
      const double diagonal = 1.5 * rho_s * phi_new(i, j) / dt + std::max(dissipation, 0.0) +
                              std::max(expansion, 0.0) +
                              (o.interphase_drag ? 3.0 * beta(i, j) : 0.0);
      triplets.emplace_back(k, k, diagonal + gx_e + gx_w + gz_n + gz_s);
    }
  Eigen::SparseMatrix<double> energy(cells, cells);
  energy.setFromTriplets(triplets.begin(), triplets.end());
  if (!energy_solver.Factorize(energy))
    Bad(s.at + "the granular temperature equation could not be factorised; remedy: lower cfl");
  const Eigen::VectorXd theta_vector = energy_solver.ldlt.solve(energy_rhs);
  Array theta_new = Eigen::Map<const Array>(theta_vector.data(), nx, nz);
  const double theta_min = theta_new.minCoeff();
  if (!theta_new.allFinite()) Bad(s.at + "non-finite granular temperature; remedy: lower cfl");
  if (theta_min < -1e-9 * std::max(theta_new.maxCoeff(), 1e-12)) {
    // The explicit parts are non-negative under the CFL limit; a negative value means the
    // transport outran it.
    Bad(s.at + "the granular temperature became negative (" + fmt(theta_min) +
        " m^2/s^2) with a step of " + fmt(dt) + " s (limit: " + to_string(s.why) +
        "); remedy: lower cfl");
  }
  return theta_new.max(0.0);
}

/// Local equilibrium (the algebraic option): from the new velocities, nothing transported;
/// theta = 0 below algebraic_theta_min_solids (TfmOptions says why).
Array TfmSimulation::Impl::EquilibriumTheta(const Step& s) const {
  const TfmOptions& o = s.o;
  Array equilibrium = Array::Zero(nx, nz);
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      if (s.phi_new(i, j) < std::max(o.residual_solids, o.algebraic_theta_min_solids)) continue;
      const Strain st = StrainAt(us, ws, i, j, dx, dz, o.solids_walls);
      try {
        equilibrium(i, j) = ktgf->EquilibriumTheta(s.phi_new(i, j), st.div, st.dev2,
                                                   o.interphase_drag ? 3.0 * beta(i, j) : 0.0);
      } catch (const Error& e) {
        throw Error(e.code(), s.at + "cell (" + std::to_string(i) + ", " + std::to_string(j) +
                                  "): " + e.what());
      }
    }
  return equilibrium;
}

/// The new state and the step's diagnostics (gas mass balance, limits, extremes).
void TfmSimulation::Impl::Record(const Step& s, const Array& theta_new) {
  const TfmOptions& o = s.o;
  const double dt = s.dt, volume = dx * dz, rho_s = o.particle_density_kg_m3;
  double gas_in = 0.0, gas_out = 0.0;
  for (int i = 0; i < nx; ++i) {
    gas_in += s.mix_z(i, 0);
    gas_out += s.mix_z(i, nz);
  }
  const double storage = -(s.phi_new - phi).sum() * volume / dt;  // d/dt int eps
  const double mass_scale = o.gas.rho_g * depth * dt;
  TfmDiagnostics& dg = diag;
  dg.gas_mass_in_kg += mass_scale * gas_in;
  dg.gas_mass_imbalance_kg += mass_scale * (gas_in - gas_out - storage);
  phi = s.phi_new;
  theta = theta_new;
  time = s.t_new;
  ++dg.steps;
  dg.time_s = time;
  dg.last_dt_s = dt;
  if (!s.landing) dg.min_dt_s = dg.min_dt_s == 0.0 ? dt : std::min(dg.min_dt_s, dt);
  dg.last_limit = s.why;
  ++dg.steps_by_limit[static_cast<int>(s.why)];
  dg.solids_mass_kg = phi.sum() * volume * depth * rho_s;
  dg.max_solids_fraction = std::max(dg.max_solids_fraction, s.phi_new_max);
  dg.max_theta_m2_s2 = std::max(dg.max_theta_m2_s2, theta_new.maxCoeff());
  dg.flux_limited_faces += s.limited;
  dg.implicit_viscosity_faces += s.implicit_faces;
  dg.positivity_limited_cells += s.positivity_limited;
  dg.packing_limited_cells += s.packing_limited;
  dg.max_wave_speed_m_s = std::max(
      dg.max_wave_speed_m_s, std::sqrt(std::max(s.c.pressure_derivative.maxCoeff(), 0.0) / rho_s));
  dg.poisson_residual = pressure->diagnostics().relative_residual;
}

}  // namespace consumers
}  // namespace draglab
