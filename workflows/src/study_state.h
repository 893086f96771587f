// study_state.h: the state folder of a law study (SensitivityOptions::state_directory): each
// finished run and each prepared realization, kept as the study goes, so that a study stopped
// part-way (a kill, a session's end) goes on where it was when run again.
//
// A run is kept as a JSON file holding everything the study takes from it (the run's record, the
// law's U_mf and background, the packing it started from, the snapshot of a law's first run)
// with every number written to round trip, so a resumed study's results are those of an
// uninterrupted one, bit for bit; a realization in the model's own file
// (BedModel::SaveRealization). Each file is named by a label and a hash of its key: what
// identifies it (the scene's text, seed, grid, law, time step, duration, t_ref). A key that
// changed finds no file and the run is done again; files are written atomically, so a kill
// leaves the previous state.
#pragma once

#include <memory>
#include <string>

#include "draglab/consumers/bed_model.h"
#include "draglab/consumers/scene.h"
#include "draglab/workflows/sensitivity.h"

namespace draglab {
namespace workflows {
namespace detail {

/// What the study takes from one run (see the file comment).
struct StoredRun {
  SensitivityRun run;
  SensitivityPacking packing;  ///< The realization it started from (seed 0: none).
  double umf_m_s = 0.0;
  double background_m_s = 0.0;
  std::string background_mode;
  bool has_snapshot = false;
  consumers::BedSnapshot snapshot;
};

/// The key of one run: the scene's text and every value a study may change in it or around it.
std::string run_key(const consumers::BedModel& model, const consumers::Scene& scene,
                    const std::string& law, const consumers::BedRunOptions& run);
/// The key of one realization: the model, the scene's text, the seed and the law it was prepared
/// with.
std::string realization_key(const consumers::BedModel& model, const consumers::Scene& scene,
                            const std::string& law);

class StudyState {
 public:
  /// Empty: no state is kept (every call does nothing, Load* find nothing).
  explicit StudyState(std::string directory);
  bool enabled() const { return !directory_.empty(); }

  /// The run kept under `key`; false when there is none (or it cannot be read).
  bool LoadRun(const std::string& label, const std::string& key, StoredRun* out) const;
  /// Keeps the run under `key`. Throws Error(kIo) when the file cannot be written.
  void SaveRun(const std::string& label, const std::string& key, const StoredRun& run) const;

  /// The realization kept under `key`, or null.
  std::shared_ptr<const consumers::BedRealization> LoadRealization(const consumers::BedModel& model,
                                                                   const std::string& label,
                                                                   const std::string& key) const;
  /// Keeps it, where the model can (BedModel::SaveRealization).
  void SaveRealization(const consumers::BedModel& model, const std::string& label,
                       const std::string& key, const consumers::BedRealization& realization) const;
  /// Where the realization under `key` keeps its checkpoint while it is prepared
  /// (RealizeOptions::checkpoint_path), the folder created; "" when no state is kept.
  std::string RealizationCheckpoint(const std::string& label, const std::string& key) const;

 private:
  std::string Path(const std::string& label, const std::string& key,
                   const std::string& extension) const;
  std::string directory_;
};

}  // namespace detail
}  // namespace workflows
}  // namespace draglab
