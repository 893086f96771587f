// workflows/src/studies.cc: see draglab/workflows/studies.h.
#include "draglab/workflows/studies.h"

#include <cstdio>
#include <memory>
#include <set>
#include <stdexcept>
#include <vector>

#include <fmt/core.h>

#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/error.h"
#include "draglab/workflows/bed_results.h"
#include "draglab/workflows/scripts.h"

namespace draglab {
namespace workflows {
namespace {

const char* const kFigureScript = "draglab_fig4.py";

/// Loads laws with the scene's range policy, each warning (draft, retracted) said once.
workflows::LawLoader law_loader(const Database& db, const consumers::Scene& scene,
                                const Messages& messages) {
  const RangePolicy policy = range_policy_from_string(scene.range_policy);
  auto warned = std::make_shared<std::set<std::string>>();
  return [&db, policy, warned, messages](const std::string& reference) {
    std::string warning;
    std::shared_ptr<const Law> law = db.load(reference, policy, &warning);
    if (!warning.empty() && warned->insert(reference).second) messages.warn(warning);
    return law;
  };
}

/// Makes the output folder at the first progress report: after the runner has checked every
/// law and grid (bad input leaves nothing behind), before the first run (a bad folder fails at
/// once, not after the runs).
StudyProgress making_folder(const std::string& out_dir, const StudyProgress& progress) {
  auto made = std::make_shared<bool>(false);
  return [out_dir, progress, made](double fraction, const std::string& stage) {
    if (!*made) {
      core::make_directories(out_dir, "--out");
      *made = true;
    }
    if (progress) progress(fraction, stage);
  };
}

/// Draws `figure` from `bundle` with the figure script.
void draw(const std::string& bundle, const StudyOutput& output, const std::string& figure) {
  std::remove(figure.c_str());  // so a stale figure is never taken for a new one
  std::vector<std::string> args = {bundle, output.out_dir};
  if (!output.beside.empty()) args.insert(args.end(), {"--beside", output.beside});
  if (output.quiet) args.push_back("--quiet");
  run_figure_script(kFigureScript, args, bundle, figure);
}

}  // namespace

nlohmann::json SensitivityStudy::ToJson(const consumers::Scene& scene,
                                        const std::string& out_dir) const {
  nlohmann::json j = sensitivity_bundle_json(scene, summary, /*with_snapshots=*/false);
  j["out_dir"] = out_dir;
  j["data"] = bundle_path;
  j["figure"] = figure_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(figure_path);
  j["figure_beside"] = beside_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(beside_path);
  return j;
}

nlohmann::json WorkPrecisionStudy::ToJson(const std::string& out_dir) const {
  nlohmann::json j = work_precision_bundle_json(result);
  j["out_dir"] = out_dir;
  j["data"] = bundle_path;
  j["figure"] = figure_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(figure_path);
  return j;
}

SensitivityStudy run_sensitivity_study(const Database& db, const consumers::Scene& scene,
                                       const workflows::SensitivityOptions& options,
                                       const StudyOutput& output, const Messages& messages,
                                       const StudyProgress& progress) {
  if (!output.beside.empty()) {
    if (!output.figure) {
      throw Error(ErrorCode::kInvalidArgument, "--beside draws a figure: drop --no-figure");
    }
    if (!core::file_exists(output.beside)) {
      throw Error(ErrorCode::kInvalidArgument,
                  "--beside: '" + output.beside +
                      "' does not exist (give another study's sensitivity.json)");
    }
  }
  SensitivityStudy study;
  study.summary = workflows::run_sensitivity(scene, law_loader(db, scene, messages), options,
                                             making_folder(output.out_dir, progress));
  const workflows::SensitivitySummary& s = study.summary;
  // A model with headline numbers has no bubble at t_ref (no snapshot, nothing for the figure
  // script to draw): its numbers are the result.
  const bool headline = s.has_headline();
  if (headline && !output.beside.empty()) {
    throw Error(ErrorCode::kInvalidArgument,
                fmt::format("--beside: the {} model reports headline numbers, not a bubble at "
                            "t_ref, so there is no Fig. 5 to draw; rerun without --beside",
                            scene.solver));
  }
  for (const auto& lr : s.laws) {
    if (headline) break;
    int not_reached = 0;
    for (const auto& r : lr.runs) not_reached += r.reached_t_ref ? 0 : 1;
    if (not_reached > 0) {
      messages.warn(
          fmt::format("{}: {} of {} runs ended before t_ref (the duration is rounded to whole "
                      "gas steps): raise [time] duration_s a little past jet.start_s + "
                      "t_ref_s",
                      lr.law, not_reached, lr.runs.size()));
    }
    if (lr.bubbles_found < static_cast<int>(lr.runs.size())) {
      messages.warn(
          fmt::format("{}: no bubble at t_ref in {} of {} runs; D = 0 is taken for them, so "
                      "its mean and uncertainty mix bubble and no bubble",
                      lr.law, lr.runs.size() - lr.bubbles_found, lr.runs.size()));
    }
  }
  core::make_directories(output.out_dir, "--out");
  study.bundle_path = output.out_dir + "/sensitivity.json";
  core::write_file_atomically(
      study.bundle_path, sensitivity_bundle_json(scene, s, /*with_snapshots=*/true).dump(1) + "\n",
      "sensitivity data");
  if (output.figure && !headline) {
    const std::string figure = output.out_dir + "/fig4.png";
    draw(study.bundle_path, output, figure);
    study.figure_path = figure;
    if (!output.beside.empty()) {
      const std::string fig5 = output.out_dir + "/fig5.png";
      if (!core::file_exists(fig5)) {
        throw std::runtime_error("the figure script wrote no " + fig5 + " (--beside " +
                                 output.beside + ")");
      }
      study.beside_path = fig5;
    }
  }
  return study;
}

WorkPrecisionStudy run_work_precision_study(const Database& db, const consumers::Scene& scene,
                                            const workflows::WorkPrecisionOptions& options,
                                            const StudyOutput& output, const Messages& messages,
                                            const StudyProgress& progress) {
  if (!output.beside.empty()) {
    throw Error(ErrorCode::kInvalidArgument, "--beside is for the law study, not --work-precision");
  }
  WorkPrecisionStudy study;
  study.result = workflows::run_work_precision(scene, law_loader(db, scene, messages), options,
                                               making_folder(output.out_dir, progress));
  const workflows::WorkPrecisionResult& w = study.result;
  // A model with headline numbers has no bubble at t_ref and no figure of this study.
  const bool headline = w.has_headline();
  for (const auto& r : w.rows) {
    if (!r.bubble_found && !headline) {
      messages.warn(fmt::format(
          "grid {}x{}, {} {}: no bubble at t_ref (D = 0){}", r.cells_x, r.cells_y,
          w.time_resolution_name, core::format_number(r.time_resolution, 4),
          r.reached_t_ref ? ""
                          : ": the run ended before t_ref (duration rounded to whole gas "
                            "steps; raise [time] duration_s)"));
    }
  }
  core::make_directories(output.out_dir, "--out");
  study.bundle_path = output.out_dir + "/work_precision.json";
  core::write_file_atomically(study.bundle_path, work_precision_bundle_json(w).dump(1) + "\n",
                              "work-precision data");
  if (output.figure && !headline) {
    const std::string figure = output.out_dir + "/work_precision.png";
    draw(study.bundle_path, output, figure);
    study.figure_path = figure;
  }
  return study;
}

}  // namespace workflows
}  // namespace draglab
