// The registry of law forms: filled at load time by DRAGLAB_REGISTER_LAW_FORM.
#include <map>
#include <mutex>

#include "draglab/drag_db/law_form.h"
#include "draglab/error.h"

namespace draglab {
namespace {

struct Registry {
  std::mutex mutex;
  std::map<std::string, LawForm> forms;  // std::map: stable addresses, sorted keys
};

Registry& registry() {
  static Registry* instance = new Registry();  // never destroyed: forms outlive static teardown
  return *instance;
}

}  // namespace

std::vector<double> LawForm::default_parameters() const {
  std::vector<double> values;
  values.reserve(description.parameters.size());
  for (const ParameterSpec& p : description.parameters) values.push_back(p.value);
  return values;
}

void register_law_form(const LawForm& form) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (static_cast<int>(form.description.parameters.size()) != form.num_parameters ||
      static_cast<int>(form.description.validity.extra.size()) != form.num_extra_inputs) {
    throw Error(ErrorCode::kInternal,
                "law form '" + form.description.key + "': parameter or extra-input count mismatch");
  }
  if (!r.forms.emplace(form.description.key, form).second) {
    throw Error(ErrorCode::kInternal, "law form key registered twice: " + form.description.key);
  }
}

const LawForm& find_law_form(const std::string& key) {
  Registry& r = registry();
  {
    std::lock_guard<std::mutex> lock(r.mutex);
    auto it = r.forms.find(key);
    if (it != r.forms.end()) return it->second;
  }
  throw Error(ErrorCode::kNotFound,
              "unknown law form '" + key + "'; valid forms are: " + law_form_keys());
}

std::vector<const LawForm*> all_law_forms() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<const LawForm*> out;
  for (const auto& kv : r.forms) out.push_back(&kv.second);
  return out;
}

std::string law_form_keys() {
  std::string keys;
  for (const LawForm* f : all_law_forms()) {
    if (!keys.empty()) keys += ", ";
    keys += f->key();
  }
  return keys;
}

}  // namespace draglab
