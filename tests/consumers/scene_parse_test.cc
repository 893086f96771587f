// Scene files (consumers/scene.h): the shipped scenes parse to the values they declare, and every
// bad input is refused with a message naming the field (and the range where one applies).
// Set-up: data/scenes/dpm_bubble.toml (the seed's bed, consumers.md 2.1: 15 x 45 x 1.5 cm,
// 2.5 mm glass, H_mf 22 cm at eps_mf 0.42 -> ~35 100 particles) and edits of it.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dpm/dpm_scene.h"
#include "draglab/consumers/scene.h"
#include "draglab/error.h"
#include "tfm/tfm_scene.h"

namespace draglab {
namespace consumers {
namespace {

std::string read(const std::string& name) {
  std::ifstream in(std::string(DRAGLAB_DATA_DIR) + "/scenes/" + name);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Replaces the first line starting with `key` (after the [section] header) by `line`.
std::string edit(std::string text, const std::string& section, const std::string& key,
                 const std::string& line) {
  const std::size_t sec = text.find("[" + section + "]");
  EXPECT_NE(sec, std::string::npos) << section;
  const std::size_t at = text.find("\n" + key + " ", sec);
  EXPECT_NE(at, std::string::npos) << key;
  const std::size_t end = text.find('\n', at + 1);
  return text.substr(0, at + 1) + line + text.substr(end);
}

/// Parses and expects kInvalidArgument whose message contains every `needle`.
void expect_bad(const std::string& text, std::initializer_list<const char*> needles) {
  try {
    parse_scene(text, "edited.toml");
    ADD_FAILURE() << "accepted; expected an error with " << *needles.begin();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_TRUE(e.is_bad_input());
    for (const char* n : needles) {
      EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what() << " lacks " << n;
    }
  }
}

TEST(SceneParse, SeedSceneDeclaresTheSeedBed) {
  const Scene s = load_scene(std::string(DRAGLAB_DATA_DIR) + "/scenes/dpm_bubble.toml");
  EXPECT_EQ(s.name, "dpm_bubble");
  EXPECT_DOUBLE_EQ(s.geometry.width_m, 0.15);
  EXPECT_DOUBLE_EQ(s.geometry.height_m, 0.45);
  EXPECT_DOUBLE_EQ(s.geometry.depth_m, 0.015);
  EXPECT_DOUBLE_EQ(s.particles.diameter_m, 2.5e-3);
  EXPECT_DOUBLE_EQ(s.particles.density_kg_m3, 2526.0);
  EXPECT_DOUBLE_EQ(dem_section(s).restitution, 0.97);
  EXPECT_DOUBLE_EQ(dem_section(s).friction, 0.1);
  EXPECT_DOUBLE_EQ(s.gas.density_kg_m3, 1.2);
  EXPECT_DOUBLE_EQ(s.gas.viscosity_pa_s, 1.8e-5);
  EXPECT_DOUBLE_EQ(s.bed_height_mf_m(), 0.22);
  // N = (1 - eps_mf) W D H / (pi d^3/6) = 0.58 * 0.15 * 0.015 * 0.22 / 8.181e-9 = 35 093.
  EXPECT_NEAR(static_cast<double>(s.particle_count()), 35093.0, 1.0);
  EXPECT_EQ(s.distributor.mode, BackgroundMode::kUmfPacking);
  EXPECT_DOUBLE_EQ(s.time.t_ref_s, 0.3);
  EXPECT_DOUBLE_EQ(s.jet_center_m(), 0.075);
  EXPECT_DOUBLE_EQ(s.bubble.eps_threshold, 0.8);
  EXPECT_EQ(s.laws.size(), 5u);
  EXPECT_EQ(s.hash().size(), 64u);
  const Scene q = load_scene(std::string(DRAGLAB_DATA_DIR) + "/scenes/dpm_bubble_quick.toml");
  EXPECT_LT(q.particle_count(), 5000);
  EXPECT_NE(q.hash(), s.hash());
}

// data/scenes/dpm_binary_seed.toml is the seed's bed (dpm_bubble.toml: box, bed height, gas, jet
// and time line) with its 2.5 mm beads replaced by 1.5 and 3 mm glass at equal volume (issue 36),
// and dpm_binary.toml the same beads in the quick scene's box.
TEST(SceneParse, BinarySeedSceneIsTheSeedBedWithTwoSizes) {
  const std::string dir = std::string(DRAGLAB_DATA_DIR) + "/scenes/";
  const Scene seed = load_scene(dir + "dpm_bubble.toml");
  const Scene bin = load_scene(dir + "dpm_binary_seed.toml");
  EXPECT_DOUBLE_EQ(bin.geometry.width_m, seed.geometry.width_m);
  EXPECT_DOUBLE_EQ(bin.geometry.height_m, seed.geometry.height_m);
  EXPECT_DOUBLE_EQ(bin.geometry.depth_m, seed.geometry.depth_m);
  EXPECT_DOUBLE_EQ(bin.bed_height_mf_m(), seed.bed_height_mf_m());
  EXPECT_DOUBLE_EQ(bin.particles.density_kg_m3, seed.particles.density_kg_m3);
  EXPECT_DOUBLE_EQ(bin.gas.density_kg_m3, seed.gas.density_kg_m3);
  EXPECT_DOUBLE_EQ(bin.gas.viscosity_pa_s, seed.gas.viscosity_pa_s);
  EXPECT_DOUBLE_EQ(bin.jet.slot_width_m, seed.jet.slot_width_m);
  EXPECT_DOUBLE_EQ(bin.jet.velocity_m_s, seed.jet.velocity_m_s);
  EXPECT_DOUBLE_EQ(bin.jet.start_s, seed.jet.start_s);
  EXPECT_DOUBLE_EQ(bin.jet.duration_s, seed.jet.duration_s);
  EXPECT_DOUBLE_EQ(bin.time.t_ref_s, seed.time.t_ref_s);
  EXPECT_DOUBLE_EQ(bin.time.duration_s, seed.time.duration_s);
  ASSERT_TRUE(bin.polydisperse());
  const Scene quick = load_scene(dir + "dpm_binary.toml");
  EXPECT_EQ(bin.particles.diameters_m, quick.particles.diameters_m);
  EXPECT_EQ(bin.particles.volume_fractions, quick.particles.volume_fractions);
  EXPECT_EQ(bin.laws, quick.laws);
  // Equal volumes of 1.5 and 3 mm spheres: 8 small per large; the solids volume
  // 0.58 * 0.15 * 0.015 * 0.22 = 2.871e-4 m^3 holds 81 233 small and 10 154 large.
  EXPECT_NEAR(static_cast<double>(bin.particle_count()), 91387.0, 2.0);
}

// data/scenes/dpm_tiny.toml, the shared scene of the fast tests: the bed the tests' comments
// describe (tests derive their variants from it key by key, so a change here shows up there).
TEST(SceneParse, TinySceneDeclaresTheTestBed) {
  const Scene s = load_scene(std::string(DRAGLAB_DATA_DIR) + "/scenes/dpm_tiny.toml");
  EXPECT_EQ(s.name, "dpm_tiny");
  EXPECT_EQ(s.solver, "dpm");
  EXPECT_EQ(s.seed, 3u);
  EXPECT_DOUBLE_EQ(s.geometry.width_m, 0.03);
  EXPECT_DOUBLE_EQ(s.geometry.height_m, 0.09);
  EXPECT_DOUBLE_EQ(s.geometry.depth_m, 0.0075);
  EXPECT_DOUBLE_EQ(s.particles.diameter_m, 2.5e-3);
  EXPECT_DOUBLE_EQ(dem_section(s).spring_stiffness_n_m, 7000.0);
  EXPECT_DOUBLE_EQ(s.bed_height_mf_m(), 0.02);
  // N = 0.58 * 0.03 * 0.0075 * 0.02 / 8.181e-9 = 319.
  EXPECT_NEAR(static_cast<double>(s.particle_count()), 319.0, 1.0);
  EXPECT_TRUE(dem_section(s).present);
  EXPECT_EQ(dem_section(s).contact_steps, 20);
  EXPECT_DOUBLE_EQ(s.time.duration_s, 0.06);
  EXPECT_DOUBLE_EQ(s.time.t_ref_s, 0.03);
  EXPECT_EQ(s.grid.cells_x, 4);
  EXPECT_EQ(s.grid.cells_y, 12);
  EXPECT_EQ(s.laws, std::vector<std::string>{"ergun@1"});
  std::string why;
  EXPECT_TRUE(s.IsValid(&why)) << why;
}

TEST(SceneParse, CountAndHeightAreInterchangeable) {
  std::string text = read("dpm_bubble.toml");
  text = edit(text, "particles", "bed_height_mf_m", "count = 35093");
  const Scene s = parse_scene(text);
  EXPECT_NEAR(s.bed_height_mf_m(), 0.22, 1e-5);
  EXPECT_EQ(s.particle_count(), 35093);
}

TEST(SceneParse, FixedBackground) {
  const Scene s = parse_scene(
      edit(read("dpm_bubble.toml"), "distributor", "background", "background = \"fixed\""));
  EXPECT_EQ(s.distributor.mode, BackgroundMode::kFixed);
  EXPECT_DOUBLE_EQ(s.distributor.velocity_m_s, 1.26);
}

// The two-fluid scene: its [tfm] table read, its defaults, and every bad [tfm] input named
// (issue: unknown solver, missing [tfm], restitution outside (0, 1], packing limit not above the
// bed's solids fraction, negative theta, unknown closure names, [tfm] with another solver).
TEST(SceneParse, TwoFluidSceneAndItsBadInput) {
  const std::string base = read("tfm_bubble.toml");
  const Scene s = parse_scene(base, "tfm_bubble.toml");
  EXPECT_EQ(s.solver, "tfm");
  EXPECT_TRUE(tfm_section(s).present);
  EXPECT_EQ(tfm_section(s).closures, "nieuwland");
  EXPECT_DOUBLE_EQ(tfm_section(s).packing_limit, 0.64);
  EXPECT_DOUBLE_EQ(tfm_section(s).restitution, -1.0) << "from [particles] unless given";
  EXPECT_DOUBLE_EQ(s.geometry.height_m, 0.60) << "the seed's TFM box is 60 cm high";
  const Scene kuipers = parse_scene(read("tfm_kuipers_jet.toml"), "tfm_kuipers_jet.toml");
  EXPECT_EQ(kuipers.solver, "tfm");
  EXPECT_DOUBLE_EQ(kuipers.particles.diameter_m, 5e-4) << "the 1992 experiment's glass";
  expect_bad(edit(base, "scene", "solver", "solver = \"lbm\""), {"[scene] solver", "tfm", "dpm"});
  expect_bad(base.substr(0, base.find("[tfm]")) + base.substr(base.find("[outputs]")),
             {"[tfm] table is missing"});
  expect_bad(edit(base, "tfm", "closures", "restitution = 1.5"), {"[tfm] restitution", "(0, 1]"});
  expect_bad(edit(base, "tfm", "closures", "restitution = 0"), {"[tfm] restitution"});
  expect_bad(edit(base, "tfm", "packing_limit", "packing_limit = 0.55"),
             {"[tfm] packing_limit", "0.58"});
  expect_bad(edit(base, "tfm", "packing_limit", "packing_limit = 0.58"), {"[tfm] packing_limit"});
  expect_bad(edit(base, "tfm", "theta_initial_m2_s2", "theta_initial_m2_s2 = -1e-3"),
             {"[tfm] theta_initial_m2_s2", ">= 0"});
  expect_bad(edit(base, "tfm", "closures", "closures = \"lun\""), {"[tfm] closures", "gidaspow"});
  expect_bad(edit(base, "tfm", "radial_distribution", "radial_distribution = \"x\""),
             {"[tfm] radial_distribution", "carnahan_starling"});
  expect_bad(edit(base, "tfm", "friction", "friction = \"coulomb\""), {"[tfm] friction", "none"});
  expect_bad(edit(base, "tfm", "cfl", "cfl = 0.9"), {"[tfm] cfl", "0.5"});
  expect_bad(edit(base, "tfm", "dt_max_s", "dt_max_s = 0"), {"[tfm] dt_max_s"});
  expect_bad(edit(base, "tfm", "closures", "cloures = \"nieuwland\""), {"unknown key", "cloures"});
  expect_bad(read("dpm_bubble.toml") + "\n[tfm]\nclosures = \"nieuwland\"\n",
             {"[tfm] is read only with solver = \"tfm\""});
  // The numerical and modelling options: defaults, values, and bad names.
  EXPECT_EQ(tfm_section(s).solids_walls, "free_slip");
  EXPECT_EQ(tfm_section(s).fraction_scheme, "upwind");
  EXPECT_EQ(tfm_section(s).granular_temperature, "transport");
  EXPECT_EQ(tfm_section(s).solids_viscosity, "explicit");
  EXPECT_DOUBLE_EQ(tfm_section(s).friction_max_viscosity_pa_s, 10.0);
  const Scene options =
      parse_scene(edit(edit(base, "tfm", "friction", "friction = \"johnson_jackson_openfoam\""),
                       "tfm", "closures",
                       "closures = \"nieuwland\"\nsolids_walls = \"no_slip\"\nfraction_scheme = "
                       "\"van_leer\"\ngranular_temperature = \"algebraic\"\n"
                       "friction_max_viscosity_pa_s = 100.0\nsolids_viscosity = "
                       "\"point_implicit\""),
                  "edited.toml");
  EXPECT_EQ(tfm_section(options).solids_walls, "no_slip");
  EXPECT_EQ(tfm_section(options).fraction_scheme, "van_leer");
  EXPECT_EQ(tfm_section(options).granular_temperature, "algebraic");
  EXPECT_DOUBLE_EQ(tfm_section(options).friction_max_viscosity_pa_s, 100.0);
  EXPECT_EQ(tfm_section(options).solids_viscosity, "point_implicit");
  EXPECT_EQ(tfm_section(options).friction, "johnson_jackson_openfoam");
  expect_bad(edit(base, "tfm", "closures", "solids_viscosity = \"implicit\""),
             {"[tfm] solids_viscosity", "point_implicit"});
  expect_bad(edit(base, "tfm", "friction", "friction = \"coulomb\""),
             {"[tfm] friction", "johnson_jackson_openfoam"});
  expect_bad(edit(base, "tfm", "closures", "solids_walls = \"sticky\""),
             {"[tfm] solids_walls", "no_slip"});
  expect_bad(edit(base, "tfm", "closures", "fraction_scheme = \"quick\""),
             {"[tfm] fraction_scheme", "van_leer"});
  expect_bad(edit(base, "tfm", "closures", "granular_temperature = \"none\""),
             {"[tfm] granular_temperature", "algebraic"});
  expect_bad(edit(base, "tfm", "closures", "friction_max_viscosity_pa_s = 0"),
             {"friction_max_viscosity_pa_s"});
}

// Scene files written before the [dem] table (DEM keys in [particles] and [time]) still parse,
// to the same values: stored scene texts are re-parsed by `draglab regress`.
TEST(SceneParse, DemKeysInTheirOldSectionsStillParse) {
  std::string old = read("dpm_bubble.toml");
  const std::size_t dem = old.find("[dem]");
  ASSERT_NE(dem, std::string::npos);
  const std::size_t grid = old.find("[grid]");
  std::string moved = old.substr(0, dem) + old.substr(grid);
  moved = edit(moved, "particles", "bed_height_mf_m",
               "bed_height_mf_m = 0.22\nrestitution = 0.97\nfriction = 0.1\n"
               "spring_stiffness_n_m = 7000.0");
  moved = edit(moved, "time", "gas_dt_s",
               "gas_dt_s = 0.0\nsettle_s = 0.3\ndem_dt_s = 0.0\n"
               "contact_steps = 20");
  const Scene a = parse_scene(old, "new.toml"), b = parse_scene(moved, "old.toml");
  const SceneDem &da = dem_section(a), &db = dem_section(b);
  EXPECT_TRUE(da.present);
  EXPECT_FALSE(db.present);
  EXPECT_DOUBLE_EQ(da.restitution, db.restitution);
  EXPECT_DOUBLE_EQ(da.friction, db.friction);
  EXPECT_DOUBLE_EQ(da.spring_stiffness_n_m, db.spring_stiffness_n_m);
  EXPECT_DOUBLE_EQ(da.settle_s, db.settle_s);
  EXPECT_EQ(da.dem_dt_s, db.dem_dt_s);
  EXPECT_EQ(da.contact_steps, db.contact_steps);
  // Other values than the defaults reach the section from the older places too.
  const Scene c = parse_scene(edit(edit(moved, "particles", "friction", "friction = 0.3"), "time",
                                   "contact_steps", "contact_steps = 40"),
                              "old.toml");
  EXPECT_DOUBLE_EQ(dem_section(c).friction, 0.3);
  EXPECT_EQ(dem_section(c).contact_steps, 40);
  expect_bad(edit(moved, "particles", "restitution", "restitution = 1.2"),
             {"[particles] restitution"});
  expect_bad(edit(moved, "particles", "friction", "friction = 1.2"), {"[particles] friction"});
  expect_bad(edit(moved, "time", "contact_steps", "contact_steps = 10"),
             {"[time] contact_steps", "[20, 1000]"});
  // A key in both places is refused, naming both.
  expect_bad(edit(old, "particles", "bed_height_mf_m", "bed_height_mf_m = 0.22\nfriction = 0.1"),
             {"friction", "[dem]", "[particles]", "only"});
}

TEST(SceneParse, EveryBadInputIsNamed) {
  const std::string base = read("dpm_bubble.toml");
  expect_bad(base + "\n[extra]\nx = 1\n", {"unknown section", "extra", "[geometry]"});
  expect_bad(edit(base, "geometry", "width_m", "widht_m = 0.15"),
             {"unknown key", "widht_m", "width_m"});
  expect_bad(edit(base, "geometry", "width_m", "width_m = \"wide\""),
             {"[geometry] width_m", "number"});
  expect_bad("[scene\nname=1", {"not valid TOML"});
  expect_bad(edit(base, "particles", "diameter_m", "diameter_m = 0.0"),
             {"[particles] diameter_m", "[1e-06, "});
  expect_bad(edit(base, "particles", "diameter_m", "diameter_m = -2.5e-3"),
             {"[particles] diameter_m"});
  expect_bad(edit(base, "particles", "density_kg_m3", "density_kg_m3 = 0"),
             {"[particles] density_kg_m3", "(0, "});
  expect_bad(edit(base, "particles", "density_kg_m3", "density_kg_m3 = -2526"),
             {"[particles] density_kg_m3"});
  expect_bad(edit(base, "gas", "density_kg_m3", "density_kg_m3 = 0"),
             {"[gas] density_kg_m3", "(0, "});
  expect_bad(edit(base, "gas", "viscosity_pa_s", "viscosity_pa_s = -1e-5"),
             {"[gas] viscosity_pa_s"});
  expect_bad(edit(base, "particles", "density_kg_m3", "density_kg_m3 = 1.0"), {"must exceed"});
  expect_bad(edit(base, "dem", "restitution", "restitution = 1.2"),
             {"[dem] restitution", "(0, 1]"});
  expect_bad(edit(base, "dem", "friction", "friction = -0.1"), {"[dem] friction", "[0, 1]"});
  expect_bad(edit(base, "particles", "diameter_m", "diameter_m = 0.02"), {"does not fit the box"});
  // A jet wider than the bed; a slot that sticks out of the bottom.
  expect_bad(edit(base, "jet", "slot_width_m", "slot_width_m = 0.2"),
             {"[jet] slot_width_m", "width"});
  expect_bad(edit(base, "jet", "slot_width_m", "slot_width_m = 0.01\ncenter_m = 0.149"),
             {"[jet] center_m"});
  expect_bad(edit(base, "jet", "velocity_m_s", "velocity_m_s = -5"), {"[jet] velocity_m_s"});
  // A bed that does not fit the box, by height or by count; both or neither given.
  expect_bad(edit(base, "particles", "bed_height_mf_m", "bed_height_mf_m = 0.5"),
             {"[particles] bed_height_mf_m", "box height"});
  expect_bad(edit(base, "particles", "bed_height_mf_m", "count = 100000"),
             {"does not fit the box"});
  expect_bad(edit(base, "particles", "bed_height_mf_m", "bed_height_mf_m = 0.22\ncount = 1000"),
             {"give exactly one of count"});
  expect_bad(edit(base, "particles", "bed_height_mf_m", "# none"), {"exactly one"});
  expect_bad(edit(base, "particles", "bed_height_mf_m", "bed_height_mf_m = 0"),
             {"neither has a usable value", "bed_height_mf_m = 0)"});
  expect_bad(edit(base, "particles", "bed_height_mf_m", "count = 0"), {"[particles] count"});
  // Times and steps: a DEM step above t_c/20 (t_c = 1.2e-4 s) is refused.
  expect_bad(edit(base, "dem", "dem_dt_s", "dem_dt_s = 1e-5"),
             {"[dem] dem_dt_s", "stability limit"});
  expect_bad(edit(base, "time", "gas_dt_s", "gas_dt_s = 1e-30"),
             {"[time] gas_dt_s", "more than 1e9"});
  expect_bad(edit(base, "dem", "dem_dt_s", "dem_dt_s = 1e-30"),
             {"[dem] dem_dt_s", "more than 1e9"});
  expect_bad(edit(base, "dem", "contact_steps", "contact_steps = 10"),
             {"[dem] contact_steps", "[20, 1000]"});
  // The DEM keys stand in [dem] or, in older files, in [particles] and [time], never in both;
  // [dem] is the DPM's.
  expect_bad(
      edit(base, "particles", "bed_height_mf_m", "bed_height_mf_m = 0.22\nrestitution = 0.9"),
      {"restitution", "[dem]", "[particles]"});
  expect_bad(edit(base, "time", "gas_dt_s", "gas_dt_s = 0.0\ncontact_steps = 30"),
             {"contact_steps", "[dem]", "[time]"});
  expect_bad(read("tfm_bubble.toml") + "\n[dem]\ncontact_steps = 30\n",
             {"[dem] is read only with solver = \"dpm\""});
  expect_bad(edit(base, "time", "t_ref_s", "t_ref_s = 0.5"), {"[time] t_ref_s", "duration_s"});
  expect_bad(edit(base, "time", "duration_s", "duration_s = 0"), {"[time] duration_s"});
  expect_bad(edit(base, "grid", "cells_x", "cells_x = 100"), {"[grid]", "smaller than a particle"});
  expect_bad(edit(base, "grid", "cells_y", "cells_y = 0"), {"[grid] cells_y", "[2, 100000]"});
  expect_bad(edit(base, "grid", "cells_x", "cells_x = 1"), {"[grid] cells_x", "[2, 100000]"});
  expect_bad(edit(base, "bubble", "eps_threshold", "eps_threshold = 0.3"),
             {"[bubble] eps_threshold"});
  expect_bad(edit(base, "bubble", "eps_threshold", "eps_threshold = 1.0"),
             {"[bubble] eps_threshold"});
  expect_bad(edit(base, "drag", "eps_mf", "eps_mf = 0.95"), {"[drag] eps_mf"});
  expect_bad(edit(base, "drag", "laws", "laws = []"), {"[drag] laws", "empty"});
  expect_bad(edit(base, "drag", "laws", "laws = [\"ergun@1\", \"ergun@1\"]"), {"twice"});
  expect_bad(edit(base, "drag", "laws", "laws = [3]"), {"[drag] laws[0]", "string"});
  expect_bad(edit(base, "drag", "range_policy", "range_policy = \"ignore\""),
             {"[drag] range_policy"});
  expect_bad(edit(base, "distributor", "background", "background = \"plate\""),
             {"[distributor] background", "umf, umf_packing, fixed"});
  expect_bad(edit(edit(base, "distributor", "background", "background = \"fixed\""), "distributor",
                  "velocity_m_s", "velocity_m_s = 0"),
             {"[distributor] velocity_m_s"});
  expect_bad(edit(base, "scene", "solver", "solver = \"lbm\""), {"[scene] solver"});
  expect_bad(edit(base, "scene", "name", "name = \"a b\""), {"[scene] name"});
  EXPECT_THROW(load_scene("/nonexistent/scene.toml"), Error);
}

}  // namespace
}  // namespace consumers
}  // namespace draglab
