// core/src/text.cc: see draglab/core/text.h.
#include "draglab/core/text.h"

#include <cstdio>
#include <cstdlib>

#include "draglab/error.h"

namespace draglab {
namespace core {

std::vector<std::string> split_list(const std::string& text, const std::string& field,
                                    const std::string& example) {
  std::vector<std::string> items;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (item.empty()) {
      throw Error(ErrorCode::kInvalidArgument,
                  field + ": empty entry in '" + text + "' (expected e.g. " + example + ")");
    }
    items.push_back(item);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return items;
}

std::vector<double> parse_number_list(const std::string& text, const std::string& field,
                                      const std::string& example) {
  std::vector<double> values;
  for (const std::string& item : split_list(text, field, example)) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || *end != '\0') {
      throw Error(ErrorCode::kInvalidArgument,
                  field + ": '" + item + "' is not a number (expected e.g. " + example + ")");
    }
    values.push_back(v);
  }
  return values;
}

std::string format_number(double x, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", digits, x);
  return text;
}

std::string format_fixed(const char* format, double a, double b, double c, double d) {
  char text[256];
  std::snprintf(text, sizeof text, format, a, b, c, d);
  return text;
}

}  // namespace core
}  // namespace draglab
