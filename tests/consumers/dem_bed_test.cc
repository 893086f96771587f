// DEM bed-scale checks: settling under gravity and terminal velocity with a stored drag law.
//
// 4. Settling: 1500 glass spheres (d = 2.5 mm, rho = 2526 kg/m^3, e = 0.5 to settle quickly,
//    friction 0.1, k_n = 1000 N/m, overlaps < 0.1 % d) poured into a box periodic in x and z
//    (10 d x 10 d: no side walls carrying weight) onto a flat floor. References: at rest the
//    floor carries the whole weight (static force balance; tolerance 0.5 %, the residual
//    kinetic-energy ratio bounds the unbalanced dynamic part far below that); the solids
//    fraction of the bed interior (slab from 3 d above the floor to 3 d below the surface,
//    exact sphere-slab volumes) lies in the random-packing range 0.55-0.64: random loose packing
//    of frictional spheres 0.555 (Onoda & Liniger, Phys. Rev. Lett. 64 (1990) 2727) to random
//    close packing 0.637 (Scott & Kilgour, J. Phys. D 2 (1969) 863).
// 5. Terminal velocity: one 0.5 mm glass bead falling through air at rest (rho_g = 1.2 kg/m^3,
//    mu = 1.8e-5 Pa s) in a box periodic along y, with the external force F_d + buoyancy from
//    the Schiller-Naumann law of drag_db (F_d = 3 pi mu d u F(phi = 0, Re = rho d u / mu)). The
//    reference is the force balance (rho_p - rho_g) V g = 3 pi mu d u F(0, Re) solved in the
//    test by bisection; after 20 relaxation times the DEM velocity must agree within 0.5 %.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "draglab/consumers/dem.h"
#include "draglab/drag_db/law.h"
#include "draglab/drag_db/law_form.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Volume of a sphere (centre y0, radius r) between heights a < b.
double SphereSlabVolume(double y0, double r, double a, double b) {
  const double lo = std::max(a, y0 - r), hi = std::min(b, y0 + r);
  if (hi <= lo) return 0.0;
  // Integral of pi (r^2 - (y - y0)^2) dy.
  auto prim = [&](double y) {
    const double t = y - y0;
    return kPi * (r * r * t - t * t * t / 3.0);
  };
  return prim(hi) - prim(lo);
}

TEST(DemSettle, BedAtRestCarriesItsWeightAtRandomPacking) {
  const double d = 2.5e-3;
  DemOptions o;
  o.box_min = {0.0, 0.0, 0.0};
  o.box_max = {10 * d, 0.1, 10 * d};
  o.periodic = {true, false, true};
  o.normal_stiffness = 1000.0;
  o.restitution = o.wall_restitution = 0.5;
  SettleOptions s;
  s.n = 1500;
  s.diameter = d;
  s.seed = 3;
  s.kinetic_energy_tolerance = 1e-6;
  const SettleResult r = settle_particles(o, s);
  RecordProperty("settle", r.BriefReport());
  std::printf("%s\n", r.BriefReport().c_str());
  EXPECT_NEAR(r.floor_force_n, r.weight_n, 0.005 * r.weight_n);
  // Interior solids fraction.
  const double a = 3 * d, b = r.bed_height_m - 3 * d;
  ASSERT_GT(b - a, 4 * d);
  double solids = 0.0;
  const auto& p = r.particles;
  for (std::size_t i = 0; i < p.size(); ++i) solids += SphereSlabVolume(p.y[i], 0.5 * d, a, b);
  const double phi = solids / ((b - a) * o.box_max[0] * o.box_max[2]);
  RecordProperty("phi", std::to_string(phi));
  std::printf("interior solids fraction %.4f\n", phi);
  EXPECT_GT(phi, 0.55);
  EXPECT_LT(phi, 0.64);
  // Deterministic: the same seed gives the same packing.
  EXPECT_EQ(p.size(), static_cast<std::size_t>(s.n));
}

TEST(DemSettle, BedThatDoesNotFitIsRefused) {
  DemOptions o;
  o.box_max = {0.02, 0.01, 0.01};
  o.normal_stiffness = 1000.0;
  o.restitution = o.wall_restitution = 0.3;
  SettleOptions s;
  s.n = 200;  // ~ 0.6 solids fraction would need ~ 1.4 cm of height
  s.kinetic_energy_tolerance = 1e-4;
  try {
    settle_particles(o, s);
    ADD_FAILURE() << "bed taller than the box accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("does not fit"), std::string::npos) << e.what();
  }
}

TEST(DemTerminalVelocity, MatchesForceBalanceOfLoadedLaw) {
  const Law law(literature_record(find_law_form("schiller_naumann")));
  const double d = 0.5e-3, rho_p = 2526.0, rho_g = 1.2, mu = 1.8e-5, g = 9.81;
  const double volume = kPi / 6.0 * d * d * d;
  const double net_weight = (rho_p - rho_g) * volume * g;
  auto drag = [&](double u) { return 3.0 * kPi * mu * d * u * law.F(0.0, rho_g * d * u / mu); };
  // Independent reference: bisection on the force balance.
  double lo = 0.0, hi = 100.0;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (drag(mid) < net_weight ? lo : hi) = mid;
  }
  const double u_t = 0.5 * (lo + hi);
  DemOptions o;
  o.box_min = {0.0, 0.0, 0.0};
  o.box_max = {4 * d, 4 * d, 4 * d};
  o.periodic = {true, true, true};
  o.normal_stiffness = 10.0;  // no contacts here: a soft spring allows a large step
  Particles p;
  p.add(2 * d, 2 * d, 2 * d, d, rho_p);
  DemSystem dem(o, p);
  auto& q = dem.mutable_particles();
  const double tau = u_t / g;  // relaxation time scale of the fall
  while (dem.time() < 20.0 * tau) {
    const double u = -q.vy[0];  // falling speed (gas at rest)
    q.fy_ext[0] = drag(std::max(u, 0.0)) * (u >= 0 ? 1.0 : -1.0) + rho_g * volume * g;
    dem.step();
  }
  RecordProperty("u_terminal", std::to_string(u_t));
  EXPECT_GT(u_t, 1.0);  // inertial regime: Re ~ 100, not Stokes
  EXPECT_NEAR(-q.vy[0], u_t, 0.005 * u_t);
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
