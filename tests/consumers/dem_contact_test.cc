// DEM contact model checks against closed-form solutions.
//
// 1. Single normal collision, 2.5 mm glass (rho 2526 kg/m^3), k_n = 7000 N/m, no gravity, no
//    friction, head-on at 0.5 m/s, particle-particle (m_eff = m/2) and particle-wall (m_eff = m).
//    Reference: the linear spring-dashpot m_eff x'' = -k x - eta x' with
//    eta = 2 sqrt(k m_eff) |ln e| / sqrt(pi^2 + ln^2 e) has contact time
//    t_c = pi / sqrt(k/m_eff - gamma^2), gamma = eta/(2 m_eff), and rebound ratio
//    exp(-gamma t_c) = e exactly (MFiX check_solids_dem.f; consumers.md 3.5: t_c = 1.21e-4 s
//    for k = 7000 N/m, e = 0.97, 2.5 mm glass). Tolerance 1 % (issue); run at t_c/200 with the
//    contact start/end interpolated linearly between steps (time error O(dt^2)).
// 2. Sphere sliding on a floor with Coulomb friction mu = 0.1, v0 = 0.5 m/s, no spin: the
//    angular momentum about the contact point is conserved, so the final rolling velocity is
//    v = (v0 + (2/5) R w0) / (7/5) = 5/7 v0 (solid sphere), reached after t = 2 v0 / (7 mu g).
//    Tolerance 1 % (tangential-spring oscillations after sticking are damped by eta_t).
// 3. Energy: 300 frictionless elastic spheres (e = 1, walls too) at phi ~ 0.2 without gravity,
//    ~3000 collisions: total energy (kinetic + spring) is conserved by velocity Verlet up to the
//    O((omega dt)^2) error of resolving each contact; bound 1 % at t_c/20 and the error must
//    shrink at least 2x at t_c/40 (second order: 4x expected).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "draglab/consumers/dem.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kD = 2.5e-3, kRho = 2526.0, kK = 7000.0;

double AnalyticContactTime(double k, double m_eff, double e) {
  const double l = std::log(e);
  const double eta = 2.0 * std::sqrt(k * m_eff) * std::fabs(l) / std::sqrt(kPi * kPi + l * l);
  const double gamma = eta / (2.0 * m_eff);
  return kPi / std::sqrt(k / m_eff - gamma * gamma);
}

DemOptions NoGravityBox() {
  DemOptions o;
  o.box_min = {0.0, 0.0, 0.0};
  o.box_max = {0.05, 0.05, 0.05};
  o.gravity = {0.0, 0.0, 0.0};
  o.normal_stiffness = kK;
  o.friction = o.wall_friction = 0.0;
  return o;
}

struct Collision {
  double contact_time = 0.0;
  double restitution = 0.0;
};

// Head-on collision: gap(t) from the system, crossing times interpolated linearly.
template <typename Gap, typename Speed>
Collision Measure(DemSystem& dem, Gap gap, Speed approach_speed) {
  const double v_in = approach_speed();
  double t_start = -1.0, t_end = -1.0;
  double g_prev = gap(), t_prev = dem.time();
  for (int s = 0; s < 1000000 && t_end < 0.0; ++s) {
    dem.step();
    const double g = gap();
    if (t_start < 0.0 && g_prev > 0.0 && g <= 0.0) {
      t_start = t_prev + (dem.time() - t_prev) * g_prev / (g_prev - g);
    } else if (t_start >= 0.0 && g_prev <= 0.0 && g > 0.0) {
      t_end = t_prev + (dem.time() - t_prev) * (-g_prev) / (g - g_prev);
    }
    g_prev = g;
    t_prev = dem.time();
  }
  dem.step();  // out of contact: velocities are the free-flight ones
  return {t_end - t_start, -approach_speed() / v_in};
}

class NormalCollision : public ::testing::TestWithParam<double> {};

TEST_P(NormalCollision, ParticleParticleRestitutionAndContactTime) {
  const double e = GetParam();
  DemOptions o = NoGravityBox();
  o.restitution = e;
  o.min_steps_per_contact = 200;
  Particles p;
  p.add(0.020, 0.025, 0.025, kD, kRho, 0.5, 0.0, 0.0);
  p.add(0.030, 0.025, 0.025, kD, kRho, -0.5, 0.0, 0.0);
  DemSystem dem(o, p);
  const double m = kRho * kPi / 6.0 * kD * kD * kD;
  const double tc = AnalyticContactTime(kK, 0.5 * m, e);
  EXPECT_NEAR(dem.contact_time(), tc, 1e-12 * tc);
  if (e == 0.97) {
    EXPECT_NEAR(tc, 1.21e-4, 0.01e-4);  // consumers.md 3.5
  }
  const auto& q = dem.particles();
  const Collision c = Measure(
      dem, [&] { return q.x[1] - q.x[0] - kD; }, [&] { return q.vx[0] - q.vx[1]; });
  EXPECT_NEAR(c.restitution, e, 0.01 * e);
  EXPECT_NEAR(c.contact_time, tc, 0.01 * tc);
  // Momentum is exchanged pairwise (each pair force computed from both sides).
  EXPECT_NEAR(q.vx[0] + q.vx[1], 0.0, 1e-12);
}

