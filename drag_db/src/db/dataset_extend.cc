// A dataset extended beyond the (phi, Re) box it was measured on by another's points (dataset.h).
#include <algorithm>
#include <cstdio>
#include <string>
#include <tuple>

#include <nlohmann/json.hpp>

#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"

namespace draglab {
namespace {

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

std::string box_text(const DatasetBox& box) {
  return "phi [" + number(box.phi_lo) + ", " + number(box.phi_hi) + "] x Re [" + number(box.re_lo) +
         ", " + number(box.re_hi) + "]";
}

void check_monodisperse(const Dataset& dataset, const std::string& role) {
  for (const DatasetPoint& p : dataset.points) {
    if (p.y != 0.0) {
      throw Error(ErrorCode::kInvalidArgument,
                  role + " dataset " + (dataset.id.empty() ? dataset.name : dataset.id) +
                      " has size-class points (y = " + number(p.y) + " at phi " + number(p.phi) +
                      "): only mixture drag extends a dataset");
    }
  }
}

nlohmann::json method_object(const Dataset& dataset) {
  if (dataset.method.empty()) return nlohmann::json::object();
  nlohmann::json method = nlohmann::json::parse(dataset.method, nullptr, false);
  return method.is_object() ? method : nlohmann::json{{"text", dataset.method}};
}

}  // namespace

Dataset extend_dataset(const Dataset& base, const DatasetBox& box, const Dataset& extension,
                       const std::string& extension_source) {
  if (base.points.empty()) {
    throw Error(ErrorCode::kInvalidArgument, "the dataset to extend has no points");
  }
  check_monodisperse(base, "the");
  check_monodisperse(extension, "the extension");
  for (const DatasetPoint& p : base.points) {
    if (!box.contains(p)) {
      throw Error(ErrorCode::kInvalidArgument, "the dataset to extend has a point (phi " +
                                                   number(p.phi) + ", Re " + number(p.re_target) +
                                                   ") outside its box " + box_text(box));
    }
  }
  Dataset out;
  out.campaign_id = base.campaign_id;
  out.name = base.name;
  out.points = base.points;
  nlohmann::json taken = nlohmann::json::array();
  for (const DatasetPoint& p : extension.points) {
    if (box.contains(p)) continue;
    out.points.push_back(p);
    taken.push_back({p.phi, p.re_target});
  }
  if (taken.empty()) {
    throw Error(ErrorCode::kInvalidArgument,
                extension_source + ": none of its " + std::to_string(extension.points.size()) +
                    " points lies outside the box " + box_text(box) +
                    " of the grid it should extend, so it adds nothing");
  }
  std::stable_sort(out.points.begin(), out.points.end(),
                   [](const DatasetPoint& a, const DatasetPoint& b) {
                     return std::tie(a.phi, a.re_target) < std::tie(b.phi, b.re_target);
                   });
  nlohmann::json method = method_object(base);
  method["extended_with"] = {
      {"base_dataset", base.id},
      {"base_hash", base.hash},
      {"base_points", base.points.size()},
      {"dataset", extension.id},
      {"hash", extension.hash},
      {"name", extension.name},
      {"source", extension_source},
      {"code_version", extension.code_version},
      {"rule", "the extension's points outside the base's box; inside it the base's alone"},
      {"box", {{"phi", {box.phi_lo, box.phi_hi}}, {"re_target", {box.re_lo, box.re_hi}}}},
      {"points", taken}};
  out.method = method.dump();
  return out;
}

}  // namespace draglab
