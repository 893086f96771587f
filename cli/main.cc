// draglab: command line of the drag-law toolkit.
//
// Sample runs:
//   draglab law list
//   draglab law eval bvk2007 --phi 0.3 --re 50
//   draglab law eval tang2015@1 --grid --json
//   draglab law diff bvk2007 tang2015
//   draglab law export bvk2007@1 --format fortran -o bvk2007.f90
//   draglab law compare
//   draglab pack --phi 0.4 --n 1000 --seed 7 --out packing.h5
//   draglab pack stats packing.h5 --json
//   draglab db info --db my.db
//   draglab lbm run --array sc --phi 0.125 --d 16 --re 0 --json
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <regex>

#include <fmt/core.h>

#include "cli/cli_context.h"
#include "drag_db_version.h"
#include "draglab/error.h"
#include "draglab/mpi/world.h"

namespace draglab {
namespace cli {

std::unique_ptr<Database> CliContext::open_database(bool read_only) const {
  const std::string path = resolved_db_path();
  // A shared, installed database the user cannot write (the file, or its directory, where SQLite
  // keeps its -wal and -shm files): read it read-only rather than fail, and say so once
  // (commands that write then fail with a clear message from the database).
  if (!read_only && ::access(path.c_str(), F_OK) == 0) {
    const std::size_t slash = path.find_last_of('/');
    const std::string dir =
        slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
    const bool file_writable = ::access(path.c_str(), W_OK) == 0;
    const bool dir_writable = ::access(dir.c_str(), W_OK) == 0;
    if (!file_writable || !dir_writable) {
      read_only = true;
      info("note: database '" + path + "' opened read-only (" +
           (file_writable ? "its directory '" + dir + "' is" : "the file is") +
           " not writable for this user): commands that change it will fail");
    }
  }
  DatabaseOptions options;
  options.read_only = read_only;
  options.create_if_missing = !read_only;
  return std::make_unique<Database>(path, options);
}

void CliContext::info(const std::string& message) const {
  if (!quiet) std::cerr << message << '\n';
}

void CliContext::warn(const std::string& message) const {
  std::cerr << "warning: " << message << '\n';
}

void CliContext::print_json(const nlohmann::json& j) const { std::cout << j.dump(2) << '\n'; }

/// Every number option of `app` and its subcommands names a word, NaN or an infinity as what it
/// is, before its own range check: a range check would call "abc" out of range, and options whose
/// "not given" is NaN would read a typed NaN as missing.
void require_finite_numbers(CLI::App* app) {
  for (CLI::Option* option : app->get_options()) {
    const std::string type = option->get_type_name();
    if (type.rfind("FLOAT", 0) != 0 && type.rfind("INT", 0) != 0 && type.rfind("UINT", 0) != 0) {
      continue;
    }
    // The allowed range, where the option's help gives one ("..., [4, 512]").
    const std::string help = option->get_description();
    std::smatch range;
    const std::string allowed =
        std::regex_search(
            help, range,
            std::regex(R"([\[(]\s*-?[0-9.][0-9.eE+^-]*\s*,\s*-?[0-9.][-0-9.eE+^ ]*[\])])"))
            ? " (allowed: " + range.str() + ")"
            : std::string();
    option->transform(CLI::Validator(
        [allowed](std::string& text) -> std::string {
          errno = 0;
          char* end = nullptr;
          const double x = std::strtod(text.c_str(), &end);
          if (text.empty() || end == text.c_str() || *end != '\0') {
            return "'" + text + "' is not a number" + allowed;
          }
          if (std::isnan(x)) return text + " is not a number (NaN)" + allowed;
          if (std::isinf(x)) return text + " is not a finite number" + allowed;
          return std::string();
        },
        ""));
  }
  for (CLI::App* sub : app->get_subcommands([](CLI::App*) { return true; })) {
    require_finite_numbers(sub);
  }
}

}  // namespace cli
}  // namespace draglab

