// draglab/core/text.h: numbers in messages, and the comma-separated lists of the command line and
// the scene and campaign files (laws a@1,b@1, parameters a,b,c0, numbers 0.1,0.2), parsed one way
// everywhere. Errors: draglab::Error(kInvalidArgument) naming `field`, the offending item and an
// example.
#pragma once

#include <string>
#include <vector>

namespace draglab {
namespace core {

/// The items of "a,b,c". An empty item ("a,,b", a trailing comma, an empty text) is refused.
std::vector<std::string> split_list(const std::string& text, const std::string& field,
                                    const std::string& example = "a,b,c");

/// The numbers of "0.1,0.2,0.3": each item a whole decimal number (strtod reads all of it);
/// nan and inf are numbers here, ranges are the caller's to check.
std::vector<double> parse_number_list(const std::string& text, const std::string& field,
                                      const std::string& example = "0.1,0.2,0.3");

/// x with `digits` significant digits (printf %g): the numbers of messages and tables.
std::string format_number(double x, int digits = 6);

/// Numbers in a printf format of a message that needs one ("%.3g", "%.1f %%", "%g x %g"); up to
/// four, passed as doubles (the format must read them so). Plain numbers take format_number.
std::string format_fixed(const char* format, double a, double b = 0.0, double c = 0.0,
                         double d = 0.0);

}  // namespace core
}  // namespace draglab