TEST_P(NormalCollision, ParticleWallRestitutionAndContactTime) {
  const double e = GetParam();
  DemOptions o = NoGravityBox();
  o.wall_restitution = e;
  o.min_steps_per_contact = 200;
  Particles p;
  p.add(0.025, 0.01, 0.025, kD, kRho, 0.0, -0.5, 0.0);
  DemSystem dem(o, p);
  const double m = kRho * kPi / 6.0 * kD * kD * kD;
  const double tc = AnalyticContactTime(kK, m, e);
  const auto& q = dem.particles();
  const Collision c = Measure(
      dem, [&] { return q.y[0] - 0.5 * kD; }, [&] { return -q.vy[0]; });
  EXPECT_NEAR(c.restitution, e, 0.01 * e);
  EXPECT_NEAR(c.contact_time, tc, 0.01 * tc);
}

INSTANTIATE_TEST_SUITE_P(Restitution, NormalCollision, ::testing::Values(0.97, 0.5));

TEST(DemTangential, SlidingSphereRollsAtFiveSeventhsV0) {
  DemOptions o;
  o.box_min = {0.0, 0.0, 0.0};
  o.box_max = {1.0, 0.02, 0.02};
  o.normal_stiffness = kK;
  o.wall_friction = 0.1;
  const double v0 = 0.5, r = 0.5 * kD, g = 9.81;
  const double m = kRho * kPi / 6.0 * kD * kD * kD;
  Particles p;
  p.add(0.05, r - m * g / kK, 0.01, kD, kRho, v0, 0.0, 0.0);  // at its static overlap
  DemSystem dem(o, p);
  const double t_roll = 2.0 * v0 / (7.0 * o.wall_friction * g);
  dem.advance(0.5 * t_roll);
  const auto& q = dem.particles();
  // Still sliding halfway: Coulomb deceleration mu g.
  EXPECT_NEAR(q.vx[0], v0 - o.wall_friction * g * 0.5 * t_roll, 0.01 * v0);
  dem.advance(2.0 * t_roll);
  EXPECT_NEAR(q.vx[0], 5.0 / 7.0 * v0, 0.01 * 5.0 / 7.0 * v0);
  EXPECT_NEAR(q.wz[0] * r, -q.vx[0], 0.01 * q.vx[0]);  // rolling without slip
}

// Maximum relative energy deviation over a dense elastic gas run.
double ElasticGasEnergyError(double steps_per_contact) {
  DemOptions o = NoGravityBox();
  o.box_max = {0.03, 0.03, 0.03};
  o.restitution = o.wall_restitution = 1.0;
  o.min_steps_per_contact = steps_per_contact;
  Particles p;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01(0.0, 0.5);
  // Simple cubic lattice start (spacing 1.5 d, phi 0.155) with random velocities.
  const double s = 1.5 * kD;
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j)
      for (int k = 0; k < 7 && p.size() < 300; ++k)
        p.add(0.003 + i * s + 0.001, 0.003 + j * s, 0.003 + k * s, kD, kRho, n01(rng), n01(rng),
              n01(rng));
  DemSystem dem(o, p);
  const double e0 = dem.energy().total();
  double worst = 0.0;
  std::int64_t collisions = 0;
  while (dem.time() < 0.03) {
    dem.advance(1e-4);
    collisions += dem.contact_count();
    worst = std::max(worst, std::fabs(dem.energy().total() - e0) / e0);
  }
  EXPECT_GT(dem.energy().kinetic(), 0.9 * e0);
  return worst;
}

TEST(DemEnergy, ElasticFrictionlessGasConservesEnergy) {
  const double err20 = ElasticGasEnergyError(20);
  const double err40 = ElasticGasEnergyError(40);
  RecordProperty("energy_error_tc20", std::to_string(err20));
  RecordProperty("energy_error_tc40", std::to_string(err40));
  EXPECT_LT(err20, 0.01);
  EXPECT_LT(err40, 0.5 * err20);
}

TEST(DemOptionsTest, RejectsBadInputNamingTheField) {
  auto message = [](const DemOptions& o) {
    std::string e;
    EXPECT_FALSE(o.IsValid(&e));
    return e;
  };
  DemOptions o;
  o.restitution = 0.0;
  EXPECT_NE(message(o).find("restitution"), std::string::npos);
  o = DemOptions();
  o.friction = -0.1;
  EXPECT_NE(message(o).find("friction"), std::string::npos);
  o = DemOptions();
  o.normal_stiffness = -1;
  EXPECT_NE(message(o).find("normal_stiffness"), std::string::npos);
  o = DemOptions();
  o.box_max[1] = -1;
  EXPECT_NE(message(o).find("box_max[1]"), std::string::npos);
  EXPECT_TRUE(DemOptions().IsValid(nullptr));

  Particles p;
  p.add(0.05, 0.05, 0.0075, -1e-3, kRho);
  try {
    DemSystem dem(DemOptions(), p);
    ADD_FAILURE() << "negative diameter accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("diameter"), std::string::npos);
  }
}

TEST(DemOptionsTest, RefusesTimeStepAboveStabilityLimit) {
  Particles p;
  p.add(0.05, 0.05, 0.0075, kD, kRho);
  DemOptions o;
  o.dt = 1e-4;  // t_c = 1.2e-4 s: far above t_c/20
  try {
    DemSystem dem(o, p);
    ADD_FAILURE() << "dt above the limit accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("stability limit"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("remedy"), std::string::npos);
  }
  o.dt = 0.0;
  DemSystem dem(o, p);
  EXPECT_THROW(dem.step(10.0 * dem.max_time_step()), Error);
  EXPECT_NEAR(dem.time_step(), dem.contact_time() / 20.0, 1e-15);
  // advance() sub-steps a long interval instead.
  EXPECT_EQ(dem.advance(10.5 * dem.max_time_step()), 11);
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
