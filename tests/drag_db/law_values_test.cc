// Literature drag-law forms against reference values and exact identities.
//
// Set-up: every registered form evaluated with its published parameters (form.F, no validity
// check, so tabulated points outside a law's box are compared too). References, all in data/:
//   law_check_values.csv             the reference dossier's check values (6 significant figures)
//   random_array_stokes_table.csv    dossier section 2.3, Re -> 0 (4 significant figures)
//   random_array_finite_re_table.csv dossier section 2.4, finite Re (4 significant figures)
//   law_check_values_independent.csv an independent Python evaluation of the published formulas
//                                    (data/generators/law_check_values_independent.py; 12 digits)
//   law_anchor_values.csv            textbook and seed-paper anchors (Stokes, Oseen, Dalla Valle,
//                                    Schiller-Naumann, Carman-Kozeny, the seed's C_d(inf) values)
// Tolerances: a printed table value is met when our value rounds to it, i.e. the difference is at
// most half a unit of its last printed digit (plus 1e-12 relative for our own rounding). The
// independent evaluation is compared at 1e-10 relative: 12 printed digits round at 5e-12, and the
// two codes evaluate the same formulas in different orders, which costs < 1e-13 (the largest
// cancellation is Syamlal-O'Brien's V_r at Re_p ~ 1e4: 600 - 600 + 0.3, i.e. ~2e-13).
// Identities between laws (gidaspow == ergun / wen_yu, tang2015 == bvk2007 == vdh2005 at Re = 0,
// ...) are checked bit for bit where the code shares the operations, otherwise to 4 ulps.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "draglab/drag_db/conventions.h"
#include "draglab/drag_db/law_form.h"

namespace draglab {
namespace {

// ---- A small CSV reader: '#' lines are comments, the first other line is the header. ----------

struct CsvCell {
  std::string text;
  double value() const { return std::stod(text); }
  bool empty() const { return text.empty(); }
  /// Half a unit of the last printed digit of a decimal number ("263.6" -> 0.05, "1255" -> 0.5).
  double half_unit_of_last_digit() const {
    std::string mantissa = text;
    const std::size_t e = mantissa.find_first_of("eE");
    int exponent = 0;
    if (e != std::string::npos) {
      exponent = std::stoi(mantissa.substr(e + 1));
      mantissa = mantissa.substr(0, e);
    }
    const std::size_t dot = mantissa.find('.');
    const int decimals = dot == std::string::npos ? 0 : static_cast<int>(mantissa.size() - dot - 1);
    return 0.5 * std::pow(10.0, exponent - decimals);
  }
};

struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::map<std::string, CsvCell>> rows;
};

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(item);
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

CsvTable read_csv(const std::string& name) {
  const std::string path = std::string(DRAGLAB_DATA_DIR) + "/" + name;
  std::ifstream in(path);
  CsvTable table;
  if (!in) {
    ADD_FAILURE() << "cannot open " << path;
    return table;
  }
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> cells = split(line);
    if (table.columns.empty()) {
      table.columns = cells;
      continue;
    }
    EXPECT_EQ(cells.size(), table.columns.size()) << name << ": " << line;
    std::map<std::string, CsvCell> row;
    for (std::size_t i = 0; i < cells.size() && i < table.columns.size(); ++i) {
      row[table.columns[i]] = CsvCell{cells[i]};
    }
    table.rows.push_back(row);
  }
  EXPECT_FALSE(table.rows.empty()) << name;
  return table;
}

// ---- Evaluation helpers ------------------------------------------------------------------------

double eval(const std::string& key, double phi, double re, std::vector<double> params = {},
            const double* extra = nullptr) {
  const LawForm& form = find_law_form(key);
  if (params.empty()) params = form.default_parameters();
  const double one = 1.0;  // representative extra input (y = 1) when none is given
  if (form.num_extra_inputs > 0 && extra == nullptr) extra = &one;
  return form.F(phi, re, extra, params.data());
}

std::vector<double> with(const std::string& key, const std::map<std::string, double>& changes) {
  const LawForm& form = find_law_form(key);
  std::vector<double> p = form.default_parameters();
  for (const auto& change : changes) {
    bool found = false;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (form.description.parameters[i].name == change.first) {
        p[i] = change.second;
        found = true;
      }
    }
    EXPECT_TRUE(found) << key << " has no parameter " << change.first;
  }
  return p;
}

/// Our value rounds to the printed table value. `units` = allowed difference in units of the last
/// printed digit: 0.5 for a correctly rounded table.
void expect_matches_printed(const std::string& what, double ours, const CsvCell& table,
                            double units = 0.5) {
  const double tolerance = 2.0 * units * table.half_unit_of_last_digit() + 1e-12 * std::fabs(ours);
  EXPECT_NEAR(ours, table.value(), tolerance) << what << " (table prints " << table.text << ")";
}

