// checkpoint.h: the file a long run resumes from (RunOptions::checkpoint).
//
// Layout: a text line naming the format, a JSON header (what must match for a run to resume
// from the file, and the run's loop state), the solver's state as named binary sections written
// from and read back into the solver's own storage (no copy of the populations), and a 64-bit
// FNV-1a checksum of everything before it, so that a damaged file is refused rather than
// resumed. Written through core::write_file_atomically: a kill during the write leaves the
// previous checkpoint.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "averaging.h"
#include "draglab/lbm/lbm.h"

namespace draglab {
namespace lbm {

/// A named byte range of a solver's state (SolverBase::state).
struct StateSection {
  const char* name;
  void* data;
  std::size_t bytes;
};

/// Writes the checkpoint at `path`; `header` is JSON text. Throws draglab::Error (kIo, or
/// kInvalidArgument for a path that cannot be written) naming `field`.
void write_checkpoint(const std::string& path, const std::string& header,
                      const std::vector<StateSection>& sections, const std::string& field);

/// The JSON header of the checkpoint at `path`; throws Error(kInvalidArgument) naming `field`
/// if the file is not a draglab checkpoint.
std::string read_checkpoint_header(const std::string& path, const std::string& field);

/// Reads the sections of the checkpoint at `path` into `sections`: the same names, sizes and
/// order as were written (else Error(kInvalidArgument)), and checks the checksum (a damaged
/// file: Error(kInvalidArgument); the destinations then hold part of it).
void read_checkpoint_sections(const std::string& path, const std::vector<StateSection>& sections,
                              const std::string& field);

/// What the run loop (driver.cc) carries from one check to the next: with the solver's state,
/// all a resumed run needs to go on as the uninterrupted run would have, bit for bit.
struct LoopState {
  std::int64_t step = 0;
  double stepping_s = 0.0;  ///< Seconds spent stepping (for MFLUPS).
  double force = 0.0;       ///< The body force now.
  int adjustments = 0;
  ReControlState re_control;
  bool averaging = false;
  int averaging_restarts = 0;
  std::int64_t averaging_start = 0;
  std::vector<std::pair<double, double>> window;  ///< (F, U) at the checks since the last change.
  std::vector<double> series_F, series_re;
  std::vector<std::vector<double>> series_body;  ///< Per body, the averaging samples.
  double last_log_force = 0.0, last_log_re = 0.0;
  double relative_change = 0.0, balance = 0.0;
  bool mach_warned = false;
  double F_mean = 0.0, U = 0.0, re_lattice = 0.0, mach = 0.0, mach_max = 0.0;
  double last_max_speed = 0.0;
  std::int64_t last_max_node = -1, last_check_step = 0;
  std::vector<HistoryPoint> history;
  std::vector<std::string> warnings;  ///< Those the loop added.
  /// The pore-speed ratio kappa a Stokes run measured for the velocity plan (0: none), so that
  /// a resumed run plans with it instead of running that Stokes run again.
  double measured_pore_speed_ratio = 0.0;
  /// Wall seconds of the run up to its last save, over every part (a resumed run's cost is that
  /// of its earlier parts plus its own).
  double elapsed_s = 0.0;
};

/// What must be equal for a run to resume from a checkpoint, as (name, value) text pairs (the
/// grid's hash, the lattice, the operator, tau, the force, the tolerances, ...).
using Fingerprint = std::vector<std::pair<std::string, std::string>>;

/// Writes a run's checkpoint: the fingerprint, the code version, the loop state and the
/// solver's sections.
void save_run_checkpoint(const std::string& path, const Fingerprint& fingerprint,
                         const LoopState& state, const std::vector<StateSection>& sections);

/// Reads a run's checkpoint into `state` and the solver's sections, after checking it was
/// written by the same run (else Error(kInvalidArgument) naming the first entry that differs,
/// with both values, before anything is read into the solver). Returns the code version that
/// wrote it.
std::string load_run_checkpoint(const std::string& path, const Fingerprint& fingerprint,
                                LoopState* state, const std::vector<StateSection>& sections);

/// The measured pore-speed ratio a checkpoint's run planned with, 0 if it has none or the file
/// is missing or unreadable (the run then reports what is wrong with it).
double checkpoint_pore_speed_ratio(const std::string& path);

/// 64-bit FNV-1a of `bytes` bytes, continuing from `seed` (for the grid's hash).
std::uint64_t fnv1a(const void* data, std::size_t bytes,
                    std::uint64_t seed = 1469598103934665603ull);

/// The bits of a double as an integer, and back: JSON keeps them exactly, NaN and infinity too.
std::uint64_t double_bits(double x);
double bits_double(std::uint64_t bits);

}  // namespace lbm
}  // namespace draglab
