// The discrete bubble model's bubble-scale closures (consumers/dbm_closures.h).
// References:
// (1) Davies & Taylor 1950, u_br = 0.711 sqrt(g d_b): 0.315 / 0.445 / 0.498 / 0.589 / 0.704 m/s
//     for d_b = 0.02 / 0.04 / 0.05 / 0.07 / 0.10 m (g = 9.81; three digits).
// (2) An isolated bubble in a quiescent emulsion (hydrostatic pressure gradient rho_e g, u = 0)
//     obeys m v' = (rho_e - rho_b) g - k v^2 with m = rho_b + C_VM rho_e, so from rest
//     v(t) = u_br tanh(t / tau), tau = m u_br / ((rho_e - rho_b) g) (0.027 s for the seed's 4 cm
//     bubble: rho_e 400, rho_b 25, C_VM 0.5). The model's implicit step is first order: with
//     dt = tau / 2000 the error at t = tau is below 1e-3 u_br, and the terminal velocity of 2,
//     4 and 8 cm bubbles is the Davies-Taylor one to 1e-9 (the steady balance is exact).
// (3) Davidson & Harrison's orifice bubble, Darton et al. 1977 and Mori & Wen 1975 (porous
//     plate, CGS inside) against values worked out by hand for the seed's DBM column
//     (1 m x 1 m, 49 nozzles, u0 - umf = 0.1 and 0.3 m/s; three digits): D-H 0.069 / 0.107 m;
//     Darton (A0 -> 0) 0.078 / 0.136 m at h = 0.5 / 1.0 m (0.1 m/s), 0.121 / 0.211 m (0.3 m/s);
//     Darton (A0 = 1/49 m^2) 0.144 / 0.195 m and 0.223 / 0.303 m; Mori-Wen (D_t = 1.128 m)
//     0.083 / 0.154 m and 0.148 / 0.255 m; C_D = 2.47 for the seed's densities.
#include <gtest/gtest.h>

#include <cmath>

#include "dbm/dbm_closures.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

TEST(DbmClosures, DaviesTaylorRiseVelocity) {
  const double d[] = {0.02, 0.04, 0.05, 0.07, 0.10};
  const double u[] = {0.315, 0.445, 0.498, 0.589, 0.704};
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(davies_taylor_rise_velocity(d[k]), u[k], 0.6e-3) << d[k];
  EXPECT_THROW(davies_taylor_rise_velocity(0.0), Error);
}

TEST(DbmClosures, IsolatedBubbleRisesAsTheClosedFormAndEndsAtDaviesTaylor) {
  const BubbleForceModel model{BubbleForceOptions{}};
  EXPECT_NEAR(model.drag_coefficient(), 2.47, 0.005);
  const double g = 9.81, rho_e = 400.0, rho_b = 25.0;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  const Eigen::Vector3d hydrostatic(0.0, 0.0, -rho_e * g);  // grad p, z up
  for (double d : {0.02, 0.04, 0.08}) {
    const double u_br = davies_taylor_rise_velocity(d);
    const double tau = model.inertia_density() * u_br / ((rho_e - rho_b) * g);
    if (d == 0.04) {
      EXPECT_NEAR(tau, 0.027, 0.0005);
    }
    const double dt = tau / 2000.0;
    Eigen::Vector3d v = zero;
    for (int n = 0; n < 2000; ++n) v = model.Step(v, zero, hydrostatic, zero, d, dt);
    EXPECT_NEAR(v.z(), u_br * std::tanh(1.0), 1e-3 * u_br) << d;
    EXPECT_EQ(v.x(), 0.0);
    for (int n = 0; n < 400; ++n) v = model.Step(v, zero, hydrostatic, zero, d, 50.0 * dt);
    EXPECT_NEAR(v.z(), u_br, 1e-9 * u_br) << d;
  }
  // The slip, not the absolute velocity, is what the drag sees: in an emulsion rising at w the
  // bubble rises at w + u_br.
  const Eigen::Vector3d w(0.0, 0.0, 0.2);
  Eigen::Vector3d v = w;
  for (int n = 0; n < 2000; ++n) v = model.Step(v, w, hydrostatic, zero, 0.04, 1e-3);
  EXPECT_NEAR(v.z(), 0.2 + davies_taylor_rise_velocity(0.04), 1e-9);
}

TEST(DbmClosures, BubbleSizeRelationsMatchTheWorkedNumbers) {
  const double area = 1.0, per_orifice = 1.0 / 49.0, diameter = std::sqrt(4.0 / 3.14159265358979);
  EXPECT_NEAR(davidson_harrison_bubble_diameter(0.1 * per_orifice), 0.069, 0.6e-3);
  EXPECT_NEAR(davidson_harrison_bubble_diameter(0.3 * per_orifice), 0.107, 0.6e-3);
  EXPECT_NEAR(davidson_harrison_bubble_volume(0.1 * per_orifice), 1.71e-4, 0.006e-4);
  const double darton0[2][2] = {{0.078, 0.136}, {0.121, 0.211}};
  const double darton49[2][2] = {{0.144, 0.195}, {0.223, 0.303}};
  const double mori[2][2] = {{0.083, 0.154}, {0.148, 0.255}};
  const double excess[2] = {0.1, 0.3}, height[2] = {0.5, 1.0};
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      EXPECT_NEAR(darton_bubble_diameter(excess[a], height[b], 0.0), darton0[a][b], 0.6e-3);
      EXPECT_NEAR(darton_bubble_diameter(excess[a], height[b], per_orifice), darton49[a][b],
                  0.6e-3);
      EXPECT_NEAR(mori_wen_bubble_diameter(excess[a], height[b], area, diameter), mori[a][b],
                  0.6e-3);
    }
  // Mori-Wen tends to its maximum d_bm = 0.65 [A (u0 - umf)]^0.4 cm high up: 0.65 m here.
  EXPECT_NEAR(mori_wen_bubble_diameter(0.1, 1e3, area, diameter), 0.65, 1e-9);
  EXPECT_NEAR(two_phase_holdup(0.1, 0.0, 0.445), 0.2247, 1e-4);
  EXPECT_EQ(two_phase_holdup(0.01, 0.02, 0.445), 0.0);
  EXPECT_THROW(darton_bubble_diameter(0.0, 0.5, 0.0), Error);
}

TEST(DbmClosures, BadOptionsNameTheField) {
  BubbleForceOptions o;
  std::string why;
  o.emulsion_density_kg_m3 = 20.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("emulsion_density_kg_m3"), std::string::npos) << why;
  EXPECT_THROW(BubbleForceModel{o}, Error);
  o = BubbleForceOptions{};
  o.virtual_mass_coefficient = -1.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("virtual_mass_coefficient"), std::string::npos) << why;
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
