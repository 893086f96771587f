// cli/report.h: the report of a dataset against fitted and literature laws (report_bundle.json,
// the figures drawn by scripts/draglab_report.py, report.md), callable in-process by `draglab
// report` and by the pipeline.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_context.h"
#include "draglab/drag_db/database.h"

namespace draglab {
namespace cli {

/// What a report shows: a stored dataset (or a CSV file), the fitted laws, the comparison laws
/// (default kDefaultComparisons), the campaign of the work-precision figure, the output folder.
struct ReportRequest {
  std::string dataset_id;
  std::string data_csv;
  std::vector<std::string> laws;
  std::string compare;
  bool compare_given = false;
  std::string campaign;
  std::string out_dir;
};

/// Writes the report into request.out_dir and returns {out_dir, report, figures, bundle}.
/// Throws draglab::Error / UsageError for bad input (exit 2) and std::runtime_error when the
/// renderer fails (the bundle is kept).
nlohmann::json write_report(const CliContext& ctx, const Database& db,
                            const ReportRequest& request);

}  // namespace cli
}  // namespace draglab
