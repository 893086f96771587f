// How `draglab regress` and the end of `draglab pipeline` report a regression check
// (workflows/regress.h): the progress line and the exit code (the JSON form is
// workflows::regress_json). Defined in regress_commands.cc.
#pragma once

#include "cli/cli_context.h"
#include "cli/progress.h"
#include "draglab/workflows/regress.h"

namespace draglab {
namespace cli {

/// Progress of a check on a ProgressLine: "run k/n scene law: stage" and the fraction of the run.
workflows::RegressProgress regress_progress(ProgressLine& line);

/// Warns (stderr) about failed runs; throws std::runtime_error (exit 1) naming every prediction
/// that moved. Call after the report is printed.
void finish_regress(const CliContext& ctx, const workflows::RegressSummary& summary);

}  // namespace cli
}  // namespace draglab
