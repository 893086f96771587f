// draglab/core/toml_schema.h: reading a TOML input file (campaign spec, scene) against its
// schema, so that every reader gives the same messages: where (file:line), which field
// ("[section] key"), what was expected, and the valid sections and keys when one is unknown.
// Errors are draglab::Error(kInvalidArgument): bad input, exit code 2 on the command line.
// Ranges are the caller's (its options' IsValid); types and names are checked here.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "draglab/core/tomlpp.h"

namespace draglab {
namespace core {
namespace toml_schema {

/// The sections of a file and the keys each accepts, in documentation order.
using Schema = std::vector<std::pair<std::string, std::vector<std::string>>>;

/// Parses `text`; a syntax error names origin:line and toml++'s description.
toml::table parse(const std::string& text, const std::string& origin);

/// "origin:line" of a node (origin alone when toml++ has no position for it).
std::string where(const std::string& origin, const toml::node& node);

/// "a, b, c".
std::string join(const std::vector<std::string>& items);

/// Typed values; `field` ("[grid] re") and `at` (where()) name the value in the message.
double number(const toml::node& n, const std::string& field, const std::string& at);
std::int64_t integer(const toml::node& n, const std::string& field, const std::string& at);
std::string text(const toml::node& n, const std::string& field, const std::string& at);
bool boolean(const toml::node& n, const std::string& field, const std::string& at);
/// A list of numbers (element i named field[i]); a single number is a list of one.
std::vector<double> numbers(const toml::node& n, const std::string& field, const std::string& at);

/// One key as found in the file.
struct Entry {
  const std::string& section;
  const std::string& key;
  const toml::node& node;
  std::string field;  ///< "[section] key"
  std::string at;     ///< where(origin, node)
};

/// Checks every top-level entry of `root` against `schema` (an unknown section or key, or a
/// value where a [section] belongs, is refused with the valid names), calls `on_section` (if
/// given) for each section before its keys, then `on_key` for each key in file order.
void visit(const toml::table& root, const std::string& origin, const Schema& schema,
           const std::function<void(const std::string& section, const toml::table& table,
                                    const std::string& at)>& on_section,
           const std::function<void(const Entry& entry)>& on_key);

}  // namespace toml_schema
}  // namespace core
}  // namespace draglab
