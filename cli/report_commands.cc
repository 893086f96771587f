// `draglab report`: figures and a Markdown summary of a drag dataset against fitted and
// literature laws. The work is workflows::write_report (draglab/workflows/report.h); this file
// only maps the options and prints. docs/report.md describes the figures and the bundle.
#include <iostream>
#include <memory>
#include <string>

#include "cli/cli_context.h"
#include "draglab/core/files.h"
#include "draglab/workflows/report.h"

namespace draglab {
namespace cli {

void add_report_commands(CLI::App& app, CliContext& ctx) {
  auto c = std::make_shared<workflows::ReportOptions>();
  CLI::App* report = app.add_subcommand(
      "report",
      "Figures and a Markdown summary of a dataset against fitted and literature laws: the seed's "
      "Fig. 3, parity, residuals against phi and Re, and the campaign's work-precision");
  auto* dataset = report->add_option("--dataset", c->dataset_id,
                                     "Stored dataset id or hash prefix (draglab campaign ...)");
  auto* data = report->add_option("--data", c->data_csv,
                                  "CSV dataset instead (columns phi,re,F,F_uncertainty; "
                                  "docs/report.md)");
  dataset->excludes(data);
  report->add_option("--law", c->laws, "Fitted law version to show, NAME@V (repeatable)");
  report
      ->add_option("--compare", c->compare,
                   std::string("Comparison laws, comma separated (default ") +
                       workflows::ReportOptions::kDefaultComparisons +
                       "; a missing default is skipped with a warning)")
      ->each([c](const std::string&) { c->compare_given = true; });
  report->add_option("--campaign", c->campaign,
                     "Campaign (id or name) whose units give the work-precision figure "
                     "(default: the dataset's campaign)");
  report->add_option("--out", c->out_dir, "Output directory (created)")->required();
  report->footer(
      "Examples:\n"
      "  draglab report --dataset 3f2a9c1b7d0e --law vdh2004_fit@1 --out report/\n"
      "  draglab report --data mydata.csv --compare bvk2007,tang2015 --out report/ --json\n"
      "Writes OUT/report_bundle.json, then /usr/bin/python3 scripts/draglab_report.py (Debian "
      "package python3-matplotlib) draws fig3_seed.png, parity.png, residuals.png, "
      "work_precision.png and report.md. F is the canonical drag-only F = F_d/(3 pi mu d eps u), "
      "Re = rho eps d u/mu.\nExit codes: 0 success, 1 failure, 2 bad input.");
  report->callback([&ctx, c]() {
    ctx.action = [&ctx, c]() {
      c->quiet = ctx.quiet;
      const std::string invalid = c->Invalid();
      if (!invalid.empty()) throw UsageError(invalid);
      // A CSV report needs the database only for the laws; it is read, never written, except
      // that a missing database is created and seeded with the literature library.
      const bool exists = core::file_exists(ctx.resolved_db_path());
      auto db = ctx.open_database(/*read_only=*/exists);
      const workflows::ReportSummary summary = workflows::write_report(*db, *c, ctx.messages());
      if (ctx.json) {
        ctx.print_json(summary.ToJson());
      } else {
        std::cout << summary.FullReport();
      }
    };
  });
}

}  // namespace cli
}  // namespace draglab
