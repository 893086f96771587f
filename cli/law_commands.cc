// `draglab law list|show|eval|diff|export|retract|compare`.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>

#include <fmt/core.h>

#include "cli/cli_context.h"
#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/drag_db/export.h"
#include "draglab/error.h"

namespace draglab {
namespace cli {
namespace {

std::string short_hash(const std::string& hash) { return hash.substr(0, 12); }

nlohmann::json record_json(const LawRecord& r) {
  return nlohmann::json::parse(export_law(r, ExportFormat::kJson));
}

/// Values of one evaluation, as printed by `law eval`: F, beta d^2/mu and K all at one point,
/// the point the formula saw (phi_evaluated, re_evaluated: the clamped point under the clamp
/// policy, else the requested one). A solver's Law::beta_d2_over_mu and Law::K convert with its
/// cell's own phi instead (law.h); `law eval` shows the closure at a single point.
struct Evaluation {
  double phi, re, F, beta_d2_over_mu, K;
  double phi_evaluated, re_evaluated;
  bool outside_validity;
};

Evaluation evaluate(const Law& law, double phi, double re, const std::vector<double>& extra) {
  const LawEvaluation v = law.evaluate(phi, re, extra.empty() ? nullptr : extra.data());
  Evaluation e;
  e.phi = phi;
  e.re = re;
  e.F = v.F;
  e.phi_evaluated = v.phi;
  e.re_evaluated = v.re;
  e.beta_d2_over_mu = conventions::beta_d2_over_mu(v.phi, e.F);
  e.K = conventions::total_force_K(v.phi, e.F);
  e.outside_validity = v.out_of_validity;
  return e;
}

nlohmann::json evaluation_json(const Law& law, const Evaluation& e) {
  nlohmann::json j = {{"law", law.record().name},
                      {"version", law.record().version},
                      {"hash", law.record().content_hash},
                      {"phi", e.phi},
                      {"re", e.re},
                      {"F", e.F},
                      {"beta_d2_over_mu", e.beta_d2_over_mu},
                      {"K", e.K},
                      {"outside_validity", e.outside_validity}};
  // Every value comes from this one point (the clamped point under the clamp policy).
  j["evaluated_at"] = {{"phi", e.phi_evaluated}, {"re", e.re_evaluated}};
  return j;
}

/// One point of a grid of evaluations: the evaluation, or where it lies outside the law's
/// validity box (range policy "error") the law, the point and why.
nlohmann::json grid_point_json(const Law& law, double phi, double re,
                               const std::vector<double>& extra) {
  try {
    return evaluation_json(law, evaluate(law, phi, re, extra));
  } catch (const Error& e) {
    if (e.code() != ErrorCode::kOutOfValidity) throw;
    return {{"law", law.record().name},
            {"version", law.record().version},
            {"phi", phi},
            {"re", re},
            {"error", e.what()}};
  }
}

/// Physical range of the inputs, checked before anything is opened or printed.
/// Far beyond any gas-solid bed (and every law's fitted range): a larger Re is a typing error.
constexpr double kMaxParticleReynolds = 1e7;

void check_physical_inputs(const std::vector<double>& phis, const std::vector<double>& res,
                           const std::string& phi_field, const std::string& re_field) {
  for (double phi : phis) {
    if (!std::isfinite(phi) || phi < 0.0 || phi >= 1.0) {
      throw UsageError(
          fmt::format("{} = {} is outside [0, 1) (phi is the solids fraction)", phi_field, phi));
    }
  }
  for (double re : res) {
    if (!std::isfinite(re) || re < 0.0 || re > kMaxParticleReynolds) {
      throw UsageError(fmt::format("{} = {} is outside [0, {:g}] (particle Reynolds number)",
                                   re_field, re, kMaxParticleReynolds));
    }
  }
}

void print_law_header(const Law& law, const std::string& warning, const CliContext& ctx) {
  if (!warning.empty()) ctx.warn(warning);
  const LawRecord& r = law.record();
  ctx.info(fmt::format("{} ({}, form {}, hash {}): F = F_d/(3 pi mu d eps u), Re = rho eps d u/mu",
                       r.reference(), to_string(r.status), r.form, short_hash(r.content_hash)));
}

// ---- law list -------------------------------------------------------------------------------
void run_list(const CliContext& ctx, bool published_only) {
  auto db = ctx.open_database();
  std::vector<LawRecord> records = db->list("", !published_only);
  if (published_only) {
    records.erase(
        std::remove_if(records.begin(), records.end(),
                       [](const LawRecord& r) { return r.status != LawStatus::kPublished; }),
        records.end());
  }
  if (ctx.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const LawRecord& r : records) {
      out.push_back({{"name", r.name},
                     {"version", r.version},
                     {"reference", r.reference()},
                     {"status", to_string(r.status)},
                     {"form", r.form},
                     {"hash", r.content_hash},
                     {"created_at", r.created_at},
                     {"provenance", r.provenance.kind}});
    }
    ctx.print_json(out);
    return;
  }
  std::cout << fmt::format("{:<20} {:>3}  {:<10} {:<18} {:<12} {:<10} {}\n", "name", "ver",
                           "status", "form", "hash", "source", "created");
  for (const LawRecord& r : records) {
    std::cout << fmt::format("{:<20} {:>3}  {:<10} {:<18} {:<12} {:<10} {}\n", r.name, r.version,
                             to_string(r.status), r.form, short_hash(r.content_hash),
                             r.provenance.kind, r.created_at);
  }
  ctx.info(fmt::format("{} law version(s) in {}", records.size(), db->path()));
}

// ---- law show -------------------------------------------------------------------------------
void run_show(const CliContext& ctx, const std::string& ref) {
  auto db = ctx.open_database();
  const LawRecord r = db->resolve(ref);
  if (ctx.json) {
    ctx.print_json(record_json(r));
    return;
  }
  const LawForm& form = find_law_form(r.form);
  std::cout << fmt::format("{}  [{}]\n", r.reference(), to_string(r.status));
  std::cout << fmt::format("  form        {}: {}\n", r.form, form.description.title);
  std::cout << fmt::format("  hash        {}\n", r.content_hash);
  std::cout << fmt::format("  created     {}\n", r.created_at);
  std::cout << fmt::format("  convention  native force {}, normalisation {}, Re {}, TFM model {}\n",
                           to_string(r.convention.force), to_string(r.convention.normalisation),
                           to_string(r.convention.reynolds), to_string(r.convention.tfm_model));
  std::cout << "              evaluated as canonical drag-only F = F_d/(3 pi mu d eps u), "
               "Re = rho eps d u/mu\n";
  std::cout << fmt::format("  validity    phi in [{}, {}], Re in [{}, {}]\n",
                           format_number(r.validity.phi.min), format_number(r.validity.phi.max),
                           format_number(r.validity.re.min), format_number(r.validity.re.max));
  for (const ExtraInputSpec& e : r.validity.extra) {
    std::cout << fmt::format("              {} in [{}, {}]: {}\n", e.name,
                             format_number(e.range.min), format_number(e.range.max), e.description);
  }
  std::cout << "  parameters\n";
  const std::size_t n = r.parameters.size();
  for (std::size_t i = 0; i < n; ++i) {
    const LawParameter& p = r.parameters[i];
    std::string sigma;
    if (r.covariance.size() == n * n) {
      sigma = fmt::format(" +- {}", format_number(std::sqrt(r.covariance[i * n + i]), 3));
    }
    std::cout << fmt::format("    {:<10} = {}{} [{}]\n", p.name, format_number(p.value, 10), sigma,
                             p.unit);
  }
  std::cout << fmt::format("  provenance  {}\n", r.provenance.kind);
  if (!r.provenance.citation.empty())
    std::cout << fmt::format("    citation  {}\n", r.provenance.citation);
  if (!r.provenance.dataset_id.empty())
    std::cout << fmt::format("    dataset   {} (data hash {})\n", r.provenance.dataset_id,
                             r.provenance.data_hash);
  if (!r.provenance.fitter_settings.empty())
    std::cout << fmt::format("    fitter    {}\n", r.provenance.fitter_settings);
  std::cout << fmt::format("    code      {}\n", r.provenance.code_version);
  if (!r.notes.empty()) std::cout << fmt::format("  notes       {}\n", r.notes);
  if (r.status == LawStatus::kRetracted)
    std::cout << fmt::format("  RETRACTED   {}\n", r.retraction_reason);
}

// ---- law eval -------------------------------------------------------------------------------
struct EvalOptions {
  std::string ref;
  double phi = std::numeric_limits<double>::quiet_NaN();
  double re = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> extra;
  bool grid = false;
  bool phi_given = false;
  bool re_given = false;
  std::string phi_list = "0.1,0.2,0.3,0.4,0.5,0.6";
  std::string re_list = "0,1,10,100,1000";
  std::string policy = "error";
};

void run_eval(const CliContext& ctx, const EvalOptions& o) {
  std::vector<double> phis, res;
  if (o.grid) {
    phis = core::parse_number_list(o.phi_list, "--phi-list");
    res = core::parse_number_list(o.re_list, "--re-list");
    check_physical_inputs(phis, res, "--phi-list", "--re-list");
  } else {
    if (!o.phi_given || !o.re_given)
      throw UsageError("--phi and --re are required (or use --grid)");
    check_physical_inputs({o.phi}, {o.re}, "--phi", "--re");
  }
  auto db = ctx.open_database();
  std::string warning;
  auto law = db->load(o.ref, range_policy_from_string(o.policy), &warning);
  if (law->num_extra_inputs() != static_cast<int>(o.extra.size())) {
    if (law->num_extra_inputs() == 0) {
      throw UsageError(fmt::format("--y: {} is monodisperse and takes no size ratio; {} given",
                                   law->reference(), o.extra.size()));
    }
    std::string names;
    for (const auto& e : law->record().validity.extra)
      names += (names.empty() ? "" : ", ") + e.name;
    throw UsageError(fmt::format("--y: {} takes {} extra input(s) ({}); {} given", law->reference(),
                                 law->num_extra_inputs(), names, o.extra.size()));
  }
  print_law_header(*law, warning, ctx);

  if (!o.grid) {
    const Evaluation e = evaluate(*law, o.phi, o.re, o.extra);
    if (ctx.json) {
      nlohmann::json j = evaluation_json(*law, e);
      j["range_policy"] = o.policy;
      ctx.print_json(j);
      return;
    }
    std::cout << fmt::format(
        "phi = {}  Re = {}{}\n", format_number(e.phi), format_number(e.re),
        e.outside_validity ? "  (outside validity box: " + o.policy + ")" : "");
    if (e.phi_evaluated != e.phi || e.re_evaluated != e.re) {
      std::cout << fmt::format("  every value at the clamped point phi = {}, Re = {}\n",
                               format_number(e.phi_evaluated), format_number(e.re_evaluated));
    }
    std::cout << fmt::format("  F              = {}\n", format_number(e.F, 10));
    std::cout << fmt::format("  beta d^2/mu    = {}\n", format_number(e.beta_d2_over_mu, 10));
    std::cout << fmt::format("  K = F/(1-phi)  = {}\n", format_number(e.K, 10));
    return;
  }

  if (ctx.json) {
    nlohmann::json out = nlohmann::json::array();
    for (double phi : phis) {
      for (double re : res) {
        out.push_back(grid_point_json(*law, phi, re, o.extra));
      }
    }
    ctx.print_json(out);
    return;
  }
  std::string table =
      fmt::format("F(phi, Re) of {}  ('-' outside the validity box with policy '{}')\n",
                  law->reference(), o.policy);
  table += fmt::format("{:>8}", "phi\\Re");
  for (double re : res) table += fmt::format(" {:>11}", format_number(re));
  table += '\n';
  for (double phi : phis) {
    table += fmt::format("{:>8}", format_number(phi));
    for (double re : res) {
      try {
        table += fmt::format(" {:>11}", format_number(evaluate(*law, phi, re, o.extra).F));
      } catch (const Error& e) {
        if (e.code() != ErrorCode::kOutOfValidity) throw;
        table += fmt::format(" {:>11}", "-");
      }
    }
    table += '\n';
  }
  std::cout << table;  // printed only once complete: nothing half-written on an error
}

// ---- law diff -------------------------------------------------------------------------------
void run_diff(const CliContext& ctx, const std::string& ref_a, const std::string& ref_b,
              int points) {
  auto db = ctx.open_database();
  auto a = db->load(ref_a, RangePolicy::kError);
  auto b = db->load(ref_b, RangePolicy::kError);
  if (a->num_extra_inputs() != 0 || b->num_extra_inputs() != 0) {
    throw UsageError("law diff compares monodisperse laws (no extra inputs)");
  }
  if (points < 2 || points > 2000) throw UsageError("--points must lie in [2, 2000]");
  const ValidityBox& va = a->record().validity;
  const ValidityBox& vb = b->record().validity;
  const InputRange phi{std::max(va.phi.min, vb.phi.min), std::min(va.phi.max, vb.phi.max)};
  const InputRange re{std::max(va.re.min, vb.re.min), std::min(va.re.max, vb.re.max)};
  if (phi.min > phi.max || re.min > re.max) {
    throw UsageError(fmt::format(
        "the validity boxes of {} and {} do not overlap (phi [{}, {}] vs [{}, {}], Re [{}, {}] vs "
        "[{}, {}])",
        a->reference(), b->reference(), va.phi.min, va.phi.max, vb.phi.min, vb.phi.max, va.re.min,
        va.re.max, vb.re.min, vb.re.max));
  }
  // Grid: phi uniform; Re = the lower bound plus log-spaced points up to the upper bound.
  std::vector<double> phis, res;
  for (int i = 0; i < points; ++i) phis.push_back(phi.min + (phi.max - phi.min) * i / (points - 1));
  res.push_back(re.min);
  const double lo = std::max(re.min, 1e-2);
  if (re.max > lo) {
    for (int i = 0; i < points - 1; ++i)
      res.push_back(lo * std::pow(re.max / lo, static_cast<double>(i) / (points - 2)));
  }
  double max_rel = -1.0, sum_sq = 0.0, at_phi = phi.min, at_re = re.min, fa_at = 0, fb_at = 0;
  std::size_t n = 0;
  for (double p : phis) {
    for (double r : res) {
      const double fa = a->F(p, r), fb = b->F(p, r);
      const double rel = std::abs(fb - fa) / std::abs(fa);
      sum_sq += rel * rel;
      ++n;
      if (rel > max_rel) {
        max_rel = rel;
        at_phi = p;
        at_re = r;
        fa_at = fa;
        fb_at = fb;
      }
    }
  }
  const double rms = std::sqrt(sum_sq / static_cast<double>(n));
  const bool same_content = a->record().content_hash == b->record().content_hash;
  if (ctx.json) {
    ctx.print_json(
        {{"a", a->reference()},
         {"b", b->reference()},
         {"same_content", same_content},
         {"grid", {{"phi", {phi.min, phi.max}}, {"re", {re.min, re.max}}, {"points", n}}},
         {"max_relative_difference", max_rel},
         {"at", {{"phi", at_phi}, {"re", at_re}, {"F_a", fa_at}, {"F_b", fb_at}}},
         {"rms_relative_difference", rms}});
    return;
  }
  std::cout << fmt::format("{} vs {}{}\n", a->reference(), b->reference(),
                           same_content ? "  (identical content hash)" : "");
  std::cout << fmt::format("  grid: {} points, phi in [{}, {}], Re in [{}, {}] (common validity)\n",
                           n, format_number(phi.min), format_number(phi.max), format_number(re.min),
                           format_number(re.max));
  std::cout << fmt::format(
      "  largest |F_b - F_a|/F_a = {:.4g} % at phi = {}, Re = {} "
      "(F_a = {}, F_b = {})\n",
      100 * max_rel, format_number(at_phi), format_number(at_re), format_number(fa_at),
      format_number(fb_at));
  std::cout << fmt::format("  rms relative difference  = {:.4g} %\n", 100 * rms);
}

// ---- law export -----------------------------------------------------------------------------
void run_export(const CliContext& ctx, const std::string& ref, const std::string& format,
                const std::string& output) {
  if (!output.empty() && output != "-") core::check_output_file(output, "--output");
  auto db = ctx.open_database();
  const LawRecord r = db->resolve(ref);
  const std::string text = export_law(r, export_format_from_string(format));
  if (output.empty() || output == "-") {
    std::cout << text;
    return;
  }
  core::write_file_atomically(output, text, "--output");
  ctx.info(fmt::format("wrote {} ({} export of {})", output, format, r.reference()));
}

// ---- law retract ----------------------------------------------------------------------------
void run_retract(const CliContext& ctx, const std::string& ref, const std::string& reason) {
  LawReference law;
  if (!LawReference::TryParse(ref, &law) || ref.find('@') == std::string::npos ||
      law.version_number() < 0) {
    throw UsageError("law retract needs an explicit NAME@VERSION (e.g. " + law.name + "@1), got '" +
                     ref + "'");
  }
  if (reason.find_first_not_of(" \t") == std::string::npos || reason.size() < 3) {
    throw UsageError("--reason '" + reason +
                     "' is too short: say why the law is retracted (at least 3 characters)");
  }
  auto db = ctx.open_database();
  const LawRecord r = db->resolve(ref);
  const LawRecord out = db->retract(r.name, r.version, reason);
  if (ctx.json) {
    ctx.print_json(
        {{"law", out.name}, {"version", out.version}, {"status", to_string(out.status)}});
    return;
  }
  std::cout << fmt::format("{} retracted: {}\n", out.reference(), reason);
}

// ---- law compare (the default job of run.sh) ------------------------------------------------
void run_compare(const CliContext& ctx, const std::string& phi_list, const std::string& re_list) {
  const std::vector<double> phis = core::parse_number_list(phi_list, "--phi-list");
  const std::vector<double> res = core::parse_number_list(re_list, "--re-list");
  check_physical_inputs(phis, res, "--phi-list", "--re-list");
  auto db = ctx.open_database();
  std::vector<std::shared_ptr<Law>> laws;
  for (const LawRecord& r : db->list("", false)) {
    if (r.status != LawStatus::kPublished) continue;
    // Latest published version of each name only.
    if (!laws.empty() && laws.back()->record().name == r.name) laws.pop_back();
    auto law = db->load(r.reference(), RangePolicy::kExtrapolate);
    if (law->num_extra_inputs() == 0) laws.push_back(law);
  }
  if (ctx.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& law : laws) {
      for (double re : res) {
        for (double phi : phis) {
          out.push_back(grid_point_json(*law, phi, re, {}));
        }
      }
    }
    ctx.print_json(out);
    return;
  }
  std::string table =
      "Published drag laws side by side: canonical drag-only F = F_d/(3 pi mu d eps u),\n"
      "Re = rho eps d u/mu (u interstitial slip). Values in parentheses lie outside the\n"
      "law's validity box (extrapolated). Database: " +
      db->path() + "\n";
  for (double re : res) {
    table += fmt::format("\nRe = {}\n{:<22}", format_number(re), "law \\ phi");
    for (double phi : phis) table += fmt::format(" {:>9}", format_number(phi));
    table += '\n';
    for (const auto& law : laws) {
      table += fmt::format("{:<22}", law->reference());
      for (double phi : phis) {
        std::string v;
        try {
          const Evaluation e = evaluate(*law, phi, re, {});
          v = format_number(e.F, 4);
          if (e.outside_validity) v = "(" + v + ")";
        } catch (const Error& e) {
          if (e.code() != ErrorCode::kOutOfValidity) throw;
          v = "-";  // the formula is not finite this far outside its box
        }
        table += fmt::format(" {:>9}", v);
      }
      table += '\n';
    }
  }
  std::cout << table;
}

}  // namespace

