// Code export (`draglab law export`): the exported C and Fortran compile with the system compilers
// and reproduce the library, for every registered literature law form.
//
// Set-up: for each form, the literature record (published default parameters) is exported; the C
// file is compiled into a shared object and loaded with dlopen, the Fortran module is compiled
// with a small generated driver that reads points and prints results with 18 significant digits.
// Both are compared with draglab::Law on a grid inside the validity box (including Re = 0 and the
// documented regime switches), and their checked variants with the library's error and clamp
// behaviour outside it. Reference: the library itself (Law::F, Law::beta), which the law-form
// tests validate against published values; here only the faithfulness of the export is tested.
//
// Tolerance 1e-12 relative: the exported code performs the same IEEE operations in the same
// order and calls the same libm functions, so the results are normally bit-identical. What may
// differ: the C compiler may fold operations on constants at compile time (correctly rounded, where
// libm may be 1 ulp off) and the Fortran compiler may contract a*b+c into an FMA; each changes
// a result by ~1e-16 relative, amplified at most by a few orders in these formulas.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cfenv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "draglab/drag_db/export.h"
#include "draglab/drag_db/law.h"
#include "draglab/drag_db/law_form.h"
#include "draglab/error.h"

#ifndef DRAGLAB_TEST_C_COMPILER
#define DRAGLAB_TEST_C_COMPILER "cc"
#endif
#ifndef DRAGLAB_TEST_FORTRAN_COMPILER
#define DRAGLAB_TEST_FORTRAN_COMPILER ""
#endif

