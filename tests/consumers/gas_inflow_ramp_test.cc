// Gas phase: the valve ramps of the inflow (GasOptions::inflow_ramp_s, consumers/gas_phase.h).
//
// Set-up: a 0.10 m wide bed on 20 cells, background 1.3 m/s, a 1 cm central slot (2 cells) at
// 15 m/s opened at 0.05 s for 0.1 s, ramp 5 ms.
// References (exact, from the definition): the background rises linearly from 0 to its value over
// [0, ramp]; the jet's excess over the background rises over [start, start + ramp] and falls over
// [end, end + ramp]; so the injected jet volume per depth, integral of sum_i (u_i - U_bg) dx dt
// over the pulse, equals slot * (v_jet - U_bg) * duration exactly (trapezoid rule on a grid that
// contains the ramp corners is exact for this piecewise-linear signal: tolerance 1e-12
// relative), and ramp = 0 gives the instant switch of before.
#include <gtest/gtest.h>

#include <string>

#include "draglab/consumers/gas_phase.h"

namespace draglab {
namespace consumers {
namespace {

GasOptions RampOptions(double ramp) {
  GasOptions g;
  g.nx = 20;
  g.nz = 10;
  g.width_m = 0.10;
  g.height_m = 0.05;
  g.depth_m = 0.0075;
  g.background_velocity_m_s = 1.3;
  g.jet_width_m = 0.01;
  g.jet_velocity_m_s = 15.0;
  g.jet_start_s = 0.05;
  g.jet_duration_s = 0.1;
  g.inflow_ramp_s = ramp;
  return g;
}

double ExcessFlow(const GasPhase& gas, double t) {  // sum over faces of (u - U_bg(t)) dx
  double q = 0.0;
  for (int i = 0; i < gas.options().nx; ++i) q += gas.InflowSuperficialVelocity(i, t) * gas.dx();
  return q;
}

TEST(GasInflowRamp, BackgroundAndJetRampLinearlyAndInjectTheSameVolume) {
  const GasPhase gas(RampOptions(0.005));
  const int centre = 10;  // a slot cell (the slot covers cells 9 and 10 exactly)
  EXPECT_DOUBLE_EQ(gas.InflowSuperficialVelocity(0, 0.0), 0.0);
  EXPECT_NEAR(gas.InflowSuperficialVelocity(0, 0.0025), 0.65, 1e-12);
  EXPECT_NEAR(gas.InflowSuperficialVelocity(0, 0.01), 1.3, 1e-12);
  EXPECT_NEAR(gas.InflowSuperficialVelocity(centre, 0.0525), 1.3 + 0.5 * 13.7, 1e-12);
  EXPECT_NEAR(gas.InflowSuperficialVelocity(centre, 0.1), 15.0, 1e-12);
  EXPECT_NEAR(gas.InflowSuperficialVelocity(centre, 0.1525), 1.3 + 0.5 * 13.7, 1e-12);
  EXPECT_NEAR(gas.InflowSuperficialVelocity(centre, 0.16), 1.3, 1e-12);
  // Injected excess volume per depth over the pulse, trapezoid on a 0.5 ms grid (exact here).
  const double background_flow = 1.3 * 0.10;
  double volume = 0.0;
  const double h = 0.0005;
  for (int k = 0; k < 300; ++k) {
    const double t0 = 0.04 + k * h, t1 = t0 + h;
    volume += 0.5 * h * (ExcessFlow(gas, t0) + ExcessFlow(gas, t1) - 2.0 * background_flow);
  }
  EXPECT_NEAR(volume, 0.01 * (15.0 - 1.3) * 0.1, 1e-12 * 0.0137);
}

TEST(GasInflowRamp, ZeroRampIsTheInstantSwitch) {
  const GasPhase gas(RampOptions(0.0));
  EXPECT_DOUBLE_EQ(gas.InflowSuperficialVelocity(0, 0.0), 1.3);
  EXPECT_DOUBLE_EQ(gas.InflowSuperficialVelocity(10, 0.0499), 1.3);
  EXPECT_DOUBLE_EQ(gas.InflowSuperficialVelocity(10, 0.05), 15.0);
  EXPECT_DOUBLE_EQ(gas.InflowSuperficialVelocity(10, 0.1501), 1.3);
}

TEST(GasInflowRamp, NegativeRampIsRefusedByName) {
  std::string why;
  EXPECT_FALSE(RampOptions(-1e-3).IsValid(&why));
  EXPECT_NE(why.find("inflow_ramp_s"), std::string::npos) << why;
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
