// Regressions found by fuzz/fuzz_campaign_spec (scripts/fuzz.sh campaign_spec): each input is
// answered with a clear Error(kInvalidArgument) or parses as TOML says, without undefined
// behaviour (the sanitizer build, ./test.sh --sanitize, fails on any UB report).
#include <gtest/gtest.h>

#include <string>

#include "draglab/campaign/campaign.h"
#include "draglab/error.h"

namespace draglab {
namespace campaign {
namespace {

const char* kSpec = R"(
[campaign]
name = "fuzz"
description = """first line \
   %s"""
[grid]
phi = [0.1]
re = [0]
[packing]
spheres = 16
[lbm]
resolutions = [10]
[dataset]
extrapolation = "finest"
)";

std::string spec_with_description_line(const std::string& line) {
  std::string text = kSpec;
  text.replace(text.find("%s"), 2, line);
  return text;
}

std::string error_of(const std::string& text) {
  try {
    parse_campaign_spec_text(text, "fuzz.toml");
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
    return e.what();
  }
  return "";
}

// toml++ 3.3.0 reached __builtin_unreachable() when it asked whether a character of U+00A1 ..
// U+049A (Latin-1 letters, Greek, Cyrillic) was whitespace: for a stray letter outside strings
// (the fuzzer's input was the two bytes of "Î" alone), a quoted key, or the first character of a
// line continued by a line-ending backslash (core/include/draglab/core/tomlpp.h).
TEST(SpecFuzzRegression, NonAsciiLetterOutsideStringsIsInvalidToml) {
  for (const std::string& text : {std::string("\xC3\x8E"), std::string("\xCF\xBC"),
                                  std::string("[campaign]\nname = \"x\" \xC3\xA9\n")}) {
    const std::string message = error_of(text);
    EXPECT_NE(message.find("not valid TOML"), std::string::npos) << message;
  }
}

TEST(SpecFuzzRegression, NonAsciiQuotedKeyIsAnUnknownKey) {
  const std::string message = error_of("[campaign]\n\"caf\xC3\xA9\" = 1\n");
  EXPECT_NE(message.find("unknown key 'caf\xC3\xA9' in [campaign]"), std::string::npos) << message;
}

TEST(SpecFuzzRegression, ContinuedLineStartingWithNonAsciiLetter) {
  const CampaignSpec spec =
      parse_campaign_spec_text(spec_with_description_line("\xC3\xA9t\xC3\xA9"), "fuzz.toml");
  EXPECT_EQ(spec.description, "first line \xC3\xA9t\xC3\xA9");
  // Non-ASCII whitespace after a continuation is skipped like a space (toml++'s reading).
  EXPECT_EQ(
      parse_campaign_spec_text(spec_with_description_line("\xC2\xA0x"), "fuzz.toml").description,
      "first line x");
}

}  // namespace
}  // namespace campaign
}  // namespace draglab
