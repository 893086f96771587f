// LawRecord helpers: enum <-> string, content hash, literature records.
#include <openssl/evp.h>

#include <cstdio>
#include <nlohmann/json.hpp>

#include "drag_db_version.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/drag_db/law.h"
#include "draglab/error.h"

namespace draglab {

LawReference LawReference::Parse(const std::string& text) {
  LawReference reference;
  if (!TryParse(text, &reference)) {
    throw Error(ErrorCode::kInvalidArgument,
                "law reference '" + text +
                    "' is malformed: use name, name@latest, name@<version> or name@<hash prefix>");
  }
  return reference;
}

bool LawReference::TryParse(const std::string& text, LawReference* out) {
  const std::size_t at = text.find('@');
  out->name = text.substr(0, at);
  out->selector = at == std::string::npos ? "latest" : text.substr(at + 1);
  return !out->name.empty() && !out->selector.empty();
}

std::string LawReference::Format(const std::string& name, int version) {
  return name + "@" + std::to_string(version);
}

int LawReference::version_number() const {
  if (selector.empty() || selector.size() > 9 ||
      selector.find_first_not_of("0123456789") != std::string::npos) {
    return -1;
  }
  return std::stoi(selector);
}

namespace {

template <typename E, std::size_t N>
E parse_enum(const std::string& s, const std::pair<E, const char*> (&table)[N], const char* what) {
  std::string valid;
  for (const auto& entry : table) {
    if (s == entry.second) return entry.first;
    valid += (valid.empty() ? "" : ", ") + std::string(entry.second);
  }
  throw Error(ErrorCode::kInvalidArgument,
              std::string(what) + " '" + s + "' is not one of: " + valid);
}

template <typename E, std::size_t N>
const char* enum_name(E v, const std::pair<E, const char*> (&table)[N]) {
  for (const auto& entry : table) {
    if (v == entry.first) return entry.second;
  }
  return "unknown";
}

const std::pair<ForceKind, const char*> kForceKinds[] = {{ForceKind::kDragOnly, "drag_only"},
                                                         {ForceKind::kTotal, "total"}};
const std::pair<Normalisation, const char*> kNormalisations[] = {
    {Normalisation::kForce, "force"},
    {Normalisation::kBetaD2OverMuPhi, "beta_d2_over_mu_phi"},
    {Normalisation::kDragCoefficient, "drag_coefficient"}};
const std::pair<ReynoldsDefinition, const char*> kReynolds[] = {
    {ReynoldsDefinition::kSuperficialDiameter, "superficial_diameter"},
    {ReynoldsDefinition::kInterstitialDiameter, "interstitial_diameter"},
    {ReynoldsDefinition::kSuperficialRadius, "superficial_radius"}};
const std::pair<TfmModel, const char*> kTfmModels[] = {
    {TfmModel::kNotApplicable, "none"}, {TfmModel::kModelA, "A"}, {TfmModel::kModelB, "B"}};
const std::pair<LawStatus, const char*> kStatuses[] = {{LawStatus::kDraft, "draft"},
                                                       {LawStatus::kPublished, "published"},
                                                       {LawStatus::kRetracted, "retracted"}};

std::string exact(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

}  // namespace

std::string sha256_hex(const std::string& data) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(data.data(), data.size(), digest, &length, EVP_sha256(), nullptr) != 1) {
    throw Error(ErrorCode::kInternal, "SHA-256 computation failed");
  }
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < length; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

const char* to_string(ForceKind v) { return enum_name(v, kForceKinds); }
const char* to_string(Normalisation v) { return enum_name(v, kNormalisations); }
const char* to_string(ReynoldsDefinition v) { return enum_name(v, kReynolds); }
const char* to_string(TfmModel v) { return enum_name(v, kTfmModels); }
const char* to_string(LawStatus v) { return enum_name(v, kStatuses); }
ForceKind force_kind_from_string(const std::string& s) {
  return parse_enum(s, kForceKinds, "force kind");
}
Normalisation normalisation_from_string(const std::string& s) {
  return parse_enum(s, kNormalisations, "normalisation");
}
ReynoldsDefinition reynolds_definition_from_string(const std::string& s) {
  return parse_enum(s, kReynolds, "Reynolds definition");
}
TfmModel tfm_model_from_string(const std::string& s) {
  return parse_enum(s, kTfmModels, "TFM model");
}
LawStatus law_status_from_string(const std::string& s) {
  return parse_enum(s, kStatuses, "law status");
}

std::string content_hash_of(const LawRecord& r) {
  // Canonical text: keys in fixed order, doubles as %.17g strings (exact round trip), so the
  // hash does not depend on JSON number formatting.
  nlohmann::ordered_json j;
  j["form"] = r.form;
  nlohmann::ordered_json params = nlohmann::ordered_json::array();
  for (const LawParameter& p : r.parameters) {
    params.push_back({{"name", p.name}, {"value", exact(p.value)}, {"unit", p.unit}});
  }
  j["parameters"] = params;
  j["convention"] = {{"force", to_string(r.convention.force)},
                     {"normalisation", to_string(r.convention.normalisation)},
                     {"reynolds", to_string(r.convention.reynolds)},
                     {"tfm_model", to_string(r.convention.tfm_model)}};
  nlohmann::ordered_json extra = nlohmann::ordered_json::array();
  for (const ExtraInputSpec& e : r.validity.extra) {
    extra.push_back({{"name", e.name}, {"min", exact(e.range.min)}, {"max", exact(e.range.max)}});
  }
  j["validity"] = {{"phi", {exact(r.validity.phi.min), exact(r.validity.phi.max)}},
                   {"re", {exact(r.validity.re.min), exact(r.validity.re.max)}},
                   {"extra", extra}};
  return sha256_hex(j.dump());
}

LawRecord literature_record(const LawForm& form) {
  LawRecord r;
  r.name = form.key();
  r.form = form.key();
  for (const ParameterSpec& p : form.description.parameters) {
    r.parameters.push_back({p.name, p.value, p.unit});
  }
  r.convention = form.convention;
  r.validity = form.description.validity;
  r.provenance.kind = "literature";
  r.provenance.citation = form.description.citation;
  r.provenance.code_version = kDragDbVersion;
  r.notes = form.description.form_notes;
  r.content_hash = content_hash_of(r);
  return r;
}

}  // namespace draglab