namespace draglab {
namespace {

namespace fs = std::filesystem;

constexpr double kRelativeTolerance = 1e-12;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Output value the checked functions must leave untouched on error.
constexpr double kUntouched = -1.0;

// ---- helpers ---------------------------------------------------------------------------------

class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = fs::temp_directory_path() / ("draglab_export_" + std::to_string(rd()));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs a shell command; returns its exit status and leaves its output in `log`.
int run(const std::string& command, const fs::path& log) {
  const std::string full = command + " > '" + log.string() + "' 2>&1";
  const int status = std::system(full.c_str());
  return status;
}

std::string number(double x) {
  if (std::isnan(x)) return "NaN";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

bool close_relative(double actual, double expected) {
  if (actual == expected) return true;
  return std::fabs(actual - expected) <= kRelativeTolerance * std::fabs(expected);
}

LawRecord published_literature_record(const LawForm& form) {
  LawRecord r = literature_record(form);
  r.version = 1;
  r.status = LawStatus::kPublished;
  return r;
}

std::vector<const LawForm*> literature_forms() {
  std::vector<const LawForm*> forms;
  for (const LawForm* f : all_law_forms()) {
    if (f->description.literature) forms.push_back(f);
  }
  return forms;
}

std::vector<double> linspace(double lo, double hi, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(n == 1 ? lo : lo + (hi - lo) * i / (n - 1));
  return v;
}

/// One evaluation point: phi, Re and the extra inputs.
struct Point {
  double phi, re;
  std::vector<double> extra;
};

/// Grid inside the validity box: phi and extra inputs evenly spaced, Re from the lower edge
/// (Re = 0 where the box starts there) over four decades to the upper edge, plus the locations
/// of the documented regime switches (where the branch comparison itself is exercised).
std::vector<Point> grid_inside(const LawRecord& r, const LawForm& form) {
  const ValidityBox& box = r.validity;
  std::vector<double> phis = linspace(box.phi.min, box.phi.max, 6);
  std::vector<double> res = {box.re.min};
  const double re_hi = std::isfinite(box.re.max) ? box.re.max : box.re.min + 1e4;
  for (double f : {1e-4, 1e-3, 1e-2, 0.1, 0.37, 1.0})
    res.push_back(box.re.min + (re_hi - box.re.min) * f);
  const std::vector<double> params = r.parameter_values();
  for (const RegimeSwitch& s : form.description.switches) {
    if (s.location == nullptr) continue;
    for (double other : (s.axis == RegimeSwitch::Axis::kPhi ? res : phis)) {
      const double at = s.location(other, params.data());
      if (!std::isfinite(at)) continue;
      if (s.axis == RegimeSwitch::Axis::kPhi && box.phi.contains(at)) phis.push_back(at);
      if (s.axis == RegimeSwitch::Axis::kRe && box.re.contains(at)) res.push_back(at);
    }
  }
  std::vector<std::vector<double>> extras = {{}};
  for (const ExtraInputSpec& e : box.extra) {
    std::vector<std::vector<double>> next;
    for (const auto& prefix : extras) {
      for (double y : linspace(e.range.min, e.range.max, 3)) {
        auto v = prefix;
        v.push_back(y);
        next.push_back(v);
      }
    }
    extras = next;
  }
  std::vector<Point> points;
  for (double phi : phis) {
    for (double re : res) {
      for (const auto& extra : extras) points.push_back({phi, re, extra});
    }
  }
  return points;
}

/// Points outside the box but physical (for the range policies) and physically impossible ones.
std::vector<Point> points_outside(const LawRecord& r, std::vector<Point>* invalid) {
  const ValidityBox& box = r.validity;
  std::vector<double> mid_extra;
  for (const ExtraInputSpec& e : box.extra) mid_extra.push_back(0.5 * (e.range.min + e.range.max));
  const double mid_phi = 0.5 * (box.phi.min + box.phi.max);
  const double mid_re = std::isfinite(box.re.max) ? 0.5 * (box.re.min + box.re.max) : 1.0;
  std::vector<Point> outside;
  if (box.phi.max + 0.05 < 1.0) outside.push_back({box.phi.max + 0.05, mid_re, mid_extra});
  if (box.phi.min - 0.05 >= 0.0) outside.push_back({box.phi.min - 0.05, mid_re, mid_extra});
  if (std::isfinite(box.re.max)) outside.push_back({mid_phi, 2.0 * box.re.max + 1.0, mid_extra});
  *invalid = {{1.2, mid_re, mid_extra},
              {kNaN, mid_re, mid_extra},
              {mid_phi, -1.0, mid_extra},
              {mid_phi, kNaN, mid_extra},
              {-0.1, mid_re, mid_extra}};
  return outside;
}

/// Dimensional inputs (eps_g, mu_g, rho_g, slip, d_p) that give (phi, Re): air-like gas,
/// 0.5 mm particles, the slip solved from Re = rho eps d u / mu. Points on the edge of the box are
/// moved inside by 1e-9 relative first: phi = 1 - (1 - phi) and Re recomputed from the slip differ
/// from the originals by a rounding error, which may put them just outside.
struct Dimensional {
  double eps_g, mu_g, rho_g, slip, d_p;
};
Dimensional dimensional_for(const Point& p, const ValidityBox& box) {
  double phi = p.phi, re = p.re;
  if (box.phi.contains(phi)) {
    phi = std::min(std::max(phi, box.phi.min + 1e-9), box.phi.max - 1e-9);
  }
  if (box.re.contains(re) && re > 0.0) {
    re = std::min(std::max(re, box.re.min * (1.0 + 1e-9)), box.re.max * (1.0 - 1e-9));
  }
  Dimensional d{1.0 - phi, 1.8e-5, 1.2, 0.0, 5e-4};
  d.slip = re * d.mu_g / (d.rho_g * d.eps_g * d.d_p);
  return d;
}

/// Library reference for beta, dga: conventions of the brief from Law (the range policy of
/// `law` applies).
double library_dga(const Law& law, const Dimensional& d, const double* extra) {
  const double phi = 1.0 - d.eps_g;
  const double re = conventions::reynolds(d.eps_g, d.mu_g, d.rho_g, d.slip, d.d_p);
  return d.eps_g * law.F(phi, re, extra) * 18.0 * (d.mu_g / (d.d_p * d.d_p));
}

// ---- format parsing and JSON -----------------------------------------------------------------

TEST(ExportFormat, ParsesTheDocumentedNames) {
  EXPECT_EQ(export_format_from_string("c"), ExportFormat::kC);
  EXPECT_EQ(export_format_from_string("fortran"), ExportFormat::kFortran);
  EXPECT_EQ(export_format_from_string("f90"), ExportFormat::kFortran);
  EXPECT_EQ(export_format_from_string("json"), ExportFormat::kJson);
  try {
    export_format_from_string("pascal");
    FAIL() << "no error for an unknown format";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(std::string(e.what()).find("c, fortran, json"), std::string::npos);
  }
}

TEST(ExportJson, CarriesTheWholeRecord) {
  for (const LawForm* form : literature_forms()) {
    SCOPED_TRACE(form->key());
    LawRecord r = published_literature_record(*form);
    const std::size_t n = r.parameters.size();
    r.covariance.assign(n * n, 0.0);
    for (std::size_t i = 0; i < n; ++i) r.covariance[i * n + i] = 0.01 * (i + 1);
    r.provenance.dataset_id = "campaign-7";
    const nlohmann::json j = nlohmann::json::parse(export_law(r, ExportFormat::kJson));
    EXPECT_EQ(j.at("name"), r.name);
    EXPECT_EQ(j.at("version"), r.version);
    EXPECT_EQ(j.at("form"), r.form);
    EXPECT_EQ(j.at("status"), "published");
    EXPECT_EQ(j.at("content_hash"), r.content_hash);
    ASSERT_EQ(j.at("parameters").size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_EQ(j["parameters"][i].at("name"), r.parameters[i].name);
      EXPECT_EQ(j["parameters"][i].at("value").get<double>(), r.parameters[i].value);  // exact
      EXPECT_EQ(j["parameters"][i].at("unit"), r.parameters[i].unit);
      for (std::size_t k = 0; k < n; ++k) {
        EXPECT_EQ(j["covariance"][i][k].get<double>(), r.covariance[i * n + k]);
      }
    }
    EXPECT_EQ(j["convention"].at("force"), to_string(r.convention.force));
    EXPECT_EQ(j["convention"].at("reynolds"), to_string(r.convention.reynolds));
    EXPECT_EQ(j["validity"]["phi"].at("min").get<double>(), r.validity.phi.min);
    EXPECT_EQ(j["validity"]["phi"].at("max").get<double>(), r.validity.phi.max);
    EXPECT_EQ(j["validity"]["extra"].size(), r.validity.extra.size());
    EXPECT_EQ(j["provenance"].at("citation"), r.provenance.citation);
    EXPECT_EQ(j["provenance"].at("dataset_id"), "campaign-7");
    EXPECT_EQ(j.at("notes"), r.notes);
  }
}

TEST(ExportC, HeaderStatesProvenanceConventionsAndValidity) {
  const LawRecord r = published_literature_record(find_law_form("bvk2007"));
  const std::string c = export_law(r, ExportFormat::kC);
  for (const std::string& needle :
       {r.reference(), r.content_hash, std::string("Beetstra"), std::string("do not edit"),
        std::string("Re   = rho_g eps d_p u / mu_g"), std::string("Validity box: 0.1 <= phi"),
        std::string("#include <math.h>"),
        std::string("double bvk2007_v1_beta(double eps_g, double mu_g, double rho_g, "
                    "double slip, double d_p)")}) {
    EXPECT_NE(c.find(needle), std::string::npos) << needle;
  }
  // The exported code must not need libdraglab: <math.h> is its only include.
  std::istringstream lines(c);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("#include", 0) == 0) {
      EXPECT_EQ(line, "#include <math.h>");
    }
  }
  const std::string f = export_law(r, ExportFormat::kFortran);
  EXPECT_NE(f.find("module bvk2007_v1_drag"), std::string::npos);
  EXPECT_NE(f.find("DRAG_USR"), std::string::npos);
}

// ---- C ---------------------------------------------------------------------------------------

/// An exported C law compiled into a shared object and loaded.
class CompiledC {
 public:
  using F0 = double (*)(double, double);
  using F1 = double (*)(double, double, const double*);
  using Checked0 = int (*)(double, double, int, double*);
  using Checked1 = int (*)(double, double, const double*, int, double*);
  using Dim0 = double (*)(double, double, double, double, double);
  using Dim1 = double (*)(double, double, double, double, double, const double*);
  using DimChecked0 = int (*)(double, double, double, double, double, int, double*);
  using DimChecked1 = int (*)(double, double, double, double, double, const double*, int, double*);

