// tests/support/toml_edit.h: test variants of a shared TOML file (data/scenes/dpm_tiny.toml and
// the like) without a second copy: the file's text, and that text with single keys replaced,
// added or dropped. Every other line (comments, order, layout) is kept, so a variant differs from
// the shared file only by the keys a test names. The edits are those of toml_edit in
// tests/support/toml_edit.sh:
//   "table.key=VALUE"   replaces the key of [table] (it must be there)
//   "table.+key=VALUE"  adds the key at the end of [table]
//   "table.key=-"       drops the key (it must be there)
// and toml_without_table drops a whole table.
// VALUE is TOML as written in the file ("0.03", "\"dpm\"", "[\"ergun@1\"]"). A table or key that
// is not there throws std::invalid_argument: a variant that silently equals the shared file would
// test nothing new.
#pragma once

#include <fstream>
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace draglab {
namespace test {

/// The whole text of the file at `path`; throws std::runtime_error if it cannot be read.
inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// `toml` with one edit applied (see the file comment for the forms of `edit`).
inline std::string toml_edit(const std::string& toml, const std::string& edit) {
  const std::size_t dot = edit.find('.');
  const std::size_t eq = edit.find('=', dot == std::string::npos ? 0 : dot);
  if (dot == std::string::npos || eq == std::string::npos) {
    throw std::invalid_argument("toml_edit: '" + edit + "' is not table.key=VALUE");
  }
  const std::string table = edit.substr(0, dot);
  std::string key = edit.substr(dot + 1, eq - dot - 1);
  const std::string value = edit.substr(eq + 1);
  const bool add = !key.empty() && key[0] == '+';
  if (add) key.erase(0, 1);
  const bool drop = value == "-";

  std::vector<std::string> lines;
  std::istringstream in(toml);
  for (std::string line; std::getline(in, line);) lines.push_back(line);

  const auto trimmed_start = [](const std::string& s) { return s.find_first_not_of(" \t"); };
  const auto header_of = [&](const std::string& s) -> std::string {
    const std::size_t b = trimmed_start(s);
    if (b == std::string::npos || s[b] != '[') return {};
    const std::size_t e = s.find(']', b);
    return e == std::string::npos ? std::string() : s.substr(b + 1, e - b - 1);
  };
  const auto is_key_line = [&](const std::string& s) {
    const std::size_t b = trimmed_start(s);
    if (b == std::string::npos || s.compare(b, key.size(), key) != 0) return false;
    const std::size_t after = s.find_first_not_of(" \t", b + key.size());
    return after != std::string::npos && s[after] == '=';
  };

  bool in_table = false, table_found = false, done = false;
  std::size_t last_of_table = 0;  // index of the table's last non-blank line
  for (std::size_t i = 0; i < lines.size() && !done; ++i) {
    const std::string header = header_of(lines[i]);
    if (!header.empty()) {
      if (in_table) break;  // the table ended without the key
      in_table = header == table;
      table_found = table_found || in_table;
      if (in_table) last_of_table = i;
      continue;
    }
    if (!in_table) continue;
    if (trimmed_start(lines[i]) != std::string::npos) last_of_table = i;
    if (!add && is_key_line(lines[i])) {
      if (drop) {
        lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(i));
      } else {
        lines[i] = key + " = " + value;
      }
      done = true;
    }
  }
  if (!table_found) throw std::invalid_argument("toml_edit: no table [" + table + "]");
  if (add) {
    lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(last_of_table) + 1,
                 key + " = " + value);
  } else if (!done) {
    throw std::invalid_argument("toml_edit: no key " + key + " in [" + table + "]");
  }
  std::string out;
  for (const std::string& line : lines) out += line + "\n";
  return out;
}

/// `toml` with the edits applied in order.
inline std::string toml_edit(std::string toml, std::initializer_list<std::string> edits) {
  for (const std::string& edit : edits) toml = toml_edit(toml, edit);
  return toml;
}

/// `toml` without [table]: its header and every line up to the next table (a model that refuses
/// another model's table). Throws std::invalid_argument when there is no [table].
inline std::string toml_without_table(const std::string& toml, const std::string& table) {
  std::istringstream in(toml);
  std::string out;
  bool skipping = false, found = false;
  for (std::string line; std::getline(in, line);) {
    const std::size_t b = line.find_first_not_of(" \t");
    if (b != std::string::npos && line[b] == '[') {
      const std::size_t e = line.find(']', b);
      skipping = e != std::string::npos && line.substr(b + 1, e - b - 1) == table;
      found = found || skipping;
    }
    if (!skipping) out += line + "\n";
  }
  if (!found) throw std::invalid_argument("toml_without_table: no table [" + table + "]");
  return out;
}

}  // namespace test
}  // namespace draglab
