// draglab/workflows/studies.h: the bed-model studies of `draglab sensitivity`, run, saved and
// drawn: a scene per drag law with the bubble diameter's numerical uncertainty (the seed's
// Fig. 4, and Fig. 5 beside another study), and the work-precision study of one law (bubble
// diameter, or a model's headline numbers, against grid and time step, with run times).
//
// The runs are workflows::run_sensitivity / run_work_precision; this layer loads the laws from
// the database (warning once per retracted or draft version), creates the output folder only
// once every input has been checked, warns about runs that ended before t_ref or found no
// bubble, writes the bundle (bed_results.h) atomically and draws the figure from it
// (scripts/draglab_fig4.py; a model with headline numbers has no figure of these studies).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "draglab/consumers/scene.h"
#include "draglab/drag_db/database.h"
#include "draglab/workflows/messages.h"
#include "draglab/workflows/sensitivity.h"

namespace draglab {
namespace workflows {

/// Where a study's results go.
struct StudyOutput {
  std::string out_dir;  ///< Created when the first run starts (after every input is checked).
  bool figure = true;   ///< Draw the PNG (needs /usr/bin/python3 with matplotlib).
  /// Another law study's sensitivity.json: its panels are drawn above this one's (fig5.png).
  std::string beside;
  bool quiet = false;  ///< The figure script's own messages off.
};

/// A law study as written.
struct SensitivityStudy {
  workflows::SensitivitySummary summary;
  std::string bundle_path;  ///< out_dir/sensitivity.json
  std::string figure_path;  ///< out_dir/fig4.png; "" when not drawn
  std::string beside_path;  ///< out_dir/fig5.png; "" when not drawn
  /// The bundle without snapshots, with out_dir, data, figure and figure_beside.
  nlohmann::json ToJson(const consumers::Scene& scene, const std::string& out_dir) const;
};

/// A work-precision study as written.
struct WorkPrecisionStudy {
  workflows::WorkPrecisionResult result;
  std::string bundle_path;  ///< out_dir/work_precision.json
  std::string figure_path;  ///< out_dir/work_precision.png; "" when not drawn
  /// The bundle with out_dir, data and figure.
  nlohmann::json ToJson(const std::string& out_dir) const;
};

/// Progress of a study: its fraction done and the stage now running (a settling, a run).
using StudyProgress = workflows::SensitivityProgress;

/// Runs, writes and draws a law study. Bad input (draglab::Error, bad input) is found before the
/// first run and leaves no folder; a figure that cannot be drawn is a runtime failure
/// (std::runtime_error) after the bundle is written.
SensitivityStudy run_sensitivity_study(const Database& db, const consumers::Scene& scene,
                                       const workflows::SensitivityOptions& options,
                                       const StudyOutput& output, const Messages& messages = {},
                                       const StudyProgress& progress = nullptr);

/// The same for a work-precision study (`beside` does not apply).
WorkPrecisionStudy run_work_precision_study(const Database& db, const consumers::Scene& scene,
                                            const workflows::WorkPrecisionOptions& options,
                                            const StudyOutput& output,
                                            const Messages& messages = {},
                                            const StudyProgress& progress = nullptr);

}  // namespace workflows
}  // namespace draglab