  CompiledC(const LawRecord& r, const fs::path& dir) : id_(export_identifier(r)) {
    const fs::path source = dir / (id_ + ".c");
    const fs::path library = dir / ("lib" + id_ + ".so");
    write_file(source, export_law(r, ExportFormat::kC));
    // Warnings are errors: the generated code must be clean C99.
    const std::string command =
        std::string("'") + DRAGLAB_TEST_C_COMPILER +
        "' -std=c99 -pedantic -Wall -Wextra -Werror -O2 -fPIC -shared -o '" + library.string() +
        "' '" + source.string() + "' -lm";
    const fs::path log = dir / "cc.log";
    if (run(command, log) != 0) {
      error_ = "C compiler failed: " + command + "\n" + read_file(log);
      return;
    }
    handle_ = dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle_ == nullptr) error_ = std::string("dlopen failed: ") + dlerror();
  }
  ~CompiledC() {
    if (handle_ != nullptr) dlclose(handle_);
  }
  const std::string& error() const { return error_; }

  template <typename Fn>
  Fn symbol(const std::string& suffix) const {
    void* p = dlsym(handle_, (id_ + suffix).c_str());
    return reinterpret_cast<Fn>(p);
  }

 private:
  std::string id_;
  void* handle_ = nullptr;
  std::string error_;
};

