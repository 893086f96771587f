// How `draglab regress` and the end of `draglab pipeline` report a regression check
// (consumers/regress.h): the JSON form, the progress line and the exit code. Defined in
// regress_commands.cc.
#pragma once

#include <nlohmann/json.hpp>

#include "cli/cli_context.h"
#include "cli/progress.h"
#include "draglab/consumers/regress.h"

namespace draglab {
namespace cli {

/// {"moved", "ok", "failed", "baselines_registered", "no_baseline", "runs", "wall_s",
///  "entries": [{scene, scene_hash, law, baseline, outcome, ran, result_id, baseline_result_id,
///  tolerances, metrics, headline: {name: value} (DBM; {} otherwise), comparisons: [{metric,
///  baseline, new, delta, tolerance, moved}] (a headline number's metric is its name; a value
///  that is not finite is null), error, warnings}]}.
nlohmann::json regress_json(const consumers::RegressSummary& summary);

/// Progress of a check on a ProgressLine: "run k/n scene law: stage" and the fraction of the run.
consumers::RegressProgress regress_progress(ProgressLine& line);

/// Warns (stderr) about failed runs; throws std::runtime_error (exit 1) naming every prediction
/// that moved. Call after the report is printed.
void finish_regress(const CliContext& ctx, const consumers::RegressSummary& summary);

}  // namespace cli
}  // namespace draglab
