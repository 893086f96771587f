// draglab/workflows/pipeline.h: the product's main job end to end, from nothing to a published
// law (`draglab pipeline`, `./run.sh`):
//
//   campaign spec -> LBM units (campaign/) -> dataset (drag_db/) -> Ceres fit of Eq. 6 with the
//   NLopt check (fitter/) -> new law version, published -> report -> regression check of the
//   published version on the registered consumer scenes (workflows/regress.h).
//
// A spec with [dataset] extend_with adds a shipped dataset's points outside the campaign's grid
// (extend_dataset) before the fit: the quick preset measures phi <= 0.4, Re <= 25 in minutes and
// takes the standard dataset's denser and faster points, so the law it publishes covers the beds.
//
// Re-running is cheap and safe: the campaign resumes (finished units are kept), the dataset is
// identified by its content hash, and a fit that gives a law identical to the latest published
// version of the name (same content hash, same dataset) reuses it instead of adding a version.
// Relative differences are |F_law/F_ref - 1| on the canonical drag-only F at the dataset's
// (phi, Re) points (Re superficial, diameter based).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "draglab/campaign/campaign.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/drag_db/law.h"
#include "draglab/fitter/fit.h"
#include "draglab/workflows/messages.h"
#include "draglab/workflows/regress.h"

namespace draglab {
namespace workflows {

/// What the pipeline runs and where its results go.
struct PipelineOptions {
  std::string db_path;    ///< The database (created and seeded if missing).
  std::string spec_path;  ///< The campaign spec (TOML); see preset_spec_path().
  std::string law_name;   ///< "": eq6_<campaign name>.
  std::string out_dir;    ///< Report folder; "": out/<campaign name>.
  int jobs = 0;           ///< Parallel LBM units, 0: the number of cores.
  bool report = true;     ///< Write the report (figures need /usr/bin/python3 + matplotlib).
  bool regress = true;    ///< Run the regression check of the published law.
  /// The check's scene (registered if new); "": the registered scenes, and the shipped quick
  /// scene registered when there is none.
  std::string regress_scene;
  bool quiet = false;  ///< The report script's own messages off.
};

/// The spec file of a preset ("quick", "standard", "paper"): in the source tree's data/, else
/// under the installed share/draglab. Throws Error(kInvalidArgument) naming both places.
std::string preset_spec_path(const std::string& preset);

/// Progress of the long stages, for a progress line.
struct PipelineProgress {
  std::function<void(std::int64_t finished, std::int64_t total, const std::string& line)>
      campaign;                           ///< Per LBM unit (campaign::RunCampaignOptions).
  workflows::RegressProgress regression;  ///< Per consumer run of the check.
  std::function<void()> stage_done;       ///< After each of the two (ends a progress line).
};

/// One law over the dataset's points: relative differences from the data and from bvk2007@1.
struct PipelineComparison {
  std::string law;
  double rms_vs_data = 0.0, max_vs_data = 0.0;
  double rms_vs_bvk2007 = 0.0, max_vs_bvk2007 = 0.0;  ///< 0 when bvk2007@1 is not stored
};

/// What the pipeline did.
struct PipelineSummary {
  campaign::CampaignStatus campaign;
  std::string spec_name;
  Dataset dataset;  ///< What the law is fitted to: the campaign's, extended if the spec says so.
  /// With the spec's [dataset] extend_with: the campaign's own dataset, the extension's id and
  /// file, and how many of its points (outside the grid's box) joined. Empty / 0 without.
  std::string campaign_dataset_id;
  std::string extension_id, extension_source;
  std::size_t extension_points = 0;
  DatasetBox grid_box;
  LawRecord law;  ///< The published version (new, or the identical one reused).
  fitter::FitResult fit;
  int cv_folds = 0;
  std::vector<PipelineComparison> comparison;  ///< The fit, Eq. 6 as printed, bvk2007, Ergun.
  std::string report_path;                     ///< "" without a report (or when it failed).
  std::string out_dir;
  std::string db_path;
  bool checked = false;          ///< The regression check ran.
  bool regress_skipped = false;  ///< It was not asked for.
  workflows::RegressSummary check;
  double campaign_s = 0.0, wall_s = 0.0;

  /// The command line's --json object.
  nlohmann::json ToJson() const;
  /// One line: campaign, points, the law published, its RMS error.
  std::string BriefReport() const;
  /// The fitted coefficients with 95 % intervals, what the data do not determine, the NLopt and
  /// constraint checks, the comparison table, what was stored, the regression check.
  std::string FullReport() const;
};

/// Runs the pipeline. Bad input (an invalid spec or law name, an unreadable check scene) is
/// refused before the campaign (draglab::Error, bad input); a report that fails is a warning
/// (the law is stored). The regression check's moved predictions are in summary.check (the
/// caller decides the exit code).
PipelineSummary run_pipeline(const PipelineOptions& options, const Messages& messages = {},
                             const PipelineProgress& progress = {});

}  // namespace workflows
}  // namespace draglab