TEST(ExportC, CompilesAndMatchesTheLibraryForEveryLiteratureForm) {
  const auto forms = literature_forms();
  ASSERT_FALSE(forms.empty());
  for (const LawForm* form : forms) {
    SCOPED_TRACE(form->key());
    const LawRecord r = published_literature_record(*form);
    const Law law(r, RangePolicy::kError);
    const Law clamp(r, RangePolicy::kClamp);
    TempDir dir;
    const CompiledC compiled(r, dir.path());
    ASSERT_EQ(compiled.error(), "");
    const bool extra = form->num_extra_inputs > 0;
    const auto F0 = compiled.symbol<CompiledC::F0>("_F");
    const auto F1 = compiled.symbol<CompiledC::F1>("_F");
    const auto C0 = compiled.symbol<CompiledC::Checked0>("_F_checked");
    const auto C1 = compiled.symbol<CompiledC::Checked1>("_F_checked");
    const auto B0 = compiled.symbol<CompiledC::Dim0>("_beta");
    const auto B1 = compiled.symbol<CompiledC::Dim1>("_beta");
    const auto G0 = compiled.symbol<CompiledC::Dim0>("_dga");
    const auto G1 = compiled.symbol<CompiledC::Dim1>("_dga");
    const auto BC0 = compiled.symbol<CompiledC::DimChecked0>("_beta_checked");
    const auto BC1 = compiled.symbol<CompiledC::DimChecked1>("_beta_checked");
    ASSERT_TRUE(F0 && C0 && B0 && G0 && BC0) << "missing exported functions";
    auto exported_F = [&](const Point& p) {
      return extra ? F1(p.phi, p.re, p.extra.data()) : F0(p.phi, p.re);
    };
    auto checked_F = [&](const Point& p, int policy, double* out) {
      return extra ? C1(p.phi, p.re, p.extra.data(), policy, out) : C0(p.phi, p.re, policy, out);
    };

    int compared = 0;
    for (const Point& p : grid_inside(r, *form)) {
      const double* x = extra ? p.extra.data() : nullptr;
      const double expected = law.F(p.phi, p.re, x);
      const double actual = exported_F(p);
      EXPECT_TRUE(close_relative(actual, expected))
          << "phi=" << p.phi << " Re=" << p.re << ": exported " << number(actual) << ", library "
          << number(expected);
      double checked = kUntouched;
      EXPECT_EQ(checked_F(p, 0, &checked), 0);
      EXPECT_EQ(checked, actual);

      const Dimensional d = dimensional_for(p, r.validity);
      const double beta_expected = law.beta(d.eps_g, d.mu_g, d.rho_g, d.slip, d.d_p, x);
      const double beta = extra ? B1(d.eps_g, d.mu_g, d.rho_g, d.slip, d.d_p, x)
                                : B0(d.eps_g, d.mu_g, d.rho_g, d.slip, d.d_p);
      EXPECT_TRUE(close_relative(beta, beta_expected))
          << "beta at phi=" << p.phi << " Re=" << p.re << ": " << number(beta) << " vs "
          << number(beta_expected);
      const double dga = extra ? G1(d.eps_g, d.mu_g, d.rho_g, d.slip, d.d_p, x)
                               : G0(d.eps_g, d.mu_g, d.rho_g, d.slip, d.d_p);
      EXPECT_TRUE(close_relative(dga, library_dga(law, d, x)));
      double beta_checked = kUntouched;
      EXPECT_EQ(extra ? BC1(d.eps_g, d.mu_g, d.rho_g, d.slip, d.d_p, x, 0, &beta_checked)
                      : BC0(d.eps_g, d.mu_g, d.rho_g, d.slip, d.d_p, 0, &beta_checked),
                0);
      EXPECT_EQ(beta_checked, beta);
      ++compared;
    }
    EXPECT_GT(compared, 20);

    std::vector<Point> invalid;
    for (const Point& p : points_outside(r, &invalid)) {
      const double* x = extra ? p.extra.data() : nullptr;
      double value = kUntouched;
      EXPECT_EQ(checked_F(p, 0, &value), 2) << "phi=" << p.phi << " Re=" << p.re;
      EXPECT_EQ(value, kUntouched);
      EXPECT_EQ(checked_F(p, 1, &value), 2);
      EXPECT_TRUE(close_relative(value, clamp.F(p.phi, p.re, x)))
          << "clamped at phi=" << p.phi << " Re=" << p.re;
    }
    for (const Point& p : invalid) {
      double value = kUntouched;
      for (int policy : {0, 1, 2}) {
        EXPECT_EQ(checked_F(p, policy, &value), 1) << "phi=" << p.phi << " Re=" << p.re;
      }
      EXPECT_EQ(value, kUntouched);
    }
    double value = kUntouched;
    const Point mid = grid_inside(r, *form)[0];
    EXPECT_EQ(checked_F(mid, 3, &value), 1) << "unknown range policy";
    EXPECT_EQ(checked_F(mid, 0, nullptr), 1) << "null output";
    const double* x = extra ? mid.extra.data() : nullptr;
    EXPECT_EQ(extra ? BC1(1.2, 1.8e-5, 1.2, 0.1, 5e-4, x, 0, &value)
                    : BC0(1.2, 1.8e-5, 1.2, 0.1, 5e-4, 0, &value),
              1)
        << "eps_g > 1";
    EXPECT_EQ(extra ? BC1(0.6, 1.8e-5, 1.2, kNaN, 5e-4, x, 0, &value)
                    : BC0(0.6, 1.8e-5, 1.2, kNaN, 5e-4, 0, &value),
              1)
        << "NaN slip";
    EXPECT_EQ(value, kUntouched);
  }
}