void add_law_commands(CLI::App& app, CliContext& ctx) {
  CLI::App* law = app.add_subcommand("law", "Inspect, evaluate, compare and export drag laws");
  law->require_subcommand(1);
  law->footer(
      "Examples:\n  draglab law list\n  draglab law show bvk2007\n"
      "  draglab law eval bvk2007 --phi 0.3 --re 50 --json\n  draglab law diff bvk2007 tang2015\n"
      "  draglab law export bvk2007@1 --format fortran -o bvk2007.f90\n  draglab law compare");

  {
    auto* cmd = law->add_subcommand("list", "List law versions (all statuses)");
    auto published_only = std::make_shared<bool>(false);
    cmd->add_flag("--published", *published_only, "Only published versions");
    cmd->footer("Examples:\n  draglab law list\n  draglab law list --published --json");
    cmd->callback([&ctx, published_only] {
      ctx.action = [&ctx, published_only] { run_list(ctx, *published_only); };
    });
  }
  {
    auto* cmd = law->add_subcommand("show",
                                    "Show one law version: parameters, conventions, "
                                    "validity, provenance");
    auto ref = std::make_shared<std::string>();
    cmd->add_option("law", *ref, "NAME, NAME@VERSION, NAME@latest or NAME@<hash prefix>")
        ->required();
    cmd->footer("Examples:\n  draglab law show bvk2007\n  draglab law show vdh2004@1 --json");
    cmd->callback([&ctx, ref] { ctx.action = [&ctx, ref] { run_show(ctx, *ref); }; });
  }
  {
    auto* cmd = law->add_subcommand(
        "eval", "Evaluate F, beta d^2/mu and K = F/(1-phi) at (phi, Re) or on a grid");
    auto o = std::make_shared<EvalOptions>();
    cmd->add_option("law", o->ref, "NAME[@VERSION]")->required();
    cmd->add_option("--phi", o->phi, "Solids volume fraction phi = 1 - eps, in [0, 1)")
        ->each([o](const std::string&) { o->phi_given = true; });
    cmd->add_option("--re", o->re, "Reynolds number rho eps d u/mu (u interstitial), [0, 1e7]")
        ->each([o](const std::string&) { o->re_given = true; });
    cmd->add_option("--y", o->extra,
                    "Extra inputs of polydisperse forms: size ratio y = d_i/<d> (Sauter mean)");
    cmd->add_flag("--grid", o->grid, "Evaluate on a phi x Re grid");
    cmd->add_option("--phi-list", o->phi_list, "Grid values of phi (comma separated)")
        ->capture_default_str();
    cmd->add_option("--re-list", o->re_list, "Grid values of Re (comma separated)")
        ->capture_default_str();
    cmd->add_option("--range-policy", o->policy,
                    "Outside the validity box: error, clamp or extrapolate")
        ->capture_default_str()
        ->check(CLI::IsMember({"error", "clamp", "extrapolate"}));
    cmd->footer(
        "Examples:\n  draglab law eval bvk2007 --phi 0.3 --re 50\n"
        "  draglab law eval tang2015@1 --phi 0.4 --re 100 --json\n"
        "  draglab law eval gidaspow --grid --phi-list 0.1,0.2,0.3 --re-list 1,10,100\n"
        "  draglab law eval bvk2007_poly --phi 0.3 --re 10 --y 1.5");
    cmd->callback([&ctx, o] { ctx.action = [&ctx, o] { run_eval(ctx, *o); }; });
  }
  {
    auto* cmd = law->add_subcommand(
        "diff", "Largest relative difference of F between two laws over their common validity");
    auto a = std::make_shared<std::string>();
    auto b = std::make_shared<std::string>();
    auto points = std::make_shared<int>(41);
    cmd->add_option("a", *a, "Reference law NAME[@VERSION]")->required();
    cmd->add_option("b", *b, "Other law NAME[@VERSION]")->required();
    cmd->add_option("--points", *points, "Grid points per axis")->capture_default_str();
    cmd->footer(
        "Examples:\n  draglab law diff bvk2007 tang2015\n  draglab law diff vdh2004 "
        "bvk2007 --json");
    cmd->callback([&ctx, a, b, points] {
      ctx.action = [&ctx, a, b, points] { run_diff(ctx, *a, *b, *points); };
    });
  }
  {
    auto* cmd = law->add_subcommand(
        "export", "Standalone C, Fortran or JSON for solvers that cannot link libdraglab");
    auto ref = std::make_shared<std::string>();
    auto format = std::make_shared<std::string>("c");
    auto output = std::make_shared<std::string>();
    cmd->add_option("law", *ref, "NAME[@VERSION]")->required();
    cmd->add_option("--format", *format, "c, fortran or json")
        ->capture_default_str()
        ->check(CLI::IsMember({"c", "fortran", "json"}));
    cmd->add_option("-o,--output", *output, "Output file (default: stdout)");
    cmd->footer(
        "Examples:\n  draglab law export bvk2007@1 --format c -o bvk2007_v1.c\n"
        "  draglab law export syamlal_obrien --format fortran -o usr_drag_law.f90\n"
        "  draglab law export tang2015 --format json");
    cmd->callback([&ctx, ref, format, output] {
      ctx.action = [&ctx, ref, format, output] { run_export(ctx, *ref, *format, *output); };
    });
  }
  {
    auto* cmd = law->add_subcommand(
        "retract", "Mark a published version as retracted (it stays loadable, with a warning)");
    auto ref = std::make_shared<std::string>();
    auto reason = std::make_shared<std::string>();
    cmd->add_option("law", *ref, "NAME@VERSION")->required();
    cmd->add_option("--reason", *reason, "Why the version is retracted")->required();
    cmd->footer("Example:\n  draglab law retract mylaw@2 --reason \"fitted to a corrupt dataset\"");
    cmd->callback([&ctx, ref, reason] {
      ctx.action = [&ctx, ref, reason] { run_retract(ctx, *ref, *reason); };
    });
  }
  {
    auto* cmd = law->add_subcommand("compare",
                                    "Side-by-side table of F for every published monodisperse law");
    auto phi_list = std::make_shared<std::string>("0.05,0.1,0.2,0.3,0.4,0.5,0.6");
    auto re_list = std::make_shared<std::string>("0,10,100,1000");
    cmd->add_option("--phi-list", *phi_list, "Values of phi (comma separated)")
        ->capture_default_str();
    cmd->add_option("--re-list", *re_list, "Values of Re (comma separated)")->capture_default_str();
    cmd->footer("Examples:\n  draglab law compare\n  draglab law compare --re-list 0,50 --json");
    cmd->callback([&ctx, phi_list, re_list] {
      ctx.action = [&ctx, phi_list, re_list] { run_compare(ctx, *phi_list, *re_list); };
    });
  }
}

}  // namespace cli
}  // namespace draglab
