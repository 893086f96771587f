// The C ABI (draglab.h) seen from a C++ caller: statuses, messages, null pointers, range
// policies, the array paths, the dimensional entry points, thread-local errors, and read-only
// opens of an installation the caller cannot write (file 0444 in a directory 0555; as root,
// which ignores permissions, that check runs in a child dropped to uid/gid 65534).
//
// Set-up: a fresh database in a temporary folder, seeded with the literature library; the law
// under test is bvk2007@1 (Beetstra, van der Hoef & Kuipers 2007, AIChE J. 53:489).
// Reference values: F(0.1, 0) = 2.42878 and F(0.4, 100) = 30.7416, the BVK 2007 formula
// evaluated independently from the published coefficients (reference dossier drag_laws.md
// section 2.4 and its law_check_values.csv, 6 significant figures). Identities between F, K,
// beta and lDgA are the canonical conversions of the brief (beta = 18 mu phi eps F / d^2,
// K = F/(1 - phi), lDgA = beta/phi).
#include <grp.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cfenv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "draglab/draglab.h"

namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// Sentinel written into outputs before a failing call: it must survive the call.
constexpr double kUntouched = -12345.0;

// The published check values have 6 significant figures: 1e-5 relative covers their rounding
// (at most 5e-6 relative for 2.42878) with margin.
constexpr double kCheckValueTolerance = 1e-5;
// Identities evaluated in a different order of operations: a few rounding errors of ~1e-16.
constexpr double kRoundingTolerance = 1e-13;

fs::path fresh_dir() {
  static std::atomic<int> counter{0};
  std::random_device rd;
  fs::path dir = fs::temp_directory_path() /
                 ("draglab_c_api_" + std::to_string(rd()) + "_" + std::to_string(counter++));
  fs::create_directories(dir);
  return dir;
}

class CApi : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fresh_dir();
    ASSERT_EQ(draglab_db_open((dir_ / "test.db").string().c_str(), &db_), DRAGLAB_OK)
        << draglab_last_error();
    ASSERT_EQ(draglab_law_load(db_, "bvk2007@1", &law_), DRAGLAB_OK) << draglab_last_error();
  }
  void TearDown() override {
    draglab_law_free(law_);
    draglab_db_close(db_);
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  double F(double phi, double re) {
    double value = kUntouched;
    EXPECT_EQ(draglab_law_F(law_, phi, re, &value), DRAGLAB_OK) << draglab_last_error();
    return value;
  }

  fs::path dir_;
  draglab_db* db_ = nullptr;
  draglab_law* law_ = nullptr;
};

TEST(CApiLibrary, VersionIsNotEmpty) {
  ASSERT_NE(draglab_version(), nullptr);
  EXPECT_GT(std::string(draglab_version()).size(), 0u);
}