TEST(ExportC, UnselectedBranchIsNotEvaluatedAtReZero) {
  // bvk2007 has Re^-0.343 and Re^-(1+4phi)/2 in its inertial term, selected only for Re > 0.
  // The library evaluates both arms (and raises divide-by-zero flags); the exported code must
  // not, so that solvers built with floating-point traps survive Re = 0 (a particle at rest).
  const LawRecord r = published_literature_record(find_law_form("bvk2007"));
  TempDir dir;
  const CompiledC compiled(r, dir.path());
  ASSERT_EQ(compiled.error(), "");
  const auto F0 = compiled.symbol<CompiledC::F0>("_F");
  ASSERT_NE(F0, nullptr);
  std::feclearexcept(FE_ALL_EXCEPT);
  volatile double value = F0(0.3, 0.0);
  const int raised = std::fetestexcept(FE_DIVBYZERO | FE_INVALID | FE_OVERFLOW);
  EXPECT_EQ(raised, 0) << "floating-point exception raised at Re = 0";
  EXPECT_TRUE(std::isfinite(value));
}

// ---- Fortran ---------------------------------------------------------------------------------

std::string fortran_driver(const std::string& id, int num_extra) {
  const std::string x = num_extra > 0 ? ", extra" : "";
  std::ostringstream o;
  o << "program export_driver\n"
    << "  use, intrinsic :: iso_c_binding, only: c_double\n"
    << "  use " << id << "_drag\n"
    << "  implicit none\n"
    << "  real(c_double) :: phi, re, eps_g, mu_g, rho_g, slip, d_p, value, v0, v1, beta, dga\n";
  if (num_extra > 0) o << "  real(c_double) :: extra(" << num_extra << ")\n";
  o << "  integer :: ios, stat0, stat1\n"
    << "  do\n"
    << "    read(*, *, iostat=ios) phi, re" << x << ", eps_g, mu_g, rho_g, slip, d_p\n"
    << "    if (ios /= 0) exit\n"
    << "    v0 = -1.0_c_double\n"
    << "    v1 = -1.0_c_double\n"
    << "    call " << id << "_F_checked(phi, re" << x << ", 0, v0, stat0)\n"
    << "    call " << id << "_F_checked(phi, re" << x << ", 1, v1, stat1)\n"
    << "    value = v0\n"
    << "    if (stat0 == 0) value = " << id << "_F(phi, re" << x << ")\n"
    << "    beta = " << id << "_beta(eps_g, mu_g, rho_g, slip, d_p" << x << ")\n"
    << "    dga = " << id << "_dga(eps_g, mu_g, rho_g, slip, d_p" << x << ")\n"
    << "    write(*, '(ES26.17E3, 2(1X, I2), 3(1X, ES26.17E3))') value, stat0, stat1, v1, "
       "beta, dga\n"
    << "  end do\n"
    << "end program export_driver\n";
  return o.str();
}

