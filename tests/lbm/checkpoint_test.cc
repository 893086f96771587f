// RunOptions::checkpoint: a run stopped (by max_steps here, by a kill in practice) and run again
// goes on from its checkpoint to the very bits the uninterrupted run gives.
//
// Reference: the same run without a checkpoint, on one thread (the thread count sets the order
// of the force sums). Set-ups, each a few tenths of a second:
//  - simple-cubic array, phi 0.3, d 10, Re 20: TRT with the target-Re controller (force
//    adjustments, the convergence window);
//  - phi 0.3, d 8, Re 40 with the automatic operator: rr with TRT's wall, whose per-link
//    correction state the checkpoint must carry;
//  - phi 0.2, d 10, Stokes: the Stokes-mode rescaling of the state at each check.
// Each is stopped twice before converging, once off the check schedule (an odd max_steps), and
// must then give F, the step count and the history bit for bit, and remove its checkpoint; a
// finite-Re run goes on with the velocity plan (the measured kappa) its first part made.
// Refusals: another run's checkpoint (a different Re), a file that is not a checkpoint and a
// truncated one are Error(kInvalidArgument) naming the file, before any stepping.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "draglab/error.h"
#include "validation_support.h"

namespace draglab {
namespace lbm {
namespace validation {
namespace {

std::string temporary_path(const std::string& name) {
  return ::testing::TempDir() + "draglab_checkpoint_" + std::to_string(::getpid()) + "_" + name;
}

bool exists(const std::string& path) { return std::ifstream(path).good(); }

RunOptions options_for(double re, Collision collision) {
  RunOptions o;
  o.collision = collision;
  o.re = re;
  o.threads = 1;
  o.throw_on_failure = false;
  return o;
}

void expect_resumed_run_is_bit_identical(double phi, double d, double re, Collision collision,
                                         const std::string& name) {
  SCOPED_TRACE(name);
  const ScArray sc = make_sc_array(phi, d);
  const RunOptions plain = options_for(re, collision);
  const RunResult reference = run(sc.grid, sc.packing.phi(), plain);
  ASSERT_TRUE(reference.converged) << format_run(reference);
  ASSERT_GT(reference.steps, 400);

  RunOptions o = plain;
  o.checkpoint = temporary_path(name);
  std::remove(o.checkpoint.c_str());
  // Stopped at about a third (on an even step) and two thirds (an odd limit: off the schedule).
  o.max_steps = (reference.steps / 3) / 2 * 2;
  const RunResult first = run(sc.grid, sc.packing.phi(), o);
  EXPECT_FALSE(first.converged);
  EXPECT_NE(first.diagnosis.find("holds step"), std::string::npos) << first.diagnosis;
  EXPECT_TRUE(exists(o.checkpoint));
  o.max_steps = 2 * reference.steps / 3 + 1;
  const RunResult second = run(sc.grid, sc.packing.phi(), o);
  EXPECT_FALSE(second.converged);
  EXPECT_EQ(second.resumed_from_step, first.steps);
  o.max_steps = plain.max_steps;
  const RunResult last = run(sc.grid, sc.packing.phi(), o);
  ASSERT_TRUE(last.converged) << format_run(last);
  EXPECT_EQ(last.resumed_from_step, second.steps);
  EXPECT_EQ(last.F, reference.F);  // the same bits
  EXPECT_EQ(last.re, reference.re);
  EXPECT_EQ(last.steps, reference.steps);
  EXPECT_EQ(last.collision, reference.collision);
  // A resumed run plans with the kappa its first part measured (no second Stokes run).
  EXPECT_EQ(last.pore_speed_ratio, reference.pore_speed_ratio);
  EXPECT_EQ(last.pore_speed_ratio_measured, reference.pore_speed_ratio_measured);
  ASSERT_EQ(last.history.size(), reference.history.size());
  for (std::size_t k = 0; k < last.history.size(); ++k) {
    EXPECT_EQ(last.history[k].step, reference.history[k].step);
    EXPECT_EQ(last.history[k].F, reference.history[k].F);
  }
  EXPECT_FALSE(exists(o.checkpoint)) << "a converged run removes its checkpoint";
}

TEST(Checkpoint, ResumedTrtRunAtFiniteReIsBitIdentical) {
  expect_resumed_run_is_bit_identical(0.3, 10.0, 20.0, Collision::kTrt, "trt");
}

TEST(Checkpoint, ResumedRrRunKeepsItsWallCorrectionState) {
  expect_resumed_run_is_bit_identical(0.3, 8.0, 40.0, Collision::kAuto, "rr");
}

TEST(Checkpoint, ResumedStokesRunIsBitIdentical) {
  expect_resumed_run_is_bit_identical(0.2, 10.0, 0.0, Collision::kTrt, "stokes");
}

TEST(Checkpoint, AnotherRunsDamagedOrForeignFileIsRefused) {
  const ScArray sc = make_sc_array(0.3, 10.0);
  RunOptions o = options_for(20.0, Collision::kTrt);
  o.checkpoint = temporary_path("refusals");
  std::remove(o.checkpoint.c_str());
  o.max_steps = 500;
  const RunResult stopped = run(sc.grid, sc.packing.phi(), o);
  ASSERT_TRUE(exists(o.checkpoint)) << format_run(stopped);

  auto refusal = [&](const RunOptions& options) {
    try {
      run(sc.grid, sc.packing.phi(), options);
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
      return std::string(e.what());
    }
    return std::string("no refusal");
  };
  // Another run: a different target Re.
  RunOptions other = o;
  other.re = 25.0;
  const std::string foreign = refusal(other);
  EXPECT_NE(foreign.find("written by another run"), std::string::npos) << foreign;
  EXPECT_NE(foreign.find("re is 20"), std::string::npos) << foreign;
  EXPECT_NE(foreign.find("remedy"), std::string::npos) << foreign;
  EXPECT_TRUE(exists(o.checkpoint)) << "a refused file is left for the user";

  // Truncated: the header is intact, the state is not.
  std::string bytes;
  {
    std::ifstream in(o.checkpoint, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  {
    std::ofstream out(o.checkpoint, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  const std::string truncated = refusal(o);
  EXPECT_NE(truncated.find("not a complete draglab checkpoint"), std::string::npos) << truncated;

  // One flipped byte in the populations: the checksum.
  {
    std::string damaged = bytes;
    damaged[damaged.size() - 100] ^= 0x5a;
    std::ofstream out(o.checkpoint, std::ios::binary | std::ios::trunc);
    out.write(damaged.data(), static_cast<std::streamsize>(damaged.size()));
  }
  const std::string flipped = refusal(o);
  EXPECT_NE(flipped.find("checksum"), std::string::npos) << flipped;

  // Not a checkpoint at all.
  {
    std::ofstream out(o.checkpoint, std::ios::trunc);
    out << "phi,re,F\n0.3,20,9.25\n";
  }
  const std::string text = refusal(o);
  EXPECT_NE(text.find("not a draglab checkpoint"), std::string::npos) << text;
  std::remove(o.checkpoint.c_str());
}

}  // namespace
}  // namespace validation
}  // namespace lbm
}  // namespace draglab