// ---- Reference tables --------------------------------------------------------------------------

TEST(LawValues, DossierCheckValues) {
  const CsvTable t = read_csv("law_check_values.csv");
  for (const auto& row : t.rows) {
    const std::string law = row.at("law").text;
    const double phi = row.at("phi").value(), re = row.at("Re").value();
    expect_matches_printed(law + " phi=" + row.at("phi").text + " Re=" + row.at("Re").text,
                           eval(law, phi, re), row.at("F"));
  }
}

// The dossier's 4-digit tables were rounded twice (6 -> 5 -> 4 significant figures): e.g. seed04 at
// phi = 0.1 is 2.56148 (6 digits in law_check_values.csv, and ours) -> 2.5615 -> 2.562, tenneti at
// 0.1 is 2.25747 -> 2.258, HKL at (0.4, 100) is 24.6247 -> 24.63. Double rounding through one extra
// digit errs by at most 0.5 + 0.05 units of the last digit, which is the tolerance used for them.
constexpr double kDoubleRoundedUnits = 0.55;

TEST(LawValues, RandomArrayStokesTable) {
  const CsvTable t = read_csv("random_array_stokes_table.csv");
  for (const auto& row : t.rows) {
    const double phi = row.at("phi").value();
    const std::string at = " phi=" + row.at("phi").text;
    for (const char* law : {"vdh2005", "bvk2007", "tang2015"}) {
      expect_matches_printed(law + at, eval(law, phi, 0.0), row.at("vdh05"), kDoubleRoundedUnits);
    }
    expect_matches_printed("vdh2004" + at, eval("vdh2004", phi, 0.0), row.at("seed04"),
                           kDoubleRoundedUnits);
    expect_matches_printed("tenneti2011" + at, eval("tenneti2011", phi, 0.0), row.at("tgs_eps"),
                           kDoubleRoundedUnits);
    // The table's HKL columns are F0 x (1-phi). For phi <= 0.01 the law (MFiX) uses the Oseen
    // branch instead (documented deviation, checked below); F0 is seen just above 0.01.
    const double phi_hkl = phi <= 0.01 ? phi + 1e-12 : phi;
    expect_matches_printed("hill_koch_ladd" + at, eval("hill_koch_ladd", phi_hkl, 0.0),
                           row.at("hkl_17_14"), kDoubleRoundedUnits);
    // CFDEM's 16.14 column is not our law, but our form reproduces it with c0 = 16.14.
    expect_matches_printed(
        "hill_koch_ladd(c0=16.14)" + at,
        eval("hill_koch_ladd", phi_hkl, 0.0, with("hill_koch_ladd", {{"c0", 16.14}})),
        row.at("hkl_16_14"), kDoubleRoundedUnits);
    if (phi >= 0.4) {
      expect_matches_printed("hill_koch_ladd (Carman-Kozeny)" + at,
                             eval("hill_koch_ladd", phi, 0.0), row.at("ck"), kDoubleRoundedUnits);
    }
  }
  // Documented deviation at phi = 0.01: MFiX's branch "phis <= 0.01 -> 1 + 3/8 Re_a" gives K = 1.
  EXPECT_DOUBLE_EQ(eval("hill_koch_ladd", 0.01, 0.0), 0.99);
}

TEST(LawValues, RandomArrayFiniteReTable) {
  const CsvTable t = read_csv("random_array_finite_re_table.csv");
  const std::vector<std::pair<std::string, std::string>> columns = {
      {"bvk07", "bvk2007"},
      {"tang15", "tang2015"},
      {"seed04", "vdh2004"},
      {"tgs_eps", "tenneti2011"},
      {"ergun", "ergun"},
      {"wen_yu", "wen_yu"},
      {"hkl_mfix_eps", "hill_koch_ladd"}};
  int compared = 0;
  for (const auto& row : t.rows) {
    const double phi = row.at("phi").value(), re = row.at("Re").value();
    for (const auto& column : columns) {
      const CsvCell& cell = row.at(column.first);
      if (cell.empty()) continue;
      const std::string what =
          column.second + " phi=" + row.at("phi").text + " Re=" + row.at("Re").text;
      if (column.second == "wen_yu" && re == 1000.0) {
        // Documented deviation: this table takes Schiller-Naumann's Newton arm at Re = 1000 (the
        // seed's and OpenFOAM's "Re < 1000"); the law uses MFiX's Re <= 1000 (as does
        // law_check_values.csv, 229.249 at phi = 0.5). The table is the value just above 1000.
        const double above = std::nextafter(1000.0, 2000.0);
        expect_matches_printed(what + " (Newton arm)", eval("wen_yu", phi, above), cell,
                               kDoubleRoundedUnits);
        EXPECT_GT(std::fabs(eval("wen_yu", phi, re) - cell.value()), 0.003 * cell.value());
      } else {
        expect_matches_printed(what, eval(column.second, phi, re), cell, kDoubleRoundedUnits);
      }
      ++compared;
    }
  }
  EXPECT_EQ(compared, 14 * 7 - 3);
}