int main(int argc, char** argv) {
  using draglab::cli::CliContext;
  namespace mpi = draglab::mpi;
  // MPI starts only when an MPI launcher (mpirun, srun) started this process.
  std::unique_ptr<mpi::Session> mpi_session;
  try {
    mpi_session = std::make_unique<mpi::Session>(&argc, &argv);
  } catch (const draglab::Error& e) {
    std::cerr << "error: " << e.what() << '\n';
    return e.is_bad_input() ? 2 : 1;
  }
  CliContext ctx;
  CLI::App app{
      "draglab: drag closures for dense gas-solid fluidized beds.\n"
      "Versioned drag laws (SQLite) with provenance, evaluated in the canonical convention\n"
      "F = F_d/(3 pi mu d eps u) (drag only), Re = rho eps d u/mu, beta d^2/mu = 18 phi eps F.",
      "draglab"};
  app.set_version_flag("--version", std::string("draglab ") + draglab::kDragDbVersion);
  app.fallthrough();  // global options (--db, --json, --quiet) are accepted after subcommands
  app.add_option("--db", ctx.db_path,
                 "Database file (default: $DRAGLAB_DB, else ./draglab.db; created and seeded "
                 "with the literature library on first use)")
      ->check(CLI::Validator(
          [](std::string& path) -> std::string {
            return path.empty() ? "empty path (give a database file, or leave --db out "
                                  "for $DRAGLAB_DB, else ./draglab.db)"
                                : std::string();
          },
          "FILE"));
  app.add_flag("--json", ctx.json, "Machine-readable JSON results on stdout");
  app.add_flag("-q,--quiet", ctx.quiet, "No informational messages on stderr");
  app.require_subcommand(1);
  app.footer(
      "Examples:\n"
      "  draglab law list\n"
      "  draglab law eval bvk2007 --phi 0.3 --re 50\n"
      "  draglab law compare\n"
      "  draglab pack --phi 0.4 --n 1000 --out packing.h5\n"
      "  draglab db info\n"
      "  draglab lbm run --array sc --phi 0.125 --d 16 --re 0\n"
      "Exit codes: 0 success, 1 failure, 2 bad input.");

  draglab::cli::add_law_commands(app, ctx);
  draglab::cli::add_pack_commands(app, ctx);
  draglab::cli::add_db_commands(app, ctx);
  draglab::cli::add_lbm_commands(app, ctx);
  draglab::cli::add_campaign_commands(app, ctx);
  draglab::cli::add_fit_commands(app, ctx);
  draglab::cli::add_report_commands(app, ctx);
  draglab::cli::add_pipeline_commands(app, ctx);
  draglab::cli::add_scene_commands(app, ctx);
  draglab::cli::add_sensitivity_commands(app, ctx);
  draglab::cli::add_regress_commands(app, ctx);
  draglab::cli::require_finite_numbers(&app);

  // CLI11 answers a mistyped command with "A subcommand is required": name it instead.
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--db") {
      ++i;
      continue;
    }
    if (arg.empty() || arg[0] == '-') continue;
    bool known = false;
    std::string names;
    for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
      known = known || sub->get_name() == arg;
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::cerr << "error: unknown command '" << arg << "' (commands: " << names
                << "; draglab --help)\n";
      return 2;
    }
    // The same one level down, for the command groups that need a subcommand (law, lbm, ...).
    CLI::App* group = app.get_subcommand(arg);
    if (group->get_require_subcommand_min() > 0 && i + 1 < argc && argv[i + 1][0] != '-') {
      const std::string word = argv[i + 1];
      std::string subcommands;
      bool found = false;
      for (const CLI::App* sub : group->get_subcommands([](CLI::App*) { return true; })) {
        found = found || sub->get_name() == word;
        subcommands += (subcommands.empty() ? "" : ", ") + sub->get_name();
      }
      if (!found) {
        std::cerr << "error: unknown " << arg << " subcommand '" << word
                  << "' (subcommands: " << subcommands << "; draglab " << arg << " --help)\n";
        return 2;
      }
    }
    break;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "error: " << e.what() << "\nRun with --help for more information.\n";
    return 2;
  }

  // Ranks other than 0 print only their own failures, with their rank.
  const std::string who =
      mpi::size() > 1 && mpi::rank() != 0 ? "rank " + std::to_string(mpi::rank()) + ": " : "";
  if (mpi::size() > 1 && !ctx.runs_on_ranks) {
    if (mpi::rank() == 0) {
      std::cerr << "error: started with " << mpi::size()
                << " MPI ranks, but only `draglab campaign run` and `draglab lbm run` run across "
                   "ranks: start this "
                   "command without mpirun/srun (or with one rank)\n";
    }
    return 2;
  }
  try {
    if (ctx.action) ctx.action();
    return 0;
  } catch (const mpi::EndedByRank0& e) {
    return e.exit_code();  // rank 0 printed why
  } catch (const draglab::cli::UsageError& e) {
    std::cerr << "error: " << who << e.what() << '\n';
    return 2;
  } catch (const draglab::Error& e) {
    std::cerr << "error: " << who << e.what() << '\n';
    return e.is_bad_input() ? 2 : 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << who << e.what() << '\n';
    return 1;
  }
}
