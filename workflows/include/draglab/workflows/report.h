// draglab/workflows/report.h: the report of a drag dataset against fitted and literature laws.
//
// Every number is computed here with the same Law objects solvers use (range policy
// `extrapolate`, the points outside each law's validity box flagged): the curves of the seed's
// Fig. 3, the Stokes curve, F at the data points, the relative differences |F_law/F_data - 1|
// and their maximum and RMS, the refitted forms, the campaign's units for the work-precision
// figure. They are written to OUT/report_bundle.json; scripts/draglab_report.py only draws from
// it (fig3_seed.png, parity.png, residuals.png, work_precision.png, report.md). docs/report.md
// describes the figures and the bundle. F is the canonical drag-only
// F = F_d / (3 pi mu d eps u) and Re = rho eps d u / mu (superficial, diameter based).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "draglab/drag_db/database.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/workflows/messages.h"

namespace draglab {
namespace workflows {

/// What a report shows and where it goes.
struct ReportOptions {
  /// Eq. 6 as printed, the classic packed-bed law, the LBM law the seed compares with and the
  /// published final form of the seed group's law.
  static constexpr const char* kDefaultComparisons = "vdh2004@1,ergun@1,hill_koch_ladd@1,bvk2007@1";

  std::string dataset_id;         ///< A stored dataset (id or hash prefix), or
  std::string data_csv;           ///< a dataset CSV file (exactly one of the two).
  std::vector<std::string> laws;  ///< Fitted laws, NAME@V; each must load.
  std::string compare;            ///< Comparison laws, comma separated.
  bool compare_given = false;     ///< false: kDefaultComparisons, a missing one skipped.
  std::string campaign;           ///< Campaign of the work-precision figure ("": the dataset's).
  std::string out_dir;            ///< Output folder (created).
  bool render_figures = true;     ///< false: the bundle only (no Python).
  bool quiet = false;             ///< The figure script's own messages off.

  /// Empty if the options can make a report; otherwise what is wrong, naming the option.
  std::string Invalid() const;
};

/// How one law compares with the dataset's points.
struct ReportLawStatistics {
  std::string label;           ///< e.g. "vdh2004@1 (Eq. 6 as printed)"
  std::string reference;       ///< NAME@V
  std::string role;            ///< "fit" or "reference"
  double max_rel_diff = 0.0;   ///< max |F_law/F_data - 1| over the points it evaluates (NaN: none)
  double rms_rel_diff = 0.0;   ///< RMS of the same (NaN: none)
  int n_evaluated = 0;         ///< points with a finite F_law
  int n_outside_validity = 0;  ///< points outside the law's validity box (extrapolated)
};

/// What a report wrote.
struct ReportSummary {
  std::string out_dir, report_path, bundle_path;
  std::vector<std::string> figures;  ///< the PNGs the script wrote
  std::vector<ReportLawStatistics> laws;
  bool has_units = false;  ///< the work-precision figure has campaign units
  nlohmann::json bundle;   ///< the bundle as written

  /// {out_dir, report, figures, bundle} (the command line's --json).
  nlohmann::json ToJson() const;
  /// One line: laws compared, worst RMS difference, where the report is.
  std::string BriefReport() const;
  /// The law table (max and RMS relative difference, points outside validity) and the files.
  std::string FullReport() const;
};

/// The bundle entry of one law against `dataset`: its record (parameters, 95 % intervals,
/// validity box), Re curves per phi of the data, the Stokes curve, F at the points and the
/// statistics, returned in `stats` too.
nlohmann::json report_law_json(const Law& law, const std::string& role, const std::string& label,
                               const Dataset& dataset, ReportLawStatistics* stats);

/// Writes the report: checks every input first (draglab::Error, kInvalidArgument / kNotFound:
/// bad input), then the bundle, then the figures. Throws std::runtime_error when the figure
/// script fails; the bundle is kept.
ReportSummary write_report(const Database& db, const ReportOptions& options,
                           const Messages& messages = {});

}  // namespace workflows
}  // namespace draglab
