// solver.h: time stepping on the sparse lattice: AA even/odd collision sweeps, the boundary-link
// pass (interpolated bounce-back and momentum exchange) and the diagnostic moment sweep.
//
// Boundary-link pass (every step when interpolating; at checked steps only for halfway
// bounce-back, which the masked AA sweeps already do), right behind the sweep of each step
// (solver.cc: a link touches only rows near its own, so it runs while they are cached). With
// interpolated walls the sweeps are plain (no solid-neighbour masks): the odd sweep writes the
// value leaving r along c_i into the solid neighbour's slot (row i at r + c_i, a ghost) and reads
// the value coming back from there, and the pass moves each value where the next step reads it
// (lattice.h, LinkTable::ghost). For a link from
// fluid node r along c_i into a solid node, with wall fraction q, the value that comes back into r
// along c_ib (ib = opp(i)) at the next step is, with post-collision values f* of this step,
//   f_ib(r, t+1) = f + a (f*_i(r - c_i) - f) + b (f*_ib(r) - f),   f = f*_i(r),
// with the weights a, b of the wall scheme (lattice.h, wall_weights), plus, with the regularized
// collision, the wall correction of lbm.h (Numerics; SolverSettings::wall_correction). The
// central one, a = kappa,
// b = -kappa, kappa = (1 - 2q)/(1 + 2q), is
// Ginzburg's central linear interpolation (CLI; Ginzburg & d'Humieres 2003, Ginzburg et al. 2008,
// Khirevich et al. 2015). It is exact for a linear profile at the wall, reduces to halfway
// bounce-back at q = 1/2, keeps |kappa| <= 1 for all q in (0, 1] (no division by q as in
// Bouzidi's q < 1/2 branch) and, being built from the post-collision values along one link line
// only, keeps the TRT steady state a function of Lambda alone (viscosity independent); but its
// negative weight amplifies the short waves that a tau near 1/2 leaves undamped. Linear Bouzidi
// (BFL: a = 1 - 2q, b = 0 for q < 1/2; a = 0, b = (2q - 1)/(2q) above) has no negative weight and
// stays stable there; its wall moves with tau, by little near tau = 1/2. Fallback:
// when r - c_i is solid (a gap of one node along the link) the link uses plain halfway
// bounce-back; this also makes every link update independent of the others (no link reads a
// value another link writes), so the pass runs in any order and in parallel.
// Momentum exchange (Ladd 1994; Mei et al. 2002 for interpolated walls): the force on the body is
//   F = sum over its links of (f*_i(r) + f_ib(r, t+1) - 2 w_i) c_i
// (the reference pressure's part 2 w_i c_i left out: it cancels over the interface, but not over a
// body that lost links in a sub-node gap to its neighbour),
// the momentum the fluid loses through the link in one step, so the steady sum over all bodies
// equals G times the fluid node count to round-off.
#pragma once

#include <cstdint>
#include <vector>

#include "checkpoint.h"
#include "collision.h"
#include "draglab/lbm/lbm.h"
#include "draglab/mpi/communicator.h"
#include "lattice.h"

namespace draglab {
namespace lbm {

/// Reductions of the moment sweep (velocities u = j/rho, or j in Stokes mode), over every rank
/// of a decomposed box. Nodes are dense indices in the whole box.
struct MomentSummary {
  double sum_u[3] = {0, 0, 0};  ///< Sum over fluid nodes.
  double max_speed2 = 0.0;      ///< max |u|^2.
  std::int64_t max_speed_node = -1;
  double min_rho = 1.0;
  std::int64_t min_rho_node = -1;
  std::int64_t nonfinite_node = -1;  ///< A node with a NaN/Inf population, -1 if none.
  double sum_drho = 0.0;             ///< Total mass minus the rest mass.
};

struct SolverSettings {
  CollisionKernel kernel = CollisionKernel::kTrt;
  bool stokes = false;
  double omega_plus = 1.0;
  double omega_minus = 1.0;
  double force_x = 0.0;
  bool interpolated = true;
  /// Feed the interpolation's net mass leak back (off only to compare schemes in tests).
  bool mass_correction = true;
  /// Regularized collision: coefficient 2 Lambda / (tau - 1/2) - 1 of the wall correction that
  /// gives the reflected values TRT's wall at Lambda (lbm.h, Numerics); 0 = off.
  double wall_correction = 0.0;
};

class SolverBase {
 public:
  virtual ~SolverBase() = default;
  virtual void set_force(double force_x) = 0;
  /// Two time steps (even then odd, with their link passes). If body_force is non-null it gets
  /// 3 components per body: the momentum exchange of the second step.
  virtual void advance_pair(std::vector<double>* body_force) = 0;
  /// Sum over links of |momentum exchange along x| of the last force evaluation: the scale of the
  /// round-off in the body-force sum (about 1e-16 of it).
  virtual double force_magnitude() const = 0;
  /// Valid after advance_pair (streamed layout).
  virtual MomentSummary moments() const = 0;
  /// Multiplies every population deviation g_i = f_i - w_i by `factor` (rescales a Stokes
  /// solution exactly when the force is rescaled by the same factor).
  virtual void scale_deviations(double factor) = 0;
  /// Velocity (3 per node), density and solid mask on the dense grid, x fastest; gathered on
  /// the first rank of a decomposed box (the others get the dims only). Collective.
  virtual void fill_fields(Fields* fields) const = 0;
  virtual std::size_t bytes() const = 0;
  /// The state a checkpoint keeps (populations, rr's wall correction, the pending mass defect):
  /// byte ranges of the solver's own storage, read from for writing and written into when
  /// resuming (checkpoint.h). This rank's share of a decomposed box.
  virtual std::vector<StateSection> state() = 0;
  /// g_i = f_i - w_i of fluid node n in the streamed layout (pre-collision, as after
  /// advance_pair): for tests and diagnostics.
  virtual double deviation(int i, std::int64_t n) const = 0;
  virtual void set_deviation(int i, std::int64_t n, double value) = 0;
};

/// Makes a solver storing populations in double or float (computing in the same type). A
/// decomposed lattice needs `group`, the ranks of its box in plane order (the solver's steps,
/// moments and field output are then collective); the body forces, the force magnitude and
/// the moments it returns are sums over all ranks, the same bits on each.
std::unique_ptr<SolverBase> make_solver(Precision precision, const SparseLattice& lattice,
                                        const LinkTable& links, const SolverSettings& settings,
                                        int threads,
                                        const mpi::Communicator& group = mpi::Communicator::self());

}  // namespace lbm
}  // namespace draglab
