// DEM checkpoints (consumers/dem.h: DemSystem::SaveState / LoadState, SettleOptions::
// checkpoint_path): a study stopped part-way must go on as if it had never stopped.
//
// Set-up: 400 glass-like spheres (d = 2.5 mm, k_n = 1000 N/m, e = 0.5, friction 0.3, so the
// tangential spring history matters) in a 10 d x 10 d periodic column, as in
// dem_neighbor_list_test.cc. References:
//  a. a system restored from a state saved after 200 of 400 stirred steps, stepped 200 more, and
//     the system that was never saved agree bitwise (positions, velocities, spins, time and
//     contacts): the state holds everything the steps read, so nothing may differ;
//  b. a settling stopped after 30 kinetic-energy checks (a kill, here an exception thrown from its
//     progress callback) and run again with the same checkpoint file ends in the bed of a
//     settling never stopped, bitwise, having gone on from the checkpoint (resumed_at_s > 0); the
//     file is gone once the bed is at rest; a checkpoint of another settling (another seed) is
//     not taken up;
//  c. damaged states (cut short, another file's bytes, bytes appended) are refused.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "draglab/consumers/dem.h"
#include "draglab/error.h"
#include "support/temp_dir.h"

namespace draglab {
namespace consumers {
namespace {

constexpr double kD = 2.5e-3;

DemOptions ColumnOptions() {
  DemOptions o;
  o.box_min = {0.0, 0.0, 0.0};
  o.box_max = {10 * kD, 0.06, 10 * kD};
  o.periodic = {true, false, true};
  o.normal_stiffness = 1000.0;
  o.restitution = o.wall_restitution = 0.5;
  o.friction = o.wall_friction = 0.3;
  return o;
}

SettleOptions ColumnSettling(std::uint64_t seed) {
  SettleOptions s;
  s.n = 400;
  s.diameter = kD;
  s.seed = seed;
  s.kinetic_energy_tolerance = 1e-4;
  return s;
}

/// The settled column stirred with random velocities of up to 0.3 m/s (contacts open and close).
Particles StirredColumn() {
  Particles p = settle_particles(ColumnOptions(), ColumnSettling(11)).particles;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.vx[i] = u(rng);
    p.vy[i] = u(rng);
    p.vz[i] = u(rng);
  }
  return p;
}

void ExpectBitwiseEqual(const Particles& a, const Particles& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.id[i], b.id[i]) << i;
    for (auto m : {&Particles::x, &Particles::y, &Particles::z, &Particles::vx, &Particles::vy,
                   &Particles::vz, &Particles::wx, &Particles::wy, &Particles::wz}) {
      ASSERT_EQ((a.*m)[i], (b.*m)[i]) << "particle " << i;
    }
  }
}

TEST(DemCheckpoint, ARestoredSystemContinuesBitForBit) {
  DemSystem never_saved(ColumnOptions(), StirredColumn());
  for (int s = 0; s < 200; ++s) never_saved.step();
  const std::string state = never_saved.SaveState();
  for (int s = 0; s < 200; ++s) never_saved.step();
  const std::unique_ptr<DemSystem> restored = DemSystem::LoadState(ColumnOptions(), state);
  EXPECT_EQ(restored->steps(), 200);
  for (int s = 0; s < 200; ++s) restored->step();
  ExpectBitwiseEqual(never_saved.particles(), restored->particles());
  EXPECT_EQ(restored->time(), never_saved.time());
  EXPECT_EQ(restored->contact_count(), never_saved.contact_count());
  EXPECT_EQ(restored->kinetic_energy(), never_saved.kinetic_energy());
  EXPECT_EQ(restored->energy().elastic, never_saved.energy().elastic);
}

TEST(DemCheckpoint, DamagedStatesAreRefused) {
  DemSystem dem(ColumnOptions(), StirredColumn());
  const std::string state = dem.SaveState();
  EXPECT_THROW(DemSystem::LoadState(ColumnOptions(), state.substr(0, state.size() / 2)), Error);
  EXPECT_THROW(DemSystem::LoadState(ColumnOptions(), "draglab dpm packing 1\n" + state), Error);
  EXPECT_THROW(DemSystem::LoadState(ColumnOptions(), state + "x"), Error);
  EXPECT_NO_THROW(DemSystem::LoadState(ColumnOptions(), state));
}

struct Stopped {};  // what the "kill" throws

TEST(DemSettleCheckpoint, AStoppedSettlingGoesOnToTheSameBed) {
  const SettleResult whole = settle_particles(ColumnOptions(), ColumnSettling(11));
  test::TempDir dir;
  SettleOptions keep = ColumnSettling(11);
  keep.checkpoint_path = dir.file("settle.checkpoint");
  keep.checkpoint_interval_s = 0.0;  // at every check, so the stop leaves a recent one
  int checks = 0;
  EXPECT_THROW(settle_particles(ColumnOptions(), keep,
                                [&](double, const std::string&) {
                                  if (++checks == 30) throw Stopped();
                                }),
               Stopped);
  ASSERT_TRUE(std::filesystem::exists(keep.checkpoint_path));
  // Another settling (seed 12) given a copy of it does not take it up.
  SettleOptions other = ColumnSettling(12);
  other.checkpoint_path = dir.file("other.checkpoint");
  {
    std::ifstream in(keep.checkpoint_path, std::ios::binary);
    std::ofstream out(other.checkpoint_path, std::ios::binary);
    out << in.rdbuf();
  }
  EXPECT_EQ(settle_particles(ColumnOptions(), other).resumed_at_s, 0.0);

  const SettleResult resumed = settle_particles(ColumnOptions(), keep);
  EXPECT_GT(resumed.resumed_at_s, 0.0);
  EXPECT_EQ(resumed.steps, whole.steps);
  EXPECT_EQ(resumed.simulated_time_s, whole.simulated_time_s);
  ExpectBitwiseEqual(whole.particles, resumed.particles);
  EXPECT_FALSE(std::filesystem::exists(keep.checkpoint_path));  // at rest: it has served
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
