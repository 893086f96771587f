// Campaign specs: TOML parsing (toml++), validation, canonical JSON (docs/campaigns.md).
#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "draglab/core/files.h"
#include "draglab/core/toml_schema.h"
#include "draglab/lbm/lbm.h"
#include "draglab/lbm/resolution.h"

#include "campaign_internal.h"
#include "draglab/campaign/campaign.h"
#include "draglab/core/text.h"
#include "draglab/error.h"

namespace draglab {
namespace campaign {
namespace {

constexpr double kMinPhi = 0.05, kMaxPhi = 0.6;
constexpr double kMaxRe = 1000.0;
using lbm::kMaxResolution;
using lbm::kMinResolution;
/// With resolutions = "rule", a point beyond max_resolution also runs at max_resolution / this.
constexpr double kRuleCoarseRatio = 1.5;

using core::format_number;

bool fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

// The keys each section accepts, in documentation order (error messages list them).
const core::toml_schema::Schema& sections() {
  static const core::toml_schema::Schema s = {
      {"campaign", {"name", "description"}},
      {"grid", {"phi", "re", "realizations", "seed"}},
      {"packing",
       {"spheres", "box_size", "distribution", "size_ratio", "large_fraction", "sigma", "min_gap"}},
      {"lbm",
       {"resolutions", "min_resolution", "max_resolution", "target_error", "collision", "boundary",
        "tolerance", "max_steps", "precision", "ranks_per_unit"}},
      {"dataset", {"extrapolation", "extend_with", "extend_with_id"}},
  };
  return s;
}

bool check_list(const std::vector<double>& values, const std::string& field, double lo, double hi,
                const std::string& what, std::string* error) {
  if (values.empty()) return fail(error, field + " has no values (give at least one " + what + ")");
  std::set<double> seen;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    if (!std::isfinite(v) || v < lo || v > hi) {
      return fail(error, field + "[" + std::to_string(i) + "] = " + format_number(v) +
                             " is outside [" + format_number(lo) + ", " + format_number(hi) +
                             "] (" + what + ")");
    }
    if (!seen.insert(v).second) {
      return fail(error, field + " lists " + format_number(v) + " twice (each value once)");
    }
  }
  return true;
}

[[noreturn]] void bad(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

}  // namespace

bool CampaignSpec::IsValid(std::string* error) const {
  if (name.empty()) return fail(error, "[campaign] name is missing or empty");
  for (char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) {
      return fail(error, "[campaign] name '" + name +
                             "' may contain only letters, digits, '_', '-' and '.'");
    }
  }
  if (name.find_first_not_of("0123456789") == std::string::npos) {
    return fail(error, "[campaign] name '" + name + "' must not be all digits (ids are numbers)");
  }
  if (!check_list(phi, "[grid] phi", kMinPhi, kMaxPhi, "solids fraction", error)) return false;
  if (!check_list(re, "[grid] re", 0.0, kMaxRe, "target Reynolds number, 0 = Stokes flow", error)) {
    return false;
  }
  if (realizations < 1 || realizations > 100) {
    return fail(error,
                "[grid] realizations = " + std::to_string(realizations) + " is outside [1, 100]");
  }
  if (seed > static_cast<std::uint64_t>(INT64_MAX)) {
    return fail(error, "[grid] seed is outside [0, 2^63 - 1]");
  }
  if (box_size > 0.0) {
    if (!std::isfinite(box_size) || box_size < 1.5 || box_size > 100.0) {
      return fail(error, "[packing] box_size = " + format_number(box_size) +
                             " is outside [1.5, 100] sphere diameters");
    }
  } else if (box_size != 0.0) {
    return fail(error,
                "[packing] box_size = " + format_number(box_size) + " must be > 0 (or left out)");
  } else if (spheres < 1 || spheres > 100000) {
    return fail(error,
                "[packing] spheres = " + std::to_string(spheres) + " is outside [1, 100000]");
  }
  if (distribution != "mono" && distribution != "bi" && distribution != "lognormal") {
    return fail(
        error, "[packing] distribution = '" + distribution + "' is not one of mono, bi, lognormal");
  }
  if (!(size_ratio > 1.0 && size_ratio <= 4.0)) {
    return fail(error,
                "[packing] size_ratio = " + format_number(size_ratio) + " is outside (1, 4]");
  }
  if (!(large_fraction >= 0.0 && large_fraction <= 1.0)) {
    return fail(error, "[packing] large_fraction = " + format_number(large_fraction) +
                           " is outside [0, 1]");
  }
  if (!(sigma > 0.0 && sigma <= 0.5)) {
    return fail(error, "[packing] sigma = " + format_number(sigma) + " is outside (0, 0.5]");
  }
  if (!(min_gap >= 0.0 && min_gap <= 0.5)) {
    return fail(error, "[packing] min_gap = " + format_number(min_gap) +
                           " is outside [0, 0.5] diameters (0 = no forced gap)");
  }
  if (resolution_rule) {
    if (!resolutions.empty()) {
      return fail(error, "[lbm] resolutions = \"rule\" leaves the list of resolutions empty");
    }
    if (!(min_resolution >= kMinResolution && min_resolution <= kMaxResolution)) {
      return fail(error, "[lbm] min_resolution = " + format_number(min_resolution) +
                             " is outside [" + format_number(kMinResolution) + ", " +
                             format_number(kMaxResolution) + "] lattice units per diameter");
    }
    if (!(max_resolution >= min_resolution && max_resolution <= kMaxResolution)) {
      return fail(error, "[lbm] max_resolution = " + format_number(max_resolution) +
                             " is outside [min_resolution = " + format_number(min_resolution) +
                             ", " + format_number(kMaxResolution) + "] lattice units per diameter");
    }
    if (!(target_error >= 0.0 && target_error < 1.0)) {
      return fail(error, "[lbm] target_error = " + format_number(target_error) +
                             " is outside [0, 1) (a relative error; 0 = the accuracy rules alone)");
    }
    if (max_resolution / kRuleCoarseRatio < kMinResolution) {
      return fail(error, "[lbm] max_resolution = " + format_number(max_resolution) +
                             " leaves no coarser resolution for the points the rule cannot "
                             "promise (it needs >= " +
                             format_number(kMinResolution * kRuleCoarseRatio) + ")");
    }
  } else if (!check_list(resolutions, "[lbm] resolutions", kMinResolution, kMaxResolution,
                         "lattice units per diameter", error)) {
    return false;
  }
  if (collision != "auto" && collision != "trt" && collision != "bgk" && collision != "rr") {
    return fail(error, "[lbm] collision = '" + collision + "' is not one of auto, trt, bgk, rr");
  }
  if (precision != "double" && precision != "float") {
    return fail(error, "[lbm] precision = '" + precision + "' is not one of double, float");
  }
  if (boundary != "ibb" && boundary != "bb") {
    return fail(error, "[lbm] boundary = '" + boundary + "' is not one of ibb, bb");
  }
  if (!(tolerance >= 1e-9 && tolerance <= 1e-2)) {
    return fail(error,
                "[lbm] tolerance = " + format_number(tolerance) + " is outside [1e-9, 1e-2]");
  }
  if (max_steps < 1 || max_steps > 100000000) {
    return fail(error,
                "[lbm] max_steps = " + std::to_string(max_steps) + " is outside [1, 100000000]");
  }
  if (ranks_per_unit < 1 || ranks_per_unit > kMaxRanksPerUnit) {
    return fail(error, "[lbm] ranks_per_unit = " + std::to_string(ranks_per_unit) +
                           " is outside [1, " + std::to_string(kMaxRanksPerUnit) + "]");
  }
  if (extrapolation != "richardson" && extrapolation != "inverse_d" && extrapolation != "finest") {
    return fail(error, "[dataset] extrapolation = '" + extrapolation +
                           "' is not one of richardson, inverse_d, finest");
  }
  if (!resolution_rule && extrapolation != "finest" && resolutions.size() < 2) {
    return fail(error, "[dataset] extrapolation = '" + extrapolation +
                           "' needs at least 2 [lbm] resolutions (3 for the measured order of "
                           "richardson); with one resolution use extrapolation = \"finest\"");
  }
  if (distribution == "bi" && box_size == 0.0 && large_fraction > 0.0 && large_fraction < 1.0) {
    const arrays::BidisperseCounts c =
        arrays::bidisperse_counts(spheres, size_ratio, large_fraction);
    if (c.large < 1 || c.small < 1 ||
        std::fabs(c.large_volume_fraction - large_fraction) > arrays::kBidisperseShareTolerance) {
      return fail(error,
                  "[packing] spheres = " + std::to_string(spheres) + " split into " +
                      std::to_string(c.large) + " large and " + std::to_string(c.small) +
                      " small at size_ratio " + format_number(size_ratio) +
                      ": a large volume share of " + format_number(c.large_volume_fraction) +
                      ", not the large_fraction " + format_number(large_fraction) +
                      " asked (within " + format_number(arrays::kBidisperseShareTolerance) +
                      "); use spheres >= " +
                      std::to_string(arrays::bidisperse_min_spheres(size_ratio, large_fraction)));
    }
  }
  // The padded spheres must be packable.
  const double gap = internal::effective_min_gap(*this);
  for (double p : phi) {
    if (distribution == "mono") {
      const double padded = p * std::pow(1.0 + gap, 3);
      if (padded > internal::kMaxPaddedPhi) {
        const double max_gap = std::cbrt(internal::kMaxPaddedPhi / p) - 1.0;
        return fail(error,
                    "[grid] phi = " + format_number(p) + " with a minimum gap of " +
                        format_number(gap) + " diameters pads the spheres to a solids fraction " +
                        format_number(padded) + " above " + format_number(internal::kMaxPaddedPhi) +
                        " (random packings of padded spheres jam); [packing] min_gap must be <= " +
                        format_number(max_gap) +
                        " diameters (0, the default, packs without a forced gap)");
      }
      if (box_size == 0.0) {
        const double edge = std::cbrt(spheres * M_PI / (6.0 * p));
        if (edge < 1.0 + gap) {
          return fail(error, "[packing] spheres = " + std::to_string(spheres) + " at phi = " +
                                 format_number(p) + " gives a box of " + format_number(edge) +
                                 " diameters, below one diameter plus the gap; use more spheres");
        }
      }
    }
    arrays::RandomPackingOptions o = internal::packing_options(*this, p, 1);
    std::string e;
    if (!o.IsValid(&e)) return fail(error, "[packing] at phi = " + format_number(p) + ": " + e);
  }
  return true;
}

std::vector<double> CampaignSpec::point_resolutions(double point_phi, double point_re) const {
  if (!resolution_rule) {
    std::vector<double> d = resolutions;
    std::sort(d.begin(), d.end());
    return d;
  }
  const auto even_above = [](double d) { return 2.0 * std::ceil(d / 2.0 - 1e-9); };
  const lbm::Collision operator_asked = lbm::collision_from_string(collision);
  const lbm::ResolutionNeed need = lbm::resolution_needed(point_phi, point_re, operator_asked);
  const auto meets_target = [&](double d) {
    return target_error <= 0.0 ||
           lbm::planned_discretisation_error(point_phi, point_re, d, operator_asked,
                                             lbm::boundary_from_string(boundary),
                                             lbm::precision_from_string(precision)) <= target_error;
  };
  for (double d = std::max(min_resolution, even_above(need.d)); d <= max_resolution; d += 2.0) {
    if (meets_target(d)) return {d};
  }
  // Beyond what the spec affords: the finest it affords and a coarser one, to extrapolate from.
  return {std::max(kMinResolution, even_above(max_resolution / kRuleCoarseRatio)), max_resolution};
}

double CampaignSpec::largest_resolution() const {
  double largest = 0.0;
  for (double p : phi) {
    for (double r : re) {
      for (double d : point_resolutions(p, r)) largest = std::max(largest, d);
    }
  }
  return largest;
}

std::int64_t CampaignSpec::unit_count() const {
  std::int64_t units = 0;
  for (double p : phi) {
    for (double r : re) {
      units += static_cast<std::int64_t>(point_resolutions(p, r).size()) * realizations;
    }
  }
  return units;
}

std::string CampaignSpec::to_json() const {
  // nlohmann's object keys are sorted and doubles print in shortest round-trip form: the text,
  // and so the spec hash, is canonical.
  nlohmann::json j = {
      {"campaign", {{"name", name}, {"description", description}}},
      {"grid", {{"phi", phi}, {"re", re}, {"realizations", realizations}, {"seed", seed}}},
      {"packing",
       {{"spheres", spheres},
        {"box_size", box_size},
        {"distribution", distribution},
        {"size_ratio", size_ratio},
        {"large_fraction", large_fraction},
        {"sigma", sigma},
        {"min_gap", min_gap}}},
      {"lbm",
       {{"resolutions", resolutions},
        {"collision", collision},
        {"boundary", boundary},
        {"tolerance", tolerance},
        {"max_steps", max_steps}}},
      {"dataset", {{"extrapolation", extrapolation}}},
  };
  if (resolution_rule) {
    j["lbm"]["resolutions"] = "rule";
    j["lbm"]["min_resolution"] = min_resolution;
    j["lbm"]["max_resolution"] = max_resolution;
    if (target_error > 0.0) j["lbm"]["target_error"] = target_error;
  }
  // Written only where it changes what a unit computes: older specs keep their text and hash.
  if (precision != "double") j["lbm"]["precision"] = precision;
  return j.dump();
}

CampaignSpec internal::spec_from_json(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(text);
  CampaignSpec s;
  s.name = j.at("campaign").at("name").get<std::string>();
  s.description = j.at("campaign").at("description").get<std::string>();
  s.phi = j.at("grid").at("phi").get<std::vector<double>>();
  s.re = j.at("grid").at("re").get<std::vector<double>>();
  s.realizations = j.at("grid").at("realizations").get<int>();
  s.seed = j.at("grid").at("seed").get<std::uint64_t>();
  const auto& p = j.at("packing");
  s.spheres = p.at("spheres").get<int>();
  s.box_size = p.at("box_size").get<double>();
  s.distribution = p.at("distribution").get<std::string>();
  s.size_ratio = p.at("size_ratio").get<double>();
  s.large_fraction = p.at("large_fraction").get<double>();
  s.sigma = p.at("sigma").get<double>();
  s.min_gap = p.at("min_gap").get<double>();
  const auto& l = j.at("lbm");
  if (l.at("resolutions").is_string()) {
    s.resolution_rule = true;
    s.min_resolution = l.at("min_resolution").get<double>();
    s.max_resolution = l.at("max_resolution").get<double>();
    s.target_error = l.value("target_error", 0.0);
  } else {
    s.resolutions = l.at("resolutions").get<std::vector<double>>();
  }
  s.collision = l.at("collision").get<std::string>();
  s.boundary = l.at("boundary").get<std::string>();
  s.tolerance = l.at("tolerance").get<double>();
  s.max_steps = l.at("max_steps").get<std::int64_t>();
  s.precision = l.value("precision", std::string("double"));
  s.extrapolation = j.at("dataset").at("extrapolation").get<std::string>();
  return s;
}

CampaignSpec parse_campaign_spec_text(const std::string& toml_text, const std::string& origin) {
  namespace ts = core::toml_schema;
  const toml::table root = ts::parse(toml_text, origin);
  CampaignSpec s;
  std::set<std::string> given;  // "section.key" present in the file
  ts::visit(root, origin, sections(), nullptr, [&](const ts::Entry& e) {
    const toml::node& node = e.node;
    const std::string& field = e.field;
    given.insert(e.section + "." + e.key);
    const std::string id = e.section + "." + e.key;
    const auto number = [&] { return ts::number(node, field, e.at); };
    const auto integer = [&] { return ts::integer(node, field, e.at); };
    const auto text = [&] { return ts::text(node, field, e.at); };
    const auto numbers = [&] { return ts::numbers(node, field, e.at); };
    if (id == "campaign.name") s.name = text();
    if (id == "campaign.description") s.description = text();
    if (id == "grid.phi") s.phi = numbers();
    if (id == "grid.re") s.re = numbers();
    if (id == "grid.realizations") {
      const std::int64_t v = integer();
      if (v < 1 || v > 100) bad(field + " = " + std::to_string(v) + " is outside [1, 100]");
      s.realizations = static_cast<int>(v);
    }
    if (id == "grid.seed") {
      const std::int64_t v = integer();
      if (v < 0) bad(field + " = " + std::to_string(v) + " is outside [0, 2^63 - 1]");
      s.seed = static_cast<std::uint64_t>(v);
    }
    if (id == "packing.spheres") {
      const std::int64_t v = integer();
      if (v < 1 || v > 100000) bad(field + " = " + std::to_string(v) + " is outside [1, 100000]");
      s.spheres = static_cast<int>(v);
    }
    if (id == "packing.box_size") {
      s.box_size = number();
      // 0 stands for "not given" in the spec; typed, it is a box of no size.
      if (!(s.box_size > 0.0)) {
        bad(field + " = " + format_number(s.box_size) +
            " is outside [1.5, 100] sphere diameters (or leave it out for spheres)");
      }
    }
    if (id == "packing.distribution") s.distribution = text();
    if (id == "packing.size_ratio") s.size_ratio = number();
    if (id == "packing.large_fraction") s.large_fraction = number();
    if (id == "packing.sigma") s.sigma = number();
    if (id == "packing.min_gap") s.min_gap = number();
    if (id == "lbm.resolutions") {
      if (node.is_string()) {
        if (text() != "rule") {
          bad(field + " = \"" + text() +
              "\" is neither a list of resolutions nor \"rule\" (each point's d from the "
              "engine's resolution rule)");
        }
        s.resolution_rule = true;
      } else {
        s.resolutions = numbers();
      }
    }
    if (id == "lbm.min_resolution") s.min_resolution = number();
    if (id == "lbm.max_resolution") s.max_resolution = number();
    if (id == "lbm.target_error") s.target_error = number();
    if (id == "lbm.collision") s.collision = text();
    if (id == "lbm.boundary") s.boundary = text();
    if (id == "lbm.tolerance") s.tolerance = number();
    if (id == "lbm.precision") s.precision = text();
    if (id == "lbm.max_steps") {
      const std::int64_t v = integer();
      if (v < 1 || v > 100000000) {
        bad(field + " = " + std::to_string(v) + " is outside [1, 100000000]");
      }
      s.max_steps = v;
    }
    if (id == "lbm.ranks_per_unit") {
      const std::int64_t v = integer();
      if (v < 1 || v > kMaxRanksPerUnit) {
        bad(field + " = " + std::to_string(v) + " is outside [1, " +
            std::to_string(kMaxRanksPerUnit) + "] (MPI ranks that share one unit's box)");
      }
      s.ranks_per_unit = static_cast<int>(v);
    }
    if (id == "dataset.extrapolation") s.extrapolation = text();
    if (id == "dataset.extend_with") {
      s.extend_with = text();
      if (s.extend_with.empty()) bad(field + " is empty (a dataset CSV file, or leave it out)");
    }
    if (id == "dataset.extend_with_id") {
      s.extend_with_id = text();
      const bool hex12 =
          s.extend_with_id.size() == 12 &&
          s.extend_with_id.find_first_not_of("0123456789abcdef") == std::string::npos;
      if (!hex12) {
        bad(field + " = \"" + s.extend_with_id +
            "\" is not a dataset id (12 lower-case hex digits, as `draglab dataset list` shows)");
      }
    }
  });
  // Required keys, then contradictions a default would hide.
  for (const char* required : {"campaign.name", "grid.phi", "grid.re", "lbm.resolutions"}) {
    if (!given.count(required)) {
      const std::string id(required);
      const std::size_t dot = id.find('.');
      bad(origin + ": [" + id.substr(0, dot) + "] " + id.substr(dot + 1) + " is required");
    }
  }
  if (!s.resolution_rule &&
      (given.count("lbm.min_resolution") || given.count("lbm.max_resolution") ||
       given.count("lbm.target_error"))) {
    bad(origin +
        ": [lbm] min_resolution, max_resolution and target_error apply only to resolutions = "
        "\"rule\"");
  }
  if (given.count("dataset.extend_with_id") && !given.count("dataset.extend_with")) {
    bad(origin + ": [dataset] extend_with_id applies only with extend_with (the dataset file)");
  }
  if (given.count("packing.spheres") && given.count("packing.box_size")) {
    bad(origin + ": [packing] spheres and box_size contradict each other: give one of them");
  }
  if (s.distribution != "bi" &&
      (given.count("packing.size_ratio") || given.count("packing.large_fraction"))) {
    bad(origin + ": [packing] size_ratio and large_fraction apply only to distribution = \"bi\" " +
        "(distribution is \"" + s.distribution + "\")");
  }
  if (s.distribution != "lognormal" && given.count("packing.sigma")) {
    bad(origin +
        ": [packing] sigma applies only to distribution = \"lognormal\" (distribution is \"" +
        s.distribution + "\")");
  }
  std::string error;
  if (!s.IsValid(&error)) bad(origin + ": " + error);
  return s;
}

CampaignSpec parse_campaign_spec(const std::string& path) {
  CampaignSpec spec = parse_campaign_spec_text(core::read_text_input(path, "campaign spec"), path);
  // A spec names its dataset file from where the spec lies, as a preset's does.
  const std::filesystem::path extension(spec.extend_with);
  if (!spec.extend_with.empty() && extension.is_relative() && path != "-") {
    spec.extend_with =
        (std::filesystem::path(path).parent_path() / extension).lexically_normal().string();
  }
  return spec;
}

}  // namespace campaign
}  // namespace draglab
