// `draglab pipeline`: the product's main job end to end, from nothing to a published law
// (workflows::run_pipeline, draglab/workflows/pipeline.h; this file maps the options and prints).
//
// Sample runs:
//   draglab pipeline --preset quick                 # what ./run.sh runs (minutes on 2 cores)
//   draglab pipeline --preset standard --jobs 2     # about an hour, Richardson in d
//   draglab pipeline --spec my_campaign.toml --law-name eq6_mine --out out/mine
//
// The pipeline ends with the regression check of the law it published (`draglab regress --law`)
// on the registered scenes: a prediction that moved beyond the baseline's tolerance is printed
// and the pipeline exits 1 (the law stays published).
#include <iostream>
#include <memory>
#include <string>

#include "cli/cli_context.h"
#include "cli/progress.h"
#include "cli/regress_report.h"
#include "draglab/workflows/pipeline.h"

namespace draglab {
namespace cli {
namespace {

struct PipelineArgs {
  std::string preset = "quick";
  std::string spec;
  std::string law_name;
  std::string out_dir;
  int jobs = 0;
  bool no_report = false;
  bool no_regress = false;
  std::string regress_scene;  // --regress-scene FILE (default: the registered scenes)
};

void run_pipeline(const CliContext& ctx, const PipelineArgs& args) {
  workflows::PipelineOptions options;
  options.db_path = ctx.resolved_db_path();
  options.spec_path = args.spec.empty() ? workflows::preset_spec_path(args.preset) : args.spec;
  options.law_name = args.law_name;
  options.out_dir = args.out_dir;
  options.jobs = args.jobs;
  options.report = !args.no_report;
  options.regress = !args.no_regress;
  options.regress_scene = args.regress_scene;
  options.quiet = ctx.quiet;

  // One progress line per long stage: the campaign's units, then the check's runs.
  auto units = std::make_shared<CampaignProgressPrinter>(!ctx.quiet);
  auto runs = std::make_shared<ProgressLine>(!ctx.quiet);
  workflows::PipelineProgress progress;
  progress.campaign = [units](std::int64_t finished, std::int64_t total, const std::string& line) {
    (*units)(finished, total, line);
  };
  progress.regression = regress_progress(*runs);
  progress.stage_done = [units, runs] {
    units->finish();
    runs->finish();
  };
  const workflows::PipelineSummary summary =
      workflows::run_pipeline(options, ctx.messages(), progress);
  if (ctx.json) {
    ctx.print_json(summary.ToJson());
  } else {
    std::cout << summary.FullReport();
  }
  if (summary.checked) finish_regress(ctx, summary.check);
}

}  // namespace

void add_pipeline_commands(CLI::App& app, CliContext& ctx) {
  auto args = std::make_shared<PipelineArgs>();
  auto* cmd = app.add_subcommand(
      "pipeline", "Campaign -> dataset -> fit of Eq. 6 -> published law -> report, in one command");
  cmd->add_option("--preset", args->preset, "Campaign preset: quick, standard or paper")
      ->check(CLI::IsMember({"quick", "standard", "paper"}))
      ->capture_default_str();
  cmd->add_option("--spec", args->spec, "Campaign spec file (TOML) instead of a preset")
      ->check(CLI::ExistingFile);
  cmd->add_option("--law-name", args->law_name,
                  "Name of the fitted law (default eq6_<campaign name>)");
  cmd->add_option("--out", args->out_dir, "Report directory (default out/<campaign name>)");
  cmd->add_option("--jobs", args->jobs, "Parallel LBM units (0 = number of cores)")
      ->check(CLI::Range(0, 1024));
  cmd->add_flag("--no-report", args->no_report, "Skip the figures");
  cmd->add_flag("--no-regress", args->no_regress,
                "Skip the final regression check of the published law");
  cmd->add_option("--regress-scene", args->regress_scene,
                  "Scene (TOML) of the final regression check, registered if new (default: the "
                  "registered scenes; the quick scene if none is)")
      ->check(CLI::ExistingFile);
  cmd->footer(
      "Examples:\n"
      "  draglab pipeline --preset quick\n"
      "  draglab pipeline --preset standard --jobs 2 --out out/standard\n"
      "  draglab pipeline --spec my.toml --law-name eq6_mine --json\n"
      "Re-running resumes the campaign and reuses an identical fitted version. The pipeline "
      "ends with `draglab regress --law` for the published version: exit 1 if a consumer "
      "prediction moved beyond its baseline's tolerance.");
  cmd->callback([&ctx, args] { ctx.action = [&ctx, args] { run_pipeline(ctx, *args); }; });
}

}  // namespace cli
}  // namespace draglab