TEST(LawValues, IndependentPythonEvaluation) {
  const CsvTable t = read_csv("law_check_values_independent.csv");
  std::map<std::string, int> per_law;
  for (const auto& row : t.rows) {
    const std::string law = row.at("law").text;
    const double phi = row.at("phi").value(), re = row.at("Re").value();
    double y = 1.0;
    const double* extra = nullptr;
    if (!row.at("y").empty()) {
      y = row.at("y").value();
      extra = &y;
    }
    const double reference = row.at("F").value();
    EXPECT_NEAR(eval(law, phi, re, {}, extra), reference, 1e-10 * std::fabs(reference))
        << law << " phi=" << phi << " Re=" << re << " y=" << y;
    ++per_law[law];
  }
  // Every law without values in the dossier's tables is covered here.
  for (const char* law : {"schiller_naumann", "gidaspow", "gidaspow_blend", "syamlal_obrien",
                          "di_felice", "rong2013", "hill_koch_ladd", "bvk2007_poly", "vdh2005",
                          "vdh2005_poly", "hys2010", "tenneti2011", "wen_yu"}) {
    EXPECT_GE(per_law[law], 5) << law;
  }
}

TEST(LawValues, TextbookAndSeedAnchors) {
  const CsvTable t = read_csv("law_anchor_values.csv");
  for (const auto& row : t.rows) {
    const std::string law = row.at("law").text;
    const double phi = row.at("phi").value(), re = row.at("Re").value();
    const double F = eval(law, phi, re);
    const std::string quantity = row.at("quantity").text;
    const double value = quantity == "Cd" ? conventions::drag_coefficient(phi, re, F) : F;
    ASSERT_TRUE(quantity == "F" || quantity == "Cd") << quantity;
    EXPECT_NEAR(value, row.at("value").value(), row.at("tolerance").value())
        << law << " " << quantity << " at phi=" << phi << " Re=" << re << ": "
        << row.at("note").text;
  }
}

// ---- Exact relations between laws --------------------------------------------------------------

TEST(LawValues, GidaspowIsErgunBelowAndWenYuAboveTheSwitch) {
  for (double re : {0.0, 0.5, 10.0, 300.0, 1000.0, 5000.0}) {
    for (double phi = 0.0; phi <= 0.65; phi += 0.0125) {
      const double gidaspow = eval("gidaspow", phi, re);
      if (1.0 - phi <= 0.8) {
        EXPECT_EQ(gidaspow, eval("ergun", phi, re)) << "phi=" << phi << " Re=" << re;
      } else {
        EXPECT_EQ(gidaspow, eval("wen_yu", phi, re)) << "phi=" << phi << " Re=" << re;
      }
    }
  }
}

TEST(LawValues, GidaspowBlendLiesBetweenErgunAndWenYu) {
  for (double re : {0.0, 1.0, 100.0, 2000.0}) {
    for (double phi = 0.0; phi <= 0.65; phi += 0.01) {
      const double e = eval("ergun", phi, re), w = eval("wen_yu", phi, re);
      const double blend = eval("gidaspow_blend", phi, re);
      EXPECT_LE(blend, std::max(e, w) * (1 + 1e-15)) << phi << " " << re;
      EXPECT_GE(blend, std::min(e, w) * (1 - 1e-15)) << phi << " " << re;
    }
    // At eps = 0.8 the arctan weight is exactly 1/2 (phi = 0.2 gives eps = 0.8 in binary too).
    ASSERT_EQ(1.0 - 0.2, 0.8);
    EXPECT_NEAR(eval("gidaspow_blend", 0.2, re),
                0.5 * (eval("ergun", 0.2, re) + eval("wen_yu", 0.2, re)),
                1e-15 * eval("ergun", 0.2, re));
  }
}

