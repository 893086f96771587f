// core/toml_schema.h, core/xdmf.h and core::format_number: the readers' shared messages and the
// writers' shared pieces.
//
// References: the TOML 1.0 specification (integers are not floats; a number where a table is
// expected is a value, not a section); XDMF 2 (Dimensions slowest axis first); printf %g.
#include <gtest/gtest.h>

#include <string>

#include "draglab/core/text.h"
#include "draglab/core/toml_schema.h"
#include "draglab/core/xdmf.h"
#include "draglab/error.h"

namespace draglab {
namespace {

namespace ts = core::toml_schema;

const ts::Schema kSchema = {{"grid", {"phi", "re", "seed"}}, {"lbm", {"collision", "fast"}}};

std::string error_of(const std::string& text) {
  try {
    const toml::table root = ts::parse(text, "spec.toml");
    ts::visit(root, "spec.toml", kSchema, nullptr, [](const ts::Entry& e) {
      if (e.key == "phi") ts::numbers(e.node, e.field, e.at);
      if (e.key == "seed") ts::integer(e.node, e.field, e.at);
      if (e.key == "collision") ts::text(e.node, e.field, e.at);
      if (e.key == "fast") ts::boolean(e.node, e.field, e.at);
    });
  } catch (const Error& e) {
    EXPECT_TRUE(e.is_bad_input());
    return e.what();
  }
  return "";
}

TEST(TomlSchema, ValidFileVisitsEveryKeyInOrderWithFieldAndLine) {
  const toml::table root = ts::parse("[grid]\nphi = [0.1, 2]\n\nseed = 7\n", "spec.toml");
  std::string seen;
  std::vector<std::string> sections;
  ts::visit(
      root, "spec.toml", kSchema,
      [&](const std::string& s, const toml::table&, const std::string&) { sections.push_back(s); },
      [&](const ts::Entry& e) { seen += e.field + "@" + e.at + ";"; });
  EXPECT_EQ(sections, std::vector<std::string>{"grid"});
  EXPECT_EQ(seen, "[grid] phi@spec.toml:2;[grid] seed@spec.toml:4;");
  EXPECT_EQ(ts::numbers(*root["grid"]["phi"].node(), "[grid] phi", "x"),
            (std::vector<double>{0.1, 2.0}));  // an integer in a list of numbers is a number
  EXPECT_EQ(ts::numbers(*root["grid"]["seed"].node(), "f", "x"), std::vector<double>{7.0});
}

TEST(TomlSchema, MessagesNameWhereWhatAndTheValidNames) {
  EXPECT_NE(error_of("[grid\n").find("spec.toml:1: not valid TOML"), std::string::npos);
  const std::string section = error_of("[gird]\nphi = 1\n");
  EXPECT_NE(section.find("unknown section or key 'gird'"), std::string::npos) << section;
  EXPECT_NE(section.find("[grid], [lbm]"), std::string::npos) << section;
  const std::string key = error_of("[lbm]\ncolision = \"trt\"\n");
  EXPECT_NE(key.find("spec.toml:2: unknown key 'colision' in [lbm]; valid keys: collision, fast"),
            std::string::npos)
      << key;
  EXPECT_NE(error_of("grid = 3\n").find("'grid' must be a [section]"), std::string::npos);
  EXPECT_NE(error_of("[grid]\nseed = 1.5\n").find("[grid] seed must be an integer"),
            std::string::npos);
  EXPECT_NE(error_of("[grid]\nphi = [0.1, \"x\"]\n").find("[grid] phi[1] must be a number"),
            std::string::npos);
  EXPECT_NE(error_of("[lbm]\ncollision = 3\n").find("must be a string"), std::string::npos);
  EXPECT_NE(error_of("[lbm]\nfast = 1\n").find("must be true or false"), std::string::npos);
  EXPECT_EQ(error_of("[lbm]\nfast = true\ncollision = \"trt\"\n"), "");
}

TEST(Xdmf, EscapesAndOrdersAxesSlowestFirst) {
  EXPECT_EQ(core::xdmf::escape("a&b<c>\"d"), "a&amp;b&lt;c&gt;&quot;d");
  EXPECT_EQ(core::xdmf::cell_dims(4, 3, 2), "2 3 4");
  const std::string mesh = core::xdmf::corect_mesh(4, 3, 2, 0.1, 0.2, 0.3, "");
  EXPECT_NE(mesh.find("Dimensions=\"3 4 5\""), std::string::npos) << mesh;     // points z y x
  EXPECT_NE(mesh.find(">0.3 0.2 0.1</DataItem>"), std::string::npos) << mesh;  // dz dy dx
  EXPECT_EQ(core::xdmf::hdf_item("2 3 4", "Float", 8, "a&b.h5", "/f/rho", ""),
            "<DataItem Dimensions=\"2 3 4\" NumberType=\"Float\" Precision=\"8\" "
            "Format=\"HDF\">a&amp;b.h5:/f/rho</DataItem>\n");
  EXPECT_EQ(core::xdmf::number(0.025), "0.025");  // shortest text that reads back
  EXPECT_EQ(std::stod(core::xdmf::number(0.1 + 0.2)), 0.1 + 0.2);
}

TEST(FormatNumber, SignificantDigitsAsPrintfG) {
  EXPECT_EQ(core::format_number(0.123456789), "0.123457");
  EXPECT_EQ(core::format_number(1e-30), "1e-30");
  EXPECT_EQ(core::format_number(2.5, 2), "2.5");
  EXPECT_EQ(core::format_number(12345.0, 2), "1.2e+04");
}

}  // namespace
}  // namespace draglab