struct FortranRow {
  double value;
  int stat0, stat1;
  double clamped, beta, dga;
};

/// Compiles the exported module with the driver and runs it on `points`.
std::vector<FortranRow> run_fortran(const LawRecord& r, int num_extra,
                                    const std::vector<Point>& points, const std::string& flags,
                                    std::string* error) {
  TempDir dir;
  const std::string id = export_identifier(r);
  write_file(dir.path() / (id + ".f90"), export_law(r, ExportFormat::kFortran));
  write_file(dir.path() / "driver.f90", fortran_driver(id, num_extra));
  std::ostringstream input;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point& p = points[i];
    // beta and dga are compared only for points inside the box (see the caller).
    const Dimensional d = dimensional_for(p, r.validity);
    input << number(p.phi) << " " << number(p.re);
    for (double y : p.extra) input << " " << number(y);
    input << " " << number(d.eps_g) << " " << number(d.mu_g) << " " << number(d.rho_g) << " "
          << number(d.slip) << " " << number(d.d_p) << "\n";
  }
  write_file(dir.path() / "points.txt", input.str());
  const std::string d = "'" + dir.path().string() + "'";
  const std::string compile = "cd " + d + " && '" + DRAGLAB_TEST_FORTRAN_COMPILER +
                              "' -std=f2008 -Wall " + flags + " -o driver " + id +
                              ".f90 driver.f90";
  if (run(compile, dir.path() / "fc.log") != 0) {
    *error = "Fortran compiler failed: " + compile + "\n" + read_file(dir.path() / "fc.log");
    return {};
  }
  if (run("cd " + d + " && ./driver < points.txt", dir.path() / "out.txt") != 0) {
    *error = "driver failed:\n" + read_file(dir.path() / "out.txt");
    return {};
  }
  std::vector<FortranRow> rows;
  std::istringstream out(read_file(dir.path() / "out.txt"));
  std::string line;
  while (std::getline(out, line)) {
    std::istringstream fields(line);
    std::string v, s0, s1, c, b, g;
    if (!(fields >> v >> s0 >> s1 >> c >> b >> g)) continue;
    rows.push_back({std::strtod(v.c_str(), nullptr), std::atoi(s0.c_str()), std::atoi(s1.c_str()),
                    std::strtod(c.c_str(), nullptr), std::strtod(b.c_str(), nullptr),
                    std::strtod(g.c_str(), nullptr)});
  }
  if (rows.size() != points.size()) {
    *error = "driver printed " + std::to_string(rows.size()) + " rows for " +
             std::to_string(points.size()) + " points:\n" + out.str();
  }
  return rows;
}