TEST_F(CApi, IdentityOfTheLoadedLaw) {
  EXPECT_STREQ(draglab_law_name(law_), "bvk2007");
  EXPECT_EQ(draglab_law_version(law_), 1);
  EXPECT_STREQ(draglab_law_form(law_), "bvk2007");
  const std::string hash = draglab_law_hash(law_);
  EXPECT_EQ(hash.size(), 64u);
  EXPECT_EQ(hash.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_EQ(draglab_law_num_extra(law_), 0);
  // A clean load leaves no message behind (a retracted one would leave a warning).
  EXPECT_STREQ(draglab_last_error(), "");
  double phi_min, phi_max, re_min, re_max;
  ASSERT_EQ(draglab_law_validity(law_, &phi_min, &phi_max, &re_min, &re_max), DRAGLAB_OK);
  EXPECT_LT(phi_min, phi_max);
  EXPECT_LE(re_min, re_max);
}

TEST_F(CApi, PublishedCheckValues) {
  EXPECT_NEAR(F(0.1, 0.0), 2.42878, kCheckValueTolerance * 2.42878);
  EXPECT_NEAR(F(0.4, 100.0), 30.7416, kCheckValueTolerance * 30.7416);
}

TEST_F(CApi, LoadingTheSameLawByHashPrefixGivesTheSameValues) {
  const std::string ref = "bvk2007@" + std::string(draglab_law_hash(law_)).substr(0, 8);
  draglab_law* again = nullptr;
  ASSERT_EQ(draglab_law_load(db_, ref.c_str(), &again), DRAGLAB_OK) << draglab_last_error();
  double a = 0, b = 0;
  ASSERT_EQ(draglab_law_F(again, 0.35, 42.0, &a), DRAGLAB_OK);
  ASSERT_EQ(draglab_law_F(law_, 0.35, 42.0, &b), DRAGLAB_OK);
  EXPECT_EQ(a, b);
  draglab_law_free(again);
}

TEST_F(CApi, PhysicallyImpossibleInputsAreErrorsNeverNaN) {
  struct Case {
    double phi, re;
    const char* names;  // what the message must mention
  };
  const Case cases[] = {{1.2, 10.0, "phi"},  {1.0, 10.0, "phi"},  {-0.1, 10.0, "phi"},
                        {kNaN, 10.0, "phi"}, {kInf, 10.0, "phi"}, {0.3, -1.0, "Re"},
                        {0.3, kNaN, "Re"},   {0.3, kInf, "Re"}};
  for (const Case& c : cases) {
    double value = kUntouched;
    EXPECT_EQ(draglab_law_F(law_, c.phi, c.re, &value), DRAGLAB_INVALID_ARGUMENT)
        << "phi=" << c.phi << " re=" << c.re;
    EXPECT_EQ(value, kUntouched);
    EXPECT_NE(std::string(draglab_last_error()).find(c.names), std::string::npos)
        << draglab_last_error();
  }
  // Every policy refuses them: they are not "outside the validity box", they are impossible.
  ASSERT_EQ(draglab_law_set_range_policy(law_, DRAGLAB_RANGE_EXTRAPOLATE), DRAGLAB_OK);
  double value = kUntouched;
  EXPECT_EQ(draglab_law_F(law_, 1.2, 10.0, &value), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_F(law_, 0.3, kNaN, &value), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(value, kUntouched);
}

TEST_F(CApi, RangePolicies) {
  // phi = 0.05 is physical but below the validity box of bvk2007 (phi >= 0.1).
  double value = kUntouched;
  EXPECT_EQ(draglab_law_F(law_, 0.05, 10.0, &value), DRAGLAB_OUT_OF_VALIDITY);
  EXPECT_EQ(value, kUntouched);
  EXPECT_NE(std::string(draglab_last_error()).find("validity"), std::string::npos);
  long long count = -1;
  ASSERT_EQ(draglab_law_out_of_range_count(law_, &count), DRAGLAB_OK);
  EXPECT_EQ(count, 0);

  int policy = -1;
  ASSERT_EQ(draglab_law_set_range_policy(law_, DRAGLAB_RANGE_CLAMP), DRAGLAB_OK);
  ASSERT_EQ(draglab_law_range_policy(law_, &policy), DRAGLAB_OK);
  EXPECT_EQ(policy, DRAGLAB_RANGE_CLAMP);
  ASSERT_EQ(draglab_law_F(law_, 0.05, 10.0, &value), DRAGLAB_OK);
  double phi_min, phi_max, re_min, re_max;
  ASSERT_EQ(draglab_law_validity(law_, &phi_min, &phi_max, &re_min, &re_max), DRAGLAB_OK);
  EXPECT_EQ(value, F(phi_min, 10.0));  // clamped onto the edge of the box
  ASSERT_EQ(draglab_law_out_of_range_count(law_, &count), DRAGLAB_OK);
  EXPECT_EQ(count, 1);

  ASSERT_EQ(draglab_law_set_range_policy(law_, DRAGLAB_RANGE_EXTRAPOLATE), DRAGLAB_OK);
  double extrapolated = kUntouched;
  ASSERT_EQ(draglab_law_F(law_, 0.05, 10.0, &extrapolated), DRAGLAB_OK);
  EXPECT_TRUE(std::isfinite(extrapolated));
  EXPECT_LT(extrapolated, value);  // F increases with phi: the formula itself, not the edge
  ASSERT_EQ(draglab_law_out_of_range_count(law_, &count), DRAGLAB_OK);
  EXPECT_EQ(count, 2);

  EXPECT_EQ(draglab_law_set_range_policy(law_, 7), DRAGLAB_INVALID_ARGUMENT);
  ASSERT_EQ(draglab_law_range_policy(law_, &policy), DRAGLAB_OK);
  EXPECT_EQ(policy, DRAGLAB_RANGE_EXTRAPOLATE);  // unchanged by the refused call
}

// A host solver that traps floating-point exceptions (OpenFOAM does, FOAM_SIGFPE; so do Fortran
// codes built with -ffpe-trap) must survive every evaluation inside the validity box: bvk2007 at
// Re = 0 computes pow(0, -x) in a term it then discards. Run in a child process, so that a trap
// fails this test instead of killing the test runner; the child also checks that its own trap
// settings and flags are as it left them.
TEST_F(CApi, EvaluationsSurviveAHostThatTrapsFloatingPointExceptions) {
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    feenableexcept(FE_DIVBYZERO | FE_INVALID | FE_OVERFLOW);
    double value = 0.0;
    const double phi[3] = {0.1, 0.3, 0.6}, re[3] = {0.0, 0.0, 10.0};
    double out[3] = {0, 0, 0};
    const bool ok = draglab_law_F(law_, 0.3, 0.0, &value) == DRAGLAB_OK && value > 0.0 &&
                    draglab_law_F_n(law_, 3, phi, re, out) == DRAGLAB_OK && out[0] > 0.0 &&
                    out[1] > 0.0 && out[2] > 0.0;
    const bool traps_kept = fegetexcept() == (FE_DIVBYZERO | FE_INVALID | FE_OVERFLOW) &&
                            !fetestexcept(FE_ALL_EXCEPT & ~FE_INEXACT);
    _exit(ok && traps_kept ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the evaluation trapped (signal " << WTERMSIG(status) << ")";
  EXPECT_EQ(WEXITSTATUS(status), 0) << "wrong values, or the caller's traps were not restored";
}

// CFD-DEM per-particle drag against the conversion identities (drag_db/conventions.h): for equal
// spheres gamma = beta V_p / phi with beta from draglab_law_beta, and gamma / (3 pi mu d eps) is
// the law's F at the returned Re = rho eps d slip / mu. Polydisperse bvk2007_poly: F_i is
// normalised by 3 pi mu d_i eps u at Re based on the Sauter mean <d>, and equals
// F_bvk2007(phi, Re) [(1 - phi) y + phi y^2 + 0.064 (1 - phi) y^3] with y = d_i/<d> (the law's
// documented form), checked at y = 1 and y = 2 against bvk2007 itself. Tolerance: a few roundings.
TEST_F(CApi, ParticleDragSatisfiesTheConversionIdentities) {
  constexpr double kPi = 3.14159265358979323846;
  const double eps = 0.65, mu = 1.8e-5, rho = 1.2, slip = 0.4, d = 4e-4, phi = 1.0 - eps;
  double gamma = kUntouched, re = kUntouched, beta = 0.0;
  ASSERT_EQ(draglab_law_particle_drag(law_, eps, mu, rho, slip, d, d, &gamma, &re), DRAGLAB_OK)
      << draglab_last_error();
  ASSERT_EQ(draglab_law_beta(law_, eps, mu, rho, slip, d, 2500.0, &beta), DRAGLAB_OK);
  const double volume = kPi * d * d * d / 6.0;
  EXPECT_NEAR(gamma * phi / volume / beta, 1.0, kRoundingTolerance);
  EXPECT_NEAR(re / (rho * eps * d * slip / mu), 1.0, kRoundingTolerance);
  EXPECT_NEAR(gamma / (3.0 * kPi * mu * d * eps) / F(phi, re), 1.0, kRoundingTolerance);
  // d_mean is ignored by a monodisperse law.
  double other = kUntouched;
  ASSERT_EQ(draglab_law_particle_drag(law_, eps, mu, rho, slip, d, 3.0 * d, &other, nullptr),
            DRAGLAB_OK);
  EXPECT_EQ(other, gamma);

  draglab_law* poly = nullptr;
  ASSERT_EQ(draglab_law_load(db_, "bvk2007_poly@1", &poly), DRAGLAB_OK) << draglab_last_error();
  for (const double y : {1.0, 2.0}) {
    double g = kUntouched, r = kUntouched;
    ASSERT_EQ(draglab_law_particle_drag(poly, eps, mu, rho, slip, y * d, d, &g, &r), DRAGLAB_OK)
        << draglab_last_error();
    EXPECT_NEAR(r / (rho * eps * d * slip / mu), 1.0, kRoundingTolerance);  // Re with <d>
    const double factor = eps * y + phi * y * y + 0.064 * eps * y * y * y;
    EXPECT_NEAR(g / (3.0 * kPi * mu * (y * d) * eps) / (F(phi, r) * factor), 1.0,
                kRoundingTolerance)
        << "y = " << y;
  }
  double untouched = kUntouched;
  EXPECT_EQ(draglab_law_particle_drag(poly, eps, mu, rho, slip, -d, d, &untouched, nullptr),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_NE(std::string(draglab_last_error()).find("d_i"), std::string::npos);
  EXPECT_EQ(untouched, kUntouched);
  EXPECT_EQ(draglab_law_particle_drag(law_, 1.5, mu, rho, slip, d, d, &untouched, nullptr),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(untouched, kUntouched);
  draglab_law_free(poly);
}

TEST_F(CApi, NullPointersAreInvalidArguments) {
  double value = kUntouched;
  EXPECT_EQ(draglab_law_F(nullptr, 0.3, 1.0, &value), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_F(law_, 0.3, 1.0, nullptr), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_K(law_, 0.3, 1.0, nullptr), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_beta(nullptr, 0.6, 1.8e-5, 1.2, 0.5, 5e-4, 2500.0, &value),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_beta(law_, 0.6, 1.8e-5, 1.2, 0.5, 5e-4, 2500.0, nullptr),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_F_n(law_, 3, nullptr, nullptr, nullptr), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_F_extra(law_, 0.3, 1.0, nullptr, nullptr), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_out_of_range_count(law_, nullptr), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_set_range_policy(nullptr, 0), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_version(nullptr), -1);
  EXPECT_EQ(draglab_law_num_extra(nullptr), -1);
  EXPECT_STREQ(draglab_law_name(nullptr), "");
  EXPECT_EQ(value, kUntouched);

  draglab_law* law = nullptr;
  EXPECT_EQ(draglab_law_load(nullptr, "bvk2007", &law), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_load(db_, nullptr, &law), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_load(db_, "bvk2007", nullptr), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(law, nullptr);
  EXPECT_EQ(draglab_db_open("x.db", nullptr), DRAGLAB_INVALID_ARGUMENT);
  // Freeing or closing NULL is a no-op, as free(NULL).
  draglab_law_free(nullptr);
  draglab_db_close(nullptr);
}

TEST_F(CApi, UnknownLawsAreNotFound) {
  draglab_law* law = nullptr;
  EXPECT_EQ(draglab_law_load(db_, "no_such_law", &law), DRAGLAB_NOT_FOUND);
  EXPECT_NE(std::string(draglab_last_error()).find("no_such_law"), std::string::npos);
  EXPECT_EQ(draglab_law_load(db_, "bvk2007@999", &law), DRAGLAB_NOT_FOUND);
  EXPECT_EQ(law, nullptr);
}

TEST(CApiDatabase, ACorruptFileIsNotADatabase) {
  const fs::path dir = fresh_dir();
  const fs::path path = dir / "garbage.db";
  {
    std::ofstream out(path, std::ios::binary);
    for (int i = 0; i < 4096; ++i) out.put(static_cast<char>(i * 37 + 11));
  }
  draglab_db* db = nullptr;
  EXPECT_EQ(draglab_db_open(path.string().c_str(), &db), DRAGLAB_NOT_A_DATABASE);
  EXPECT_EQ(db, nullptr);
  EXPECT_GT(std::string(draglab_last_error()).size(), 0u);
  fs::remove_all(dir);
}

// ---- read-only opens: a solver reading a shared installation it cannot write ---------------

constexpr uid_t kNobody = 65534;

// Runs `check` ("" = passed, else what failed) as an unprivileged user: as root (which ignores
// file permissions) in a forked child that drops to uid/gid 65534 without supplementary groups,
// as `setpriv --reuid=65534 --regid=65534 --clear-groups` does; otherwise in this process.
std::string run_unprivileged(const std::function<std::string()>& check) {
  if (geteuid() != 0) return check();
  int fds[2];
  if (pipe(fds) != 0) return "pipe() failed";
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return "fork() failed";
  if (pid == 0) {
    close(fds[0]);
    const std::string result =
        (setgroups(0, nullptr) != 0 || setresgid(kNobody, kNobody, kNobody) != 0 ||
         setresuid(kNobody, kNobody, kNobody) != 0)
            ? "cannot drop privileges to uid/gid 65534"
            : check();
    const ssize_t ignored = write(fds[1], result.data(), result.size());
    (void)ignored;
    _exit(result.empty() ? 0 : 1);  // no atexit handlers, no gtest output from the child
  }
  close(fds[1]);
  std::string result;
  char buffer[512];
  ssize_t n;
  while ((n = read(fds[0], buffer, sizeof buffer)) > 0) result.append(buffer, n);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status)) return "the unprivileged child did not exit normally: " + result;
  if (WEXITSTATUS(status) != 0 && result.empty()) return "the unprivileged child failed";
  return result;
}

// Size, modification time and bytes of a file: what "nothing was written" compares.
std::string file_fingerprint(const fs::path& path) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return "missing";
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return std::to_string(st.st_size) + " bytes, mtime " + std::to_string(st.st_mtim.tv_sec) + "." +
         std::to_string(st.st_mtim.tv_nsec) + ", content hash " +
         std::to_string(std::hash<std::string>()(bytes));
}

std::vector<std::string> directory_entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// A seeded database closed (its WAL folded into the file), then made read-only the way a shared
// installation is: file 0444 in a directory 0555.
class CApiReadOnly : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fresh_dir();
    path_ = dir_ / "shared.db";
    draglab_db* db = nullptr;
    ASSERT_EQ(draglab_db_open(path_.c_str(), &db), DRAGLAB_OK) << draglab_last_error();
    draglab_db_close(db);
    ASSERT_FALSE(fs::exists(path_.string() + "-wal"));
    ASSERT_EQ(chmod(path_.c_str(), 0444), 0);
    ASSERT_EQ(chmod(dir_.c_str(), 0555), 0);
    fingerprint_ = file_fingerprint(path_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_, ec);
  }

  // Opens read-only, loads bvk2007@1 and checks F(0.4, 100); returns what failed.
  std::string read_through_the_abi() const {
    draglab_db* db = nullptr;
    if (draglab_db_open_readonly(path_.c_str(), &db) != DRAGLAB_OK) {
      return std::string("draglab_db_open_readonly: ") + draglab_last_error();
    }
    draglab_law* law = nullptr;
    std::string failures;
    if (draglab_law_load(db, "bvk2007@1", &law) != DRAGLAB_OK) {
      failures = std::string("load: ") + draglab_last_error();
    } else {
      double F = kUntouched;
      if (draglab_law_F(law, 0.4, 100.0, &F) != DRAGLAB_OK ||
          !(std::fabs(F - 30.7416) <= kCheckValueTolerance * 30.7416)) {
        failures = "F(0.4, 100) = " + std::to_string(F) + ", expected 30.7416";
      }
      draglab_law_free(law);
    }
    draglab_db_close(db);
    return failures;
  }

  fs::path dir_;
  fs::path path_;
  std::string fingerprint_;
};

TEST_F(CApiReadOnly, ReadsWithoutWritingTheFile) {
  EXPECT_EQ(read_through_the_abi(), "");
  EXPECT_EQ(file_fingerprint(path_), fingerprint_);
}

TEST_F(CApiReadOnly, UnprivilegedSolverReadsAnInstallationItCannotWrite) {
  const std::vector<std::string> entries = directory_entries(dir_);
  const std::string failure = run_unprivileged([&]() -> std::string {
    if (access(dir_.c_str(), W_OK) == 0) return "the 0555 directory is writable: no test";
    std::string failures = read_through_the_abi();
    if (directory_entries(dir_) != entries) failures += "; files were created next to it";
    // The read-write open is refused with a clear status.
    draglab_db* db = nullptr;
    if (draglab_db_open(path_.c_str(), &db) != DRAGLAB_DATABASE_ERROR) {
      failures += "; the read-write open was not refused";
      draglab_db_close(db);
    }
    return failures;
  });
  EXPECT_EQ(failure, "");
  EXPECT_EQ(file_fingerprint(path_), fingerprint_);
}

TEST_F(CApiReadOnly, BadPathsGiveTheirStatus) {
  // A missing file is not created.
  const fs::path absent = dir_ / "absent.db";
  draglab_db* db = nullptr;
  EXPECT_EQ(draglab_db_open_readonly(absent.c_str(), &db), DRAGLAB_NOT_FOUND);
  EXPECT_NE(std::string(draglab_last_error()).find(absent.string()), std::string::npos)
      << draglab_last_error();
  EXPECT_EQ(db, nullptr);
  EXPECT_FALSE(fs::exists(absent));
  // A directory, or a directory that does not exist, is bad input.
  EXPECT_EQ(draglab_db_open_readonly(dir_.c_str(), &db), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_db_open_readonly((dir_ / "nowhere" / "x.db").c_str(), &db),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_NE(std::string(draglab_last_error()).find("nowhere"), std::string::npos);
  EXPECT_EQ(db, nullptr);
  EXPECT_EQ(draglab_db_open_readonly(path_.c_str(), nullptr), DRAGLAB_INVALID_ARGUMENT);
}

TEST_F(CApi, LawOutlivesItsDatabase) {
  const double before = F(0.3, 20.0);
  draglab_db_close(db_);
  db_ = nullptr;
  EXPECT_EQ(F(0.3, 20.0), before);
}

TEST_F(CApi, ArrayPathEqualsScalarPath) {
  const std::vector<double> phi = {0.1, 0.2, 0.3, 0.45, 0.6, 0.33};
  const std::vector<double> re = {0.0, 1.0, 10.0, 100.0, 1000.0, 0.5};
  std::vector<double> out(phi.size(), kUntouched);
  ASSERT_EQ(draglab_law_F_n(law_, phi.size(), phi.data(), re.data(), out.data()), DRAGLAB_OK)
      << draglab_last_error();
  for (std::size_t i = 0; i < phi.size(); ++i) EXPECT_EQ(out[i], F(phi[i], re[i])) << i;
  // n = 0 is a no-op even with NULL arrays.
  EXPECT_EQ(draglab_law_F_n(law_, 0, nullptr, nullptr, nullptr), DRAGLAB_OK);
  // A bad element: the error names its index.
  std::vector<double> bad_re = re;
  bad_re[2] = kNaN;
  EXPECT_EQ(draglab_law_F_n(law_, phi.size(), phi.data(), bad_re.data(), out.data()),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_NE(std::string(draglab_last_error()).find("index 2"), std::string::npos)
      << draglab_last_error();
}

TEST_F(CApi, ConversionsOfF) {
  const double phi = 0.4, re = 100.0;
  const double f = F(phi, re);
  double K = 0, b = 0;
  ASSERT_EQ(draglab_law_K(law_, phi, re, &K), DRAGLAB_OK);
  EXPECT_NEAR(K, f / (1.0 - phi), kRoundingTolerance * K);
  ASSERT_EQ(draglab_law_beta_d2_over_mu(law_, phi, re, &b), DRAGLAB_OK);
  EXPECT_NEAR(b, 18.0 * phi * (1.0 - phi) * f, kRoundingTolerance * b);
}

TEST_F(CApi, BetaFromDimensionalInputs) {
  // Air-like gas and 0.5 mm particles: eps_g = 0.6, u = 0.5 m/s.
  const double eps_g = 0.6, mu_g = 1.8e-5, rho_g = 1.2, slip = 0.5, d_p = 5e-4, rho_s = 2500.0;
  const double phi = 1.0 - eps_g;
  const double re = rho_g * eps_g * d_p * slip / mu_g;  // superficial Re of the brief
  const double f = F(phi, re);
  const double expected_beta = 18.0 * mu_g * phi * eps_g * f / (d_p * d_p);
  double beta = kUntouched, dga = kUntouched;
  ASSERT_EQ(draglab_law_beta(law_, eps_g, mu_g, rho_g, slip, d_p, rho_s, &beta), DRAGLAB_OK)
      << draglab_last_error();
  EXPECT_NEAR(beta, expected_beta, kRoundingTolerance * expected_beta);
  ASSERT_EQ(draglab_law_dga(law_, eps_g, mu_g, rho_g, slip, d_p, rho_s, &dga), DRAGLAB_OK);
  EXPECT_NEAR(dga, beta / phi, kRoundingTolerance * dga);

  // rho_s is unused but must be physical; so must every other input.
  double value = kUntouched;
  EXPECT_EQ(draglab_law_beta(law_, eps_g, mu_g, rho_g, slip, d_p, 0.0, &value),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_NE(std::string(draglab_last_error()).find("rho_s"), std::string::npos);
  EXPECT_EQ(draglab_law_beta(law_, eps_g, mu_g, rho_g, slip, d_p, kNaN, &value),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_beta(law_, 1.2, mu_g, rho_g, slip, d_p, rho_s, &value),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_beta(law_, 0.0, mu_g, rho_g, slip, d_p, rho_s, &value),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_beta(law_, eps_g, -mu_g, rho_g, slip, d_p, rho_s, &value),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_dga(law_, eps_g, mu_g, rho_g, -slip, d_p, rho_s, &value),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(value, kUntouched);

  // lDgA stays finite at eps_g = 1 (phi = 0, outside the box: extrapolate) where beta/phi is 0/0.
  ASSERT_EQ(draglab_law_set_range_policy(law_, DRAGLAB_RANGE_EXTRAPOLATE), DRAGLAB_OK);
  ASSERT_EQ(draglab_law_dga(law_, 1.0, mu_g, rho_g, slip, d_p, rho_s, &dga), DRAGLAB_OK);
  const double re1 = rho_g * d_p * slip / mu_g;
  EXPECT_NEAR(dga, 18.0 * mu_g * F(0.0, re1) / (d_p * d_p), kRoundingTolerance * dga);
}

TEST_F(CApi, BetaArrayPathEqualsScalarPath) {
  const std::vector<double> eps = {0.45, 0.6, 0.75, 0.85};
  const std::vector<double> mu = {1.8e-5, 1.8e-5, 2.0e-5, 1.7e-5};
  const std::vector<double> rho = {1.2, 1.0, 1.3, 1.2};
  const std::vector<double> slip = {0.0, 0.1, 0.5, 2.0};
  const std::vector<double> d = {5e-4, 1e-4, 5e-4, 2e-3};
  std::vector<double> out(eps.size(), kUntouched);
  ASSERT_EQ(draglab_law_beta_n(law_, eps.size(), eps.data(), mu.data(), rho.data(), slip.data(),
                               d.data(), out.data()),
            DRAGLAB_OK)
      << draglab_last_error();
  for (std::size_t i = 0; i < eps.size(); ++i) {
    double b = 0;
    ASSERT_EQ(draglab_law_beta(law_, eps[i], mu[i], rho[i], slip[i], d[i], 2500.0, &b), DRAGLAB_OK);
    EXPECT_EQ(out[i], b) << i;
  }
  std::vector<double> bad = eps;
  bad[3] = 1.5;
  EXPECT_EQ(draglab_law_beta_n(law_, eps.size(), bad.data(), mu.data(), rho.data(), slip.data(),
                               d.data(), out.data()),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_NE(std::string(draglab_last_error()).find("index 3"), std::string::npos);
}

TEST_F(CApi, LastErrorIsPerThread) {
  double value = 0;
  ASSERT_EQ(draglab_law_F(law_, 1.5, 1.0, &value), DRAGLAB_INVALID_ARGUMENT);
  const std::string mine = draglab_last_error();
  ASSERT_FALSE(mine.empty());
  std::string other_before, other_after;
  std::thread other([&] {
    other_before = draglab_last_error();  // a fresh thread has no message
    double v = 0;
    draglab_law_F(law_, 0.3, -5.0, &v);
    other_after = draglab_last_error();
  });
  other.join();
  EXPECT_EQ(other_before, "");
  EXPECT_NE(other_after.find("Re"), std::string::npos);
  EXPECT_EQ(std::string(draglab_last_error()), mine);  // untouched by the other thread
}

TEST_F(CApi, ConcurrentEvaluationGivesTheSerialResults) {
  std::vector<double> phi, re, serial;
  for (int i = 0; i < 200; ++i) {
    phi.push_back(0.1 + 0.5 * (i % 20) / 19.0);
    re.push_back(1000.0 * (i / 20) / 9.0);
    serial.push_back(F(phi.back(), re.back()));
  }
  std::atomic<int> mismatches{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&] {
      for (int repeat = 0; repeat < 50; ++repeat) {
        for (std::size_t i = 0; i < phi.size(); ++i) {
          double v = 0;
          if (draglab_law_F(law_, phi[i], re[i], &v) != DRAGLAB_OK || v != serial[i]) ++mismatches;
        }
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(mismatches.load(), 0);
}

TEST_F(CApi, ExportThroughTheAbi) {
  std::size_t length = 0;
  ASSERT_EQ(draglab_law_export(law_, "c", nullptr, 0, &length), DRAGLAB_OK) << draglab_last_error();
  ASSERT_GT(length, 100u);
  std::vector<char> buffer(length + 1, 'x');
  ASSERT_EQ(draglab_law_export(law_, "c", buffer.data(), buffer.size(), &length), DRAGLAB_OK);
  const std::string text(buffer.data());
  EXPECT_EQ(text.size(), length);
  EXPECT_NE(text.find("double bvk2007_v1_F(double phi, double re)"), std::string::npos);
  EXPECT_NE(text.find(draglab_law_hash(law_)), std::string::npos);

  std::vector<char> small(10, 'x');
  EXPECT_EQ(draglab_law_export(law_, "c", small.data(), small.size(), &length),
            DRAGLAB_INVALID_ARGUMENT);
  EXPECT_EQ(draglab_law_export(law_, "pascal", nullptr, 0, &length), DRAGLAB_INVALID_ARGUMENT);
  EXPECT_NE(std::string(draglab_last_error()).find("fortran"), std::string::npos);
}

}  // namespace
