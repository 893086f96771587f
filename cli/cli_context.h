// Shared state and helpers of the draglab command line (cli/).
//
// Output discipline: results go to stdout (a table, or JSON with --json), messages to stderr.
// Exit codes: 0 success, 1 failure, 2 bad input (draglab::Error::is_bad_input(), UsageError,
// or a command-line parse error).
#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "draglab/core/text.h"
#include "draglab/drag_db/database.h"
#include "draglab/workflows/messages.h"

namespace draglab {
namespace cli {

/// Bad command-line input detected after parsing (exit code 2).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Options shared by every command, and the command chosen by the parser.
struct CliContext {
  std::string db_path;  ///< --db, else $DRAGLAB_DB, else ./draglab.db.
  bool json = false;    ///< --json: machine-readable results on stdout.
  bool quiet = false;   ///< --quiet: no informational messages on stderr.
  /// The action of the selected subcommand (set by its parse callback, run by main()).
  std::function<void()> action;
  /// Set by the commands that run across MPI ranks (campaign run, lbm run); main() refuses the
  /// others when started with several ranks.
  bool runs_on_ranks = false;

  std::string resolved_db_path() const {
    return db_path.empty() ? Database::default_path() : db_path;
  }
  /// Opens the database (creating and seeding it on first use unless read_only).
  std::unique_ptr<Database> open_database(bool read_only = false) const;
  /// Informational message on stderr (suppressed by --quiet).
  void info(const std::string& message) const;
  /// Warning on stderr (always shown).
  void warn(const std::string& message) const;
  /// info() and warn() for a workflow (draglab/workflows/messages.h).
  workflows::Messages messages() const {
    return {[this](const std::string& m) { info(m); }, [this](const std::string& m) { warn(m); }};
  }
  /// Prints JSON on stdout (indent 2).
  void print_json(const nlohmann::json& j) const;
};

/// Registers `draglab law ...` (law_commands.cc).
void add_law_commands(CLI::App& app, CliContext& ctx);
/// Registers `draglab pack ...` (pack_commands.cc).
void add_pack_commands(CLI::App& app, CliContext& ctx);
/// Registers `draglab db ...` (db_commands.cc).
void add_db_commands(CLI::App& app, CliContext& ctx);
/// Registers `draglab lbm ...` (lbm_commands.cc).
void add_lbm_commands(CLI::App& app, CliContext& ctx);

/// Registers `draglab campaign ...` and `draglab dataset ...` (campaign_commands.cc).
void add_campaign_commands(CLI::App& app, CliContext& ctx);
/// Registers `draglab fit` and `draglab law publish` (fit_commands.cc).
void add_fit_commands(CLI::App& app, CliContext& ctx);
/// Registers `draglab report` (report_commands.cc).
void add_report_commands(CLI::App& app, CliContext& ctx);
/// Registers `draglab pipeline` (pipeline_commands.cc).
void add_pipeline_commands(CLI::App& app, CliContext& ctx);
/// Registers `draglab scene ...` (scene_commands.cc).
void add_scene_commands(CLI::App& app, CliContext& ctx);
/// `draglab sensitivity`: a scene per law, bubble diameter with its numerical uncertainty,
/// the seed's Fig. 4 as a PNG, and its --work-precision study (bubble vs grid and DEM step).
void add_sensitivity_commands(CLI::App& app, CliContext& ctx);
/// `draglab regress`: consumer predictions of changed law versions against stored baselines.
void add_regress_commands(CLI::App& app, CliContext& ctx);

using core::format_number;

}  // namespace cli
}  // namespace draglab