TEST(ExportFortran, CompilesAndMatchesTheLibraryForEveryLiteratureForm) {
  if (std::string(DRAGLAB_TEST_FORTRAN_COMPILER).empty()) {
    GTEST_SKIP() << "no Fortran compiler configured";
  }
  for (const LawForm* form : literature_forms()) {
    SCOPED_TRACE(form->key());
    const LawRecord r = published_literature_record(*form);
    const Law law(r, RangePolicy::kError);
    const Law clamp(r, RangePolicy::kClamp);
    const bool extra = form->num_extra_inputs > 0;
    std::vector<Point> inside = grid_inside(r, *form);
    std::vector<Point> invalid;
    std::vector<Point> outside = points_outside(r, &invalid);
    std::vector<Point> points = inside;
    points.insert(points.end(), outside.begin(), outside.end());
    points.insert(points.end(), invalid.begin(), invalid.end());
    std::string error;
    const std::vector<FortranRow> rows =
        run_fortran(r, form->num_extra_inputs, points, "-O2", &error);
    ASSERT_EQ(error, "");
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Point& p = points[i];
      const FortranRow& row = rows[i];
      const double* x = extra ? p.extra.data() : nullptr;
      const std::string where = "phi=" + number(p.phi) + " Re=" + number(p.re);
      if (i < inside.size()) {
        const double expected = law.F(p.phi, p.re, x);
        EXPECT_TRUE(close_relative(row.value, expected))
            << where << ": Fortran " << number(row.value) << ", library " << number(expected);
        EXPECT_EQ(row.stat0, 0) << where;
        EXPECT_EQ(row.stat1, 0) << where;
        EXPECT_TRUE(close_relative(row.clamped, expected)) << where;
        const Dimensional d = dimensional_for(p, r.validity);
        const double beta = law.beta(d.eps_g, d.mu_g, d.rho_g, d.slip, d.d_p, x);
        EXPECT_TRUE(close_relative(row.beta, beta))
            << where << ": beta " << number(row.beta) << " vs " << number(beta);
        EXPECT_TRUE(close_relative(row.dga, library_dga(law, d, x))) << where;
      } else if (i < inside.size() + outside.size()) {
        EXPECT_EQ(row.stat0, 2) << where;
        EXPECT_EQ(row.value, kUntouched) << where;
        EXPECT_EQ(row.stat1, 2) << where;
        EXPECT_TRUE(close_relative(row.clamped, clamp.F(p.phi, p.re, x))) << where;
      } else {
        EXPECT_EQ(row.stat0, 1) << where;
        EXPECT_EQ(row.stat1, 1) << where;
        EXPECT_EQ(row.clamped, kUntouched) << where;
      }
    }
  }
}

TEST(ExportFortran, NoFloatingPointTrapAtReZero) {
  if (std::string(DRAGLAB_TEST_FORTRAN_COMPILER).empty()) {
    GTEST_SKIP() << "no Fortran compiler configured";
  }
  // As for C: with traps on (what MFiX debug builds use) a particle at rest must not abort the
  // solver. A merge()-based export, which evaluates both arms, fails this test.
  const LawRecord r = published_literature_record(find_law_form("bvk2007"));
  std::vector<Point> points;
  for (double phi : {0.1, 0.3, 0.6}) points.push_back({phi, 0.0, {}});
  std::string error;
  const auto rows = run_fortran(r, 0, points, "-O0 -ffpe-trap=invalid,zero,overflow", &error);
  ASSERT_EQ(error, "");
  const Law law(r);
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_TRUE(close_relative(rows[i].value, law.F(points[i].phi, 0.0)));
  }
}

}  // namespace
}  // namespace draglab
