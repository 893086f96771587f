// Small helpers shared by the scene sources (private to consumers/src/scene).
#pragma once

#include <cmath>
#include <string>

#include "draglab/core/text.h"

namespace draglab {
namespace consumers {
namespace scene_util {

constexpr double kPi = 3.14159265358979323846;

/// A value for a message, with `digits` significant digits.
inline std::string fmt(double x, int digits = 6) { return core::format_number(x, digits); }

/// IsValid() helper: stores `message` in *error (if given) and returns false.
inline bool fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

/// lo < x <= hi (open_lo) or lo <= x <= hi, finite; else a message naming field and range.
inline bool in_range(double x, double lo, double hi, bool open_lo, bool open_hi,
                     const std::string& field, const std::string& unit, std::string* error) {
  const bool ok = std::isfinite(x) && (open_lo ? x > lo : x >= lo) && (open_hi ? x < hi : x <= hi);
  if (ok) return true;
  return fail(error, field + " = " + fmt(x) + " is outside " + (open_lo ? "(" : "[") + fmt(lo) +
                         ", " + fmt(hi) + (open_hi ? ")" : "]") + (unit.empty() ? "" : " " + unit));
}

}  // namespace scene_util
}  // namespace consumers
}  // namespace draglab