TEST(LawValues, StokesPartsAgreeExactlyAtReZero) {
  for (double phi = 0.0; phi <= 0.65; phi += 0.025) {
    const double vdh = eval("vdh2005", phi, 0.0);
    EXPECT_EQ(eval("bvk2007", phi, 0.0), vdh) << phi;
    EXPECT_EQ(eval("tang2015", phi, 0.0), vdh) << phi;
    // The seed's Eq. 6 with eps^4 in C0 (the later published form) is the same Stokes law.
    EXPECT_NEAR(eval("vdh2004", phi, 0.0, with("vdh2004", {{"n0", 4.0}})), vdh, 4e-15 * vdh) << phi;
  }
}

TEST(LawValues, SeedEquation6WithoutCorrectionsIsErgun) {
  const auto ergun_like =
      with("vdh2004", {{"A", 150.0}, {"k0", 0.0}, {"c10", 0.0}, {"c11", 0.0}, {"c12", 0.0}});
  for (double phi : {0.1, 0.3, 0.6}) {
    for (double re : {0.0, 1.0, 100.0, 1000.0}) {
      const double ergun = eval("ergun", phi, re);
      EXPECT_NEAR(eval("vdh2004", phi, re, ergun_like), ergun, 4e-15 * ergun) << phi << " " << re;
    }
  }
}

TEST(LawValues, SingleSphereIdentitiesAtPhiZero) {
  for (double re : {0.0, 1e-6, 0.3, 1.0, 31.6, 100.0, 999.0, 1000.0, 1001.0, 5000.0}) {
    // Di Felice and Rong differ only in the exponent of eps, which is irrelevant at eps = 1: both
    // are the isolated-sphere Dalla Valle law, F = C_d Re/24.
    const double dalla_valle = std::pow(0.63 * std::sqrt(re) + 4.8, 2) / 24.0;
    EXPECT_EQ(eval("di_felice", 0.0, re), eval("rong2013", 0.0, re)) << re;
    EXPECT_NEAR(eval("di_felice", 0.0, re), dalla_valle, 4e-16 * dalla_valle) << re;
    // Wen-Yu's voidage function is 1 at eps = 1: the Schiller-Naumann sphere.
    EXPECT_DOUBLE_EQ(eval("wen_yu", 0.0, re), eval("schiller_naumann", 0.0, re)) << re;
    // Tenneti's isolated-sphere term is Schiller-Naumann without the Newton switch.
    if (re <= 1000.0) {
      EXPECT_DOUBLE_EQ(eval("tenneti2011", 0.0, re), eval("schiller_naumann", 0.0, re)) << re;
    }
  }
}

TEST(LawValues, PolydisperseFormAtUnitSizeRatio) {
  // Documented property of Beetstra et al.'s fit: at y = 1 the factor is 1 + 0.064 (1 - phi).
  const double y = 1.0;
  for (double phi : {0.0, 0.1, 0.35, 0.6}) {
    for (double re : {0.0, 10.0, 500.0}) {
      const double mono = eval("bvk2007", phi, re);
      EXPECT_NEAR(eval("bvk2007_poly", phi, re, {}, &y), mono * (1.0 + 0.064 * (1.0 - phi)),
                  4e-16 * mono)
          << phi << " " << re;
      // With the y^3 coefficient set to 0 it is the monodisperse law.
      EXPECT_NEAR(eval("bvk2007_poly", phi, re, with("bvk2007_poly", {{"g", 0.0}}), &y), mono,
                  4e-16 * mono);
    }
  }
}

TEST(LawValues, PolydisperseFormsReduceToEachOther) {
  // The fitting form at its defaults is Beetstra et al.'s factor, and without the y^3 terms van
  // der Hoef et al.'s (which at Re = 0 is vdh2005_poly); HYS at y = 1 is bvk2007 itself.
  const std::vector<double> no_cubic = with("bvk2007_polyfit", {{"c0", 0.0}, {"c1", 0.0}});
  for (double phi : {0.1, 0.35, 0.6}) {
    for (double y : {0.3, 0.8, 1.0, 2.5, 4.0}) {
      for (double re : {0.0, 10.0, 500.0}) {
        const double poly = eval("bvk2007_poly", phi, re, {}, &y);
        EXPECT_NEAR(eval("bvk2007_polyfit", phi, re, {}, &y), poly, 1e-14 * poly);
      }
      const double vdh = eval("vdh2005_poly", phi, 0.0, {}, &y);
      EXPECT_NEAR(eval("bvk2007_polyfit", phi, 0.0, no_cubic, &y), vdh, 1e-14 * vdh);
    }
    const double one = 1.0;
    EXPECT_NEAR(eval("hys2010", phi, 10.0, {}, &one), eval("bvk2007", phi, 10.0),
                1e-14 * eval("bvk2007", phi, 10.0));
  }
}

}  // namespace
}  // namespace draglab
