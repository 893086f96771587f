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

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "averaging.h"
#include "checkpoint.h"
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

/// What read_checkpoint_progress reports of a stopped run is that run's own record.
void expect_progress_is_the_runs(const CheckpointProgress& p, const RunResult& run) {
  EXPECT_EQ(p.step, run.steps);
  // The checkpoint holds the checks made before it was written (a Stokes run's record may add
  // the check its stop makes).
  ASSERT_GT(p.checks, 0u);
  ASSERT_LE(p.checks, run.history.size());
  ASSERT_GE(p.checks + 1, run.history.size());
  const HistoryPoint& last = run.history[p.checks - 1];
  EXPECT_EQ(p.F, last.F);
  EXPECT_EQ(p.re, last.re);
  const std::size_t first = p.checks - std::min<std::size_t>(p.checks, 40);
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (std::size_t k = first; k < p.checks; ++k) {
    lo = std::min(lo, run.history[k].F);
    hi = std::max(hi, run.history[k].F);
  }
  EXPECT_EQ(p.recent_F_min, lo);
  EXPECT_EQ(p.recent_F_max, hi);
  EXPECT_EQ(p.force_adjustments, run.force_adjustments);
  EXPECT_FALSE(p.averaging);
  EXPECT_NE(p.BriefReport().find("step " + std::to_string(run.steps)), std::string::npos)
      << p.BriefReport();
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
  expect_progress_is_the_runs(read_checkpoint_progress(o.checkpoint), first);
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

// request_stop (what SIGTERM and SIGINT call in `campaign run` and `lbm run --checkpoint`) ends a
// run at its next check with its checkpoint saved there, between the periodic saves; the same
// run then goes on to the bits of one that never stopped. The stop is asked from inside the run
// (its progress callback, once the main run steps), as a signal handler would.
TEST(Checkpoint, RunStoppedOnRequestSavesItsStateAndGoesOnToTheSameBits) {
  const ScArray sc = make_sc_array(0.3, 16.0);
  const RunOptions plain = options_for(20.0, Collision::kTrt);
  const RunResult reference = run(sc.grid, sc.packing.phi(), plain);
  ASSERT_TRUE(reference.converged) << format_run(reference);

  RunOptions o = plain;
  o.checkpoint = temporary_path("stop");
  o.checkpoint_interval = 1e6;  // no periodic save: only the stop writes the file
  std::remove(o.checkpoint.c_str());
  const ProgressCallback stop_once_stepping = [](double, const std::string& status) {
    if (status.rfind("step ", 0) == 0) request_stop();
  };
  const RunResult stopped = lbm::run(sc.grid, sc.packing.phi(), o, stop_once_stepping);
  clear_stop_request();
  ASSERT_TRUE(stopped.stopped_on_request) << format_run(stopped);
  EXPECT_FALSE(stopped.converged);
  EXPECT_NE(stopped.diagnosis.find("stopped on request at step"), std::string::npos)
      << stopped.diagnosis;
  ASSERT_GT(stopped.steps, 0);
  ASSERT_LT(stopped.steps, reference.steps) << "the run ended before the stop was asked";
  ASSERT_TRUE(exists(o.checkpoint));
  EXPECT_EQ(read_checkpoint_progress(o.checkpoint).step, stopped.steps);

  const RunResult resumed = run(sc.grid, sc.packing.phi(), o);
  ASSERT_TRUE(resumed.converged) << format_run(resumed);
  EXPECT_EQ(resumed.resumed_from_step, stopped.steps);
  // The first part's time comes back with the checkpoint (the run's cost is both parts').
  EXPECT_GT(resumed.earlier_parts_wall_s, 0.0);
  EXPECT_LE(resumed.earlier_parts_wall_s, stopped.wall_s);
  EXPECT_EQ(reference.earlier_parts_wall_s, 0.0);
  EXPECT_EQ(resumed.F, reference.F);  // the same bits
  EXPECT_EQ(resumed.steps, reference.steps);
  EXPECT_FALSE(exists(o.checkpoint));
}

// An averaging run's progress: the time mean so far is the engine's own (MSER start-up, blocking
// standard error) of the samples the checkpoint carries. A synthetic state: a start-up transient
// then a stationary, correlated signal.
TEST(Checkpoint, ProgressOfAnAveragingRunIsTheTimeMeanOfItsSamples) {
  LoopState state;
  state.step = 5000;
  state.averaging = true;
  state.averaging_start = 3000;
  state.adjustments = 4;
  for (int k = 0; k < 200; ++k) {
    const double F = 70.0 + 5.0 * std::exp(-k / 10.0) + std::sin(0.7 * k) + 0.3 * std::cos(2.3 * k);
    state.series_F.push_back(F);
    state.history.push_back({3000 + 10 * k, F, 300.0 + std::sin(0.5 * k), 1e-3});
  }
  std::vector<double> populations(64, 0.25);
  const std::string path = temporary_path("averaging");
  save_run_checkpoint(path, {{"case", "synthetic"}}, state,
                      {{"populations", populations.data(), populations.size() * sizeof(double)}});
  const CheckpointProgress p = read_checkpoint_progress(path);
  std::remove(path.c_str());
  const TimeAverage expected = time_average(state.series_F);
  EXPECT_TRUE(p.averaging);
  EXPECT_EQ(p.averaging_start, 3000);
  EXPECT_EQ(p.averaged_samples, 200u);
  EXPECT_EQ(p.force_adjustments, 4);
  EXPECT_GT(expected.truncated, 0u) << "the transient is discarded";
  EXPECT_EQ(p.F_average, expected.mean);
  EXPECT_EQ(p.F_average_standard_error, expected.standard_error);
  EXPECT_NEAR(p.F_average, 70.0, 0.1);
  EXPECT_NEAR(p.recent_re_min, 299.0, 0.05);
  EXPECT_NEAR(p.recent_re_max, 301.0, 0.05);
  EXPECT_NE(p.BriefReport().find("averaging since step 3000, 200 samples"), std::string::npos)
      << p.BriefReport();
  EXPECT_THROW(read_checkpoint_progress(path), Error);  // gone: kNotFound
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
