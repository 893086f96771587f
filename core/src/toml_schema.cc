// core/src/toml_schema.cc: see draglab/core/toml_schema.h.
#include "draglab/core/toml_schema.h"

#include "draglab/error.h"

namespace draglab {
namespace core {
namespace toml_schema {
namespace {

[[noreturn]] void bad(const std::string& message) {
  throw Error(ErrorCode::kInvalidArgument, message);
}

}  // namespace

toml::table parse(const std::string& text, const std::string& origin) {
  try {
    return toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    bad(origin + ":" + std::to_string(e.source().begin.line) +
        ": not valid TOML: " + std::string(e.description()));
  }
}

std::string where(const std::string& origin, const toml::node& node) {
  const auto& src = node.source();
  if (src.begin.line == 0) return origin;
  return origin + ":" + std::to_string(src.begin.line);
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& i : items) out += (out.empty() ? "" : ", ") + i;
  return out;
}

double number(const toml::node& n, const std::string& field, const std::string& at) {
  if (auto v = n.value_exact<double>()) return *v;
  if (auto i = n.value_exact<std::int64_t>()) return static_cast<double>(*i);
  bad(at + ": " + field + " must be a number");
}

std::int64_t integer(const toml::node& n, const std::string& field, const std::string& at) {
  if (auto i = n.value_exact<std::int64_t>()) return *i;
  bad(at + ": " + field + " must be an integer");
}

std::string text(const toml::node& n, const std::string& field, const std::string& at) {
  if (auto s = n.value_exact<std::string>()) return *s;
  bad(at + ": " + field + " must be a string");
}

bool boolean(const toml::node& n, const std::string& field, const std::string& at) {
  if (auto b = n.value_exact<bool>()) return *b;
  bad(at + ": " + field + " must be true or false");
}

std::vector<double> numbers(const toml::node& n, const std::string& field, const std::string& at) {
  std::vector<double> out;
  if (const toml::array* a = n.as_array()) {
    for (std::size_t i = 0; i < a->size(); ++i) {
      out.push_back(number(*a->get(i), field + "[" + std::to_string(i) + "]", at));
    }
    return out;
  }
  out.push_back(number(n, field, at));
  return out;
}

void visit(const toml::table& root, const std::string& origin, const Schema& schema,
           const std::function<void(const std::string& section, const toml::table& table,
                                    const std::string& at)>& on_section,
           const std::function<void(const Entry& entry)>& on_key) {
  std::vector<std::string> section_names;
  for (const auto& [name, keys] : schema) section_names.push_back("[" + name + "]");
  for (const auto& [section_key, section_node] : root) {
    const std::string section(section_key.str());
    const std::vector<std::string>* keys = nullptr;
    for (const auto& [name, k] : schema) {
      if (name == section) keys = &k;
    }
    if (!keys) {
      bad(where(origin, section_node) + ": unknown section or key '" + section +
          "' at the top level; valid sections: " + join(section_names));
    }
    const toml::table* table = section_node.as_table();
    if (!table) bad(where(origin, section_node) + ": '" + section + "' must be a [section]");
    if (on_section) on_section(section, *table, where(origin, section_node));
    for (const auto& [key_name, node] : *table) {
      const std::string key(key_name.str());
      bool known = false;
      for (const auto& k : *keys) known = known || k == key;
      if (!known) {
        bad(where(origin, node) + ": unknown key '" + key + "' in [" + section +
            "]; valid keys: " + join(*keys));
      }
      on_key(Entry{section, key, node, "[" + section + "] " + key, where(origin, node)});
    }
  }
}

}  // namespace toml_schema
}  // namespace core
}  // namespace draglab
