// Small helpers shared by the scene sources (private to consumers/src/scene).
#pragma once

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

}  // namespace scene_util
}  // namespace consumers
}  // namespace draglab
