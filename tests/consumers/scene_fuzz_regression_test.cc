// Regressions found by fuzzing the TOML readers (fuzz/fuzz_scene, fuzz/fuzz_campaign_spec; see
// fuzz/README.md): each input is answered with a clear Error(kInvalidArgument) or parses as TOML
// says, without undefined behaviour (./test.sh --sanitize fails on any UB report).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "draglab/consumers/scene.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

std::string shipped_scene(const std::string& name) {
  std::ifstream in(std::string(DRAGLAB_DATA_DIR) + "/scenes/" + name);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string error_of(const std::string& text) {
  try {
    parse_scene(text, "fuzz.toml");
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument) << e.what();
    return e.what();
  }
  return "";
}

// toml++ 3.3.0 reached __builtin_unreachable() when it asked whether a character of U+00A1 ..
// U+049A (Latin-1 letters, Greek, Cyrillic) was whitespace (core/include/draglab/core/tomlpp.h).
TEST(SceneFuzzRegression, NonAsciiLetterOutsideStringsIsInvalidToml) {
  for (const std::string& text : {std::string("\xC3\x8E"), std::string("[scene]\n\xC2\xB5 = 1\n"),
                                  std::string("[scene]\nname = \"x\" \xC3\xA9\n")}) {
    const std::string message = error_of(text);
    EXPECT_NE(message.find("not valid TOML"), std::string::npos) << message;
  }
}

TEST(SceneFuzzRegression, NonAsciiQuotedKeyIsAnUnknownKey) {
  const std::string message = error_of("[scene]\n\"\xCE\xB5_mf\" = 0.4\n");
  EXPECT_NE(message.find("unknown key '\xCE\xB5_mf' in [scene]"), std::string::npos) << message;
}

TEST(SceneFuzzRegression, ContinuedDescriptionStartingWithNonAsciiLetter) {
  std::string text = shipped_scene("dpm_bubble_quick.toml");
  const std::size_t scene = text.find("[scene]\n");
  ASSERT_NE(scene, std::string::npos);
  text.insert(scene + 8, "description = \"\"\"d = 2.5 mm, \\\n  \xCF\x81 = 2526 kg/m3\"\"\"\n");
  // The shipped scene may have its own description: keep only ours.
  const std::size_t theirs = text.find("\ndescription = \"", scene + 8);
  if (theirs != std::string::npos) text.erase(theirs, text.find('\n', theirs + 1) - theirs);
  const Scene s = parse_scene(text, "fuzz.toml");
  EXPECT_EQ(s.description, "d = 2.5 mm, \xCF\x81 = 2526 kg/m3");
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
