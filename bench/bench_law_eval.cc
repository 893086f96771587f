// Benchmark: evaluating a loaded drag law at 10^7 (phi, Re) points.
//
// Sample runs:
//   build/bench/bench_law_eval                      # bvk2007, 10^7 points, 7 repetitions
//   build/bench/bench_law_eval --law tang2015 --points 1000000 --repeat 11
//
// Compares, on the same points: (1) the formula written inline here as plain C++ (the best a
// solver could do by pasting the law into its own loop), (2) the C++ array path Law::F(n, ...),
// (3) the C ABI array path draglab_law_F_n, (4) the C ABI scalar path draglab_law_F in a loop.
// Reports the median time of each and the ratio to the inline loop (goal for bvk2007: array
// path within 1.25x of inline), plus the largest relative difference to the inline values.
// A benchmark, not a test: it asserts nothing about time.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "draglab/draglab.h"
#include "draglab/drag_db/database.h"
#include "draglab/drag_db/law.h"

namespace {

// Beetstra, van der Hoef & Kuipers (2007), drag_laws.md 1.10, written out by hand.
inline double bvk2007_inline(double phi, double re) {
  const double eps = 1.0 - phi;
  const double stokes = 10.0 * phi / (eps * eps) + eps * eps * (1.0 + 1.5 * std::sqrt(phi));
  if (re <= 0.0) return stokes;
  const double numerator = re * (1.0 / eps + 3.0 * phi * eps) + 8.4 * std::pow(re, 1.0 - 0.343);
  const double denominator = 1.0 + std::pow(10.0, 3.0 * phi) * std::pow(re, -(1.0 + 4.0 * phi) * 0.5);
  return stokes + 0.413 / (24.0 * eps * eps) * numerator / denominator;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <typename Fn>
double time_median(int repeat, Fn&& fn) {
  std::vector<double> t;
  for (int r = 0; r < repeat; ++r) {
    const auto start = std::chrono::steady_clock::now();
    fn();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return median(t);
}

}  // namespace

int main(int argc, char** argv) {
  std::string law_name = "bvk2007";
  std::size_t n = 10000000;
  int repeat = 7;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--law" && i + 1 < argc) {
      law_name = argv[++i];
    } else if (a == "--points" && i + 1 < argc) {
      n = std::strtoull(argv[++i], nullptr, 10);
    } else if (a == "--repeat" && i + 1 < argc) {
      repeat = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: %s [--law KEY] [--points N] [--repeat R]\n", argv[0]);
      return 2;
    }
  }
  if (n == 0 || repeat < 1) {
    std::fprintf(stderr, "--points must be >= 1 and --repeat >= 1\n");
    return 2;
  }

  // A throw-away database in the temp directory, seeded with the literature library.
  const char* tmpdir = std::getenv("TMPDIR");
  std::string dir_template_s = std::string(tmpdir && *tmpdir ? tmpdir : "/tmp") + "/draglab_bench_XXXXXX";
  std::vector<char> dir_template(dir_template_s.begin(), dir_template_s.end());
  dir_template.push_back('\0');
  if (!mkdtemp(dir_template.data())) {
    std::perror("mkdtemp");
    return 1;
  }
  const std::string db_path = std::string(dir_template.data()) + "/bench.db";
  draglab_db* db = nullptr;
  draglab_law* c_law = nullptr;
  if (draglab_db_open(db_path.c_str(), &db) != 0 ||
      draglab_law_load(db, law_name.c_str(), &c_law) != 0) {
    std::fprintf(stderr, "error: %s\n", draglab_last_error());
    return 1;
  }
  // The C++ path loads the same stored version through the C++ API.
  draglab::Database cxx_db(db_path);
  const std::shared_ptr<draglab::Law> loaded = cxx_db.load(law_name);
  const draglab::Law& law = *loaded;
  const draglab::ValidityBox& box = law.record().validity;

  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<double> phi(n), re(n), f_inline(n), f_array(n), f_c(n), f_scalar(n);
  const double re_hi = std::min(box.re.max, 1000.0);
  for (std::size_t i = 0; i < n; ++i) {
    phi[i] = box.phi.min + (box.phi.max - box.phi.min) * u01(rng);
    re[i] = re_hi * u01(rng);
  }
  const bool have_inline = law_name == "bvk2007";

  std::printf("draglab bench_law_eval: law %s, %zu points, median of %d runs\n", law_name.c_str(), n,
              repeat);
  double t_inline = 0.0;
  if (have_inline) {
    t_inline = time_median(repeat, [&] {
      for (std::size_t i = 0; i < n; ++i) f_inline[i] = bvk2007_inline(phi[i], re[i]);
    });
  }
  const double t_array = time_median(repeat, [&] { law.F(n, phi.data(), re.data(), f_array.data()); });
  const double t_c = time_median(repeat, [&] {
    if (draglab_law_F_n(c_law, n, phi.data(), re.data(), f_c.data()) != 0) std::abort();
  });
  const double t_scalar = time_median(repeat, [&] {
    for (std::size_t i = 0; i < n; ++i) draglab_law_F(c_law, phi[i], re[i], &f_scalar[i]);
  });

  auto max_rel = [&](const std::vector<double>& a, const std::vector<double>& b) {
    double m = 0.0;
    for (std::size_t i = 0; i < n; ++i) m = std::max(m, std::abs(a[i] - b[i]) / std::abs(b[i]));
    return m;
  };
  const std::vector<double>& ref = have_inline ? f_inline : f_array;
  std::printf("%-28s %10s %12s %10s %14s\n", "path", "time [s]", "ns/point", "ratio", "max rel diff");
  auto row = [&](const char* name, double t, const std::vector<double>& f) {
    std::printf("%-28s %10.4f %12.2f %10s %14.2e\n", name, t, 1e9 * t / n,
                have_inline ? (std::to_string(t / t_inline).substr(0, 5) + "x").c_str() : "-",
                max_rel(f, ref));
  };
  if (have_inline) row("inline formula (plain C++)", t_inline, f_inline);
  row("C++ array Law::F(n, ...)", t_array, f_array);
  row("C ABI draglab_law_F_n", t_c, f_c);
  row("C ABI draglab_law_F (loop)", t_scalar, f_scalar);

  draglab_law_free(c_law);
  draglab_db_close(db);
  std::remove(db_path.c_str());
  std::remove((db_path + "-wal").c_str());
  std::remove((db_path + "-shm").c_str());
  rmdir(dir_template.data());
  return 0;
}
