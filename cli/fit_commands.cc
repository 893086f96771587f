// `draglab fit` (Ceres least-squares / NLopt minimax refit of a law form to a dataset or a CSV
// file, optionally stored as a new draft law version) and `draglab law publish NAME@V`.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>

#include <fmt/core.h>

#include "cli/cli_context.h"
#include "draglab/core/text.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"
#include "draglab/fitter/fit.h"

namespace draglab {
namespace cli {
namespace {

// The literature laws every comparison shows as published.
constexpr const char* kComparedLaws[] = {"vdh2004@1", "bvk2007@1", "tang2015@1", "tenneti2011@1",
                                         "hill_koch_ladd@1"};

struct FitArgs {
  std::string dataset_id;
  std::string data_csv;
  std::string form = "vdh2004";
  std::string free;
  std::string set;
  std::string objective = "lsq";
  std::string loss = "none";
  double loss_scale = 2.0;
  int cv = 5;
  int bootstrap = 0;
  bool no_global = false;
  std::string select = "auto";
  bool compare_forms = false;
  std::string publish;
};

/// Larger than any coefficient of a drag law's form: beyond it a --set value is a typing error
/// (and the fit's arithmetic overflows).
constexpr double kMaxCoefficient = 1e6;

std::vector<std::pair<std::string, double>> parse_assignments(const std::string& text) {
  std::vector<std::pair<std::string, double>> out;
  if (text.empty()) return out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw UsageError("--set: '" + item + "' is not name=value (e.g. --set n=4,A=180)");
    }
    const std::vector<double> value =
        core::parse_number_list(item.substr(eq + 1), "--set " + item.substr(0, eq));
    if (!std::isfinite(value[0]) || std::abs(value[0]) > kMaxCoefficient) {
      throw UsageError(fmt::format("--set {}: {} is outside [-{:g}, {:g}] (a law coefficient)",
                                   item.substr(0, eq), item.substr(eq + 1), kMaxCoefficient,
                                   kMaxCoefficient));
    }
    out.push_back({item.substr(0, eq), value[0]});
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

struct Comparison {
  std::string law;
  double rms = 0.0, max = 0.0;
};

Comparison compare(const std::string& label, const std::vector<double>& relative) {
  Comparison c{label, 0.0, 0.0};
  for (double r : relative) {
    c.rms += r * r;
    c.max = std::max(c.max, std::fabs(r));
  }
  c.rms = relative.empty() ? 0.0 : std::sqrt(c.rms / relative.size());
  return c;
}

void run_fit(const CliContext& ctx, const FitArgs& args) {
  // Everything about the input is checked before anything is opened for writing.
  if (args.dataset_id.empty() == args.data_csv.empty()) {
    throw UsageError("give exactly one of --dataset ID (stored) or --data FILE.csv");
  }
  if (!args.publish.empty()) {
    try {
      check_law_name(args.publish);
    } catch (const Error& e) {
      throw UsageError(std::string("--publish: ") + e.what());
    }
  }
  fitter::FitOptions options;
  options.form = args.form;
  if (!args.free.empty()) options.free = core::split_list(args.free, "--free", "a,b,c0,c1,c2");
  options.initial = parse_assignments(args.set);
  options.objective = fitter::objective_from_string(args.objective);
  options.loss = fitter::robust_loss_from_string(args.loss);
  options.loss_scale = args.loss_scale;
  options.cv_folds = args.cv;
  options.bootstrap = args.bootstrap;
  options.global_check = !args.no_global;
  options.selection = fitter::selection_from_string(args.select);
  std::string why;
  if (!options.IsValid(&why)) {
    // Name the command-line options rather than the FitOptions fields.
    for (const auto& [field, flag] : {std::pair<std::string, std::string>{"cv_folds", "--cv"},
                                      {"loss_scale", "--loss-scale"},
                                      {"bootstrap", "--bootstrap"}}) {
      if (why.rfind(field, 0) == 0) why = flag + why.substr(field.size());
    }
    throw UsageError(why);
  }

  const bool publishing = !args.publish.empty();
  std::unique_ptr<Database> db;
  Dataset dataset;
  if (!args.dataset_id.empty()) {
    db = ctx.open_database(!publishing);
    dataset = load_dataset(*db, args.dataset_id);
  } else {
    dataset = read_dataset_csv(args.data_csv);
    if (dataset.hash.empty()) dataset.hash = dataset_hash(dataset.points);
    if (dataset.id.empty()) dataset.id = dataset.hash.substr(0, 12);
  }
  std::vector<fitter::FitPoint> points;
  bool per_species = false;
  for (const DatasetPoint& p : dataset.points) {
    points.push_back({p.phi, p.re, p.F, p.F_uncertainty, {}});
    if (p.y > 0.0) {
      points.back().extra = {p.y};
      per_species = true;
    }
  }
  if (per_species && args.compare_forms) {
    throw UsageError(
        "--compare-forms refits the monodisperse forms; this dataset holds size classes (y): "
        "the fit's table compares it with the polydisperse literature laws");
  }
  ctx.info(fmt::format("fitting {} to {} points of dataset {} ({})", options.form, points.size(),
                       dataset.id, dataset.name));
  const fitter::FitResult fit = fitter::fit_law(points, options);

  // Literature versions beside the fit, over the same points (evaluated as written, also outside
  // their validity boxes). Like every command, this creates and seeds the database on first use.
  if (!db) {
    try {
      db = ctx.open_database();
    } catch (const Error& e) {
      if (publishing) throw;
      ctx.warn(std::string("no comparison with the literature laws: ") + e.what());
    }
  }
  std::vector<Comparison> comparisons;
  comparisons.push_back(compare("fit (" + fit.form + ")", [&] {
    std::vector<double> rel;
    for (const fitter::FitPoint& p : points) {
      rel.push_back(
          find_law_form(fit.form).F(p.phi, p.re, p.extra_data(), fit.values.data()) / p.F - 1.0);
    }
    return rel;
  }()));
  if (db) {
    const std::vector<const char*> refs =
        per_species ? std::vector<const char*>{"bvk2007_poly@1", "vdh2005_poly@1", "hys2010@1"}
                    : std::vector<const char*>{"vdh2004@1", "bvk2007@1", "ergun@1"};
    for (const char* ref : refs) {
      try {
        const auto law = db->load(ref, RangePolicy::kExtrapolate);
        comparisons.push_back(compare(ref, fitter::relative_errors(*law, points)));
      } catch (const Error& e) {
        ctx.warn(fmt::format("comparison: {} skipped ({})", ref, e.what()));
      }
    }
  }

  std::vector<fitter::FormComparisonRow> form_rows;
  if (args.compare_forms) {
    std::vector<std::shared_ptr<Law>> loaded;
    std::vector<const Law*> published;
    if (db) {
      for (const char* ref : kComparedLaws) {
        try {
          loaded.push_back(db->load(ref, RangePolicy::kExtrapolate));
          published.push_back(loaded.back().get());
        } catch (const Error& e) {
          ctx.warn(fmt::format("form comparison: {} skipped ({})", ref, e.what()));
        }
      }
    }
    ctx.info("comparing forms (4 refits with subset selection, " +
             std::to_string(published.size()) + " laws as published)");
    form_rows = fitter::compare_forms(points, published, args.cv, options.seed);
  }

  LawRecord stored;
  if (publishing && fit.constraints_checked && !fit.constraints_satisfied) {
    // A law that breaks the physics it must obey (F > 0, ...) is not stored, not even as a draft.
    throw std::runtime_error(
        "--publish " + args.publish +
        ": nothing stored: the fitted law violates its constraints (" + fit.constraint_report +
        ")" +
        (args.set.empty() ? std::string()
                          : "; the values fixed by --set " + args.set + " may be the cause") +
        "; free more parameters, fix them at other values (--set), or fit more data");
  }
  if (publishing) {
    if (args.dataset_id.empty()) {
      // The CSV's points become a stored (immutable, deduplicated) dataset so that the law's
      // provenance can be followed.
      dataset = store_dataset(*db, dataset);
    }
    stored = db->add_draft(
        fitter::fitted_record(fit, options, args.publish, dataset.id, dataset.hash, points));
  }

  if (ctx.json) {
    nlohmann::json params = nlohmann::json::object(), ci95 = nlohmann::json::object();
    nlohmann::json free = nlohmann::json::array(), boot = nlohmann::json::object();
    for (std::size_t k = 0; k < fit.names.size(); ++k) {
      params[fit.names[k]] = fit.values[k];
      ci95[fit.names[k]] = {fit.ci95_low[k], fit.ci95_high[k]};
      if (fit.is_free[k]) free.push_back(fit.names[k]);
      if (!fit.bootstrap_stddev.empty() && fit.is_free[k])
        boot[fit.names[k]] = fit.bootstrap_stddev[k];
    }
    nlohmann::json comparison = nlohmann::json::array();
    for (const Comparison& c : comparisons) {
      comparison.push_back({{"law", c.law}, {"rms_rel_err", c.rms}, {"max_rel_err", c.max}});
    }
    nlohmann::json out = {
        {"law", publishing ? nlohmann::json(stored.name) : nlohmann::json(nullptr)},
        {"version", publishing ? nlohmann::json(stored.version) : nlohmann::json(nullptr)},
        {"hash", publishing ? nlohmann::json(stored.content_hash) : nlohmann::json(nullptr)},
        {"form", fit.form},
        {"dataset", dataset.id},
        {"objective", fitter::to_string(options.objective)},
        {"num_points", fit.num_points},
        {"params", params},
        {"ci95", ci95},
        {"free", free},
        {"rms_rel_err", fit.rms_rel_err},
        {"max_rel_err", fit.max_rel_err},
        {"cv_rms_rel_err",
         fit.cv_rms_rel_err >= 0 ? nlohmann::json(fit.cv_rms_rel_err) : nlohmann::json(nullptr)},
        {"chi2", fit.chi2},
        {"chi2_per_dof", fit.chi2_per_dof},
        {"dof", fit.dof},
        {"global_checked", fit.global_checked},
        {"global_agrees", fit.global_agrees},
        {"global_best_cost", fit.global_best_cost},
        {"constraints_satisfied", fit.constraints_satisfied},
        {"constraint_report", fit.constraint_report},
        {"bootstrap_stddev", boot},
        {"notes", fit.notes},
        {"comparison", comparison}};
    out["selection"] = {{"performed", fit.selection.performed},
                        {"requested", fit.selection.requested},
                        {"undetermined", fit.selection.undetermined},
                        {"least_separable", fit.selection.inseparable},
                        {"chosen", fit.selection.chosen}};
    if (args.compare_forms)
      out["form_comparison"] = nlohmann::json::parse(fitter::form_comparison_json_text(form_rows));
    ctx.print_json(out);
  } else {
    std::cout << fit.FullReport();
    std::cout << fmt::format("\nRelative difference from the {} data points:\n", points.size());
    std::cout << fmt::format("  {:<22} {:>10} {:>10}\n", "law", "rms", "max");
    for (const Comparison& c : comparisons) {
      std::cout << fmt::format("  {:<22} {:>9.2f}% {:>9.2f}%\n", c.law, 100 * c.rms, 100 * c.max);
    }
    if (args.compare_forms) {
      std::cout << "\nForms compared on the same points (refits with subset selection; CV = "
                   "k-fold cross-validation):\n"
                << fitter::form_comparison_markdown(form_rows);
    }
  }
  if (publishing) {
    ctx.info(fmt::format("stored draft {} (hash {}); freeze it with: draglab law publish {}",
                         stored.reference(), stored.content_hash.substr(0, 12),
                         stored.reference()));
  }
}

void run_publish(const CliContext& ctx, const std::string& ref) {
  LawReference law;
  if (!LawReference::TryParse(ref, &law) || ref.find('@') == std::string::npos ||
      law.version_number() < 0) {
    throw UsageError(
        "law publish needs NAME@VERSION with a version number (e.g. vdh2004_refit@1), "
        "got '" +
        ref + "'");
  }
  auto db = ctx.open_database();
  const LawRecord out = db->publish(law.name, law.version_number());
  if (ctx.json) {
    ctx.print_json({{"law", out.name},
                    {"version", out.version},
                    {"status", to_string(out.status)},
                    {"hash", out.content_hash}});
    return;
  }
  std::cout << fmt::format("{} published (immutable from now on; hash {})\n", out.reference(),
                           out.content_hash.substr(0, 12));
}

}  // namespace

void add_fit_commands(CLI::App& app, CliContext& ctx) {
  auto args = std::make_shared<FitArgs>();
  CLI::App* cmd = app.add_subcommand(
      "fit",
      "Fit a law form (default: the seed's Eq. 6, vdh2004) to drag data with Ceres; NLopt "
      "confirms the optimum and fits minimax; optionally store it as a new draft version");
  cmd->add_option("--dataset", args->dataset_id, "Stored dataset id (or hash prefix) in --db");
  cmd->add_option("--data", args->data_csv,
                  "CSV file with columns phi,re,F,F_uncertainty (canonical drag-only F)");
  cmd->add_option("--form", args->form, "Law form to fit (" + law_form_keys() + ")")
      ->capture_default_str();
  cmd->add_option("--free", args->free,
                  "Parameters to fit, comma separated (vdh2004 default: a,b,c0,c1,c2 = "
                  "k0,k1,c10,c11,c12; add n to free the eps exponent; other forms: all)");
  cmd->add_option("--set", args->set, "Fixed / starting values, e.g. --set n=4,A=180");
  cmd->add_option("--objective", args->objective, "lsq (weighted least squares) or minimax")
      ->capture_default_str();
  cmd->add_option("--loss", args->loss, "Robust loss: none, huber, cauchy")->capture_default_str();
  cmd->add_option("--loss-scale", args->loss_scale, "Robust loss scale in units of sigma (> 0)")
      ->capture_default_str();
  cmd->add_option("--cv", args->cv, "k-fold cross-validation (0 = off)")->capture_default_str();
  cmd->add_option("--bootstrap", args->bootstrap, "Bootstrap resamples (0 = off)")
      ->capture_default_str();
  cmd->add_flag("--no-global", args->no_global, "Skip the NLopt multi-start global check");
  cmd->add_option("--select", args->select,
                  "auto: when the data do not determine every free parameter (95 % interval "
                  "wider than the value), fit the largest determined subset (ties: lowest AICc) "
                  "and print the candidates; off: fit the free set as given")
      ->check(CLI::IsMember({"auto", "off"}))
      ->capture_default_str();
  cmd->add_flag("--compare-forms", args->compare_forms,
                "Also compare Eq. 6 (n = 3 and n free), bvk2007 and tang2015 refitted, and the "
                "literature laws as published, on the same points (rms, max, CV error, AICc)");
  cmd->add_option("--publish", args->publish,
                  "Store the fit as a new draft version of law NAME (freeze it with "
                  "`draglab law publish NAME@V`)");
  cmd->footer(
      "Examples:\n"
      "  draglab fit --dataset 3fa2c01b9e77 --publish vdh2004_refit\n"
      "  draglab fit --data mydata.csv --free a,n,b,c0,c1,c2 --bootstrap 200\n"
      "  draglab fit --dataset 3fa2 --form bvk2007 --objective minimax --json\n"
      "  draglab fit --dataset 3fa2 --compare-forms\n"
      "  draglab law publish vdh2004_refit@1");
  cmd->callback([&ctx, args] { ctx.action = [&ctx, args] { run_fit(ctx, *args); }; });

  CLI::App* law = app.get_subcommand("law");
  auto ref = std::make_shared<std::string>();
  auto* publish = law->add_subcommand("publish", "Freeze a draft version: published, immutable");
  publish->add_option("law", *ref, "NAME@VERSION")->required();
  publish->footer("Example:\n  draglab law publish vdh2004_refit@1");
  publish->callback([&ctx, ref] { ctx.action = [&ctx, ref] { run_publish(ctx, *ref); }; });
}

}  // namespace cli
}  // namespace draglab
