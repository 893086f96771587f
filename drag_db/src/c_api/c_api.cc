// The C ABI of libdraglab (draglab/draglab.h) over the C++ API.
//
// Every entry point runs its body through guarded(): a draglab::Error becomes its ErrorCode as the
// status, any other exception DRAGLAB_INTERNAL, and the message goes to a thread-local string for
// draglab_last_error(). No exception crosses the ABI. Outputs are written only on success (the
// array functions are the documented exception). guarded() also holds the caller's
// floating-point traps (see FloatingPointGuard).
#include "draglab/draglab.h"

#include <cfenv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "drag_db_version.h"
#include "draglab/drag_db/database.h"
#include "draglab/drag_db/export.h"
#include "draglab/drag_db/law.h"
#include "draglab/error.h"

struct draglab_db {
  std::unique_ptr<draglab::Database> db;
};

struct draglab_law {
  std::shared_ptr<draglab::Law> law;
  // Cached so that the const char* accessors stay valid while the handle lives.
  std::string name;
  std::string form;
  std::string hash;
};

namespace {

using draglab::Error;
using draglab::ErrorCode;

thread_local std::string g_last_error;

static_assert(DRAGLAB_OK == static_cast<int>(ErrorCode::kOk), "status codes drifted");
static_assert(DRAGLAB_INVALID_ARGUMENT == static_cast<int>(ErrorCode::kInvalidArgument), "");
static_assert(DRAGLAB_OUT_OF_VALIDITY == static_cast<int>(ErrorCode::kOutOfValidity), "");
static_assert(DRAGLAB_NOT_FOUND == static_cast<int>(ErrorCode::kNotFound), "");
static_assert(DRAGLAB_IMMUTABLE == static_cast<int>(ErrorCode::kImmutable), "");
static_assert(DRAGLAB_DATABASE_ERROR == static_cast<int>(ErrorCode::kDatabase), "");
static_assert(DRAGLAB_SCHEMA_TOO_NEW == static_cast<int>(ErrorCode::kSchemaTooNew), "");
static_assert(DRAGLAB_NOT_A_DATABASE == static_cast<int>(ErrorCode::kNotADatabase), "");
static_assert(DRAGLAB_INTERNAL == static_cast<int>(ErrorCode::kInternal), "");
static_assert(DRAGLAB_IO_ERROR == static_cast<int>(ErrorCode::kIo), "");

/// Records `message` for draglab_last_error(); never throws (an allocation failure leaves the
/// previous message, which is still better than an exception across the ABI).
void set_last_error(const char* message) noexcept {
  try {
    g_last_error = message;
  } catch (...) {
  }
}

int fail(int status, const char* message) noexcept {
  set_last_error(message);
  return status;
}

/// Host solvers often trap floating-point exceptions (OpenFOAM's FOAM_SIGFPE, gfortran's
/// -ffpe-trap). The forms are evaluated branch-free and may raise one in a value they then
/// discard (pow(0, -x) masked by a select at Re = 0), so the traps are held while draglab
/// computes and the caller's environment, its flags included, is restored afterwards. A result
/// that is really not finite is still reported as an error.
class FloatingPointGuard {
 public:
  FloatingPointGuard() noexcept { std::feholdexcept(&saved_); }
  ~FloatingPointGuard() { std::fesetenv(&saved_); }
  FloatingPointGuard(const FloatingPointGuard&) = delete;
  FloatingPointGuard& operator=(const FloatingPointGuard&) = delete;

 private:
  std::fenv_t saved_;
};

/// Runs `body` (returning void) and maps exceptions to status codes.
template <typename Body>
int guarded(Body&& body) noexcept {
  const FloatingPointGuard traps_held;
  try {
    body();
    return DRAGLAB_OK;
  } catch (const Error& e) {
    return fail(static_cast<int>(e.code()), e.what());
  } catch (const std::bad_alloc&) {
    return fail(DRAGLAB_INTERNAL, "out of memory");
  } catch (const std::exception& e) {
    return fail(DRAGLAB_INTERNAL, e.what());
  } catch (...) {
    return fail(DRAGLAB_INTERNAL, "unknown internal error");
  }
}

void require(bool ok, const char* what) {
  if (!ok) throw Error(ErrorCode::kInvalidArgument, what);
}

const draglab::Law& law_of(const draglab_law* law, const char* function) {
  if (law == nullptr || !law->law) {
    throw Error(ErrorCode::kInvalidArgument, std::string(function) + ": law is NULL");
  }
  return *law->law;
}

std::string format_value(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

/// rho_s is accepted for MFiX signature compatibility: it must be physical, but is not used.
void check_rho_s(const draglab::Law& law, double rho_s) {
  if (!std::isfinite(rho_s) || !(rho_s > 0.0)) {
    throw Error(ErrorCode::kInvalidArgument,
                law.reference() + ": rho_s = " + format_value(rho_s) + " must be finite and > 0");
  }
}

/// Opens `path` ($DRAGLAB_DB or ./draglab.db if NULL or "") with `options` into *db.
int open_database(const char* function, const char* path, const draglab::DatabaseOptions& options,
                  draglab_db** db) {
  return guarded([&] {
    if (db == nullptr)
      throw Error(ErrorCode::kInvalidArgument, std::string(function) + ": db is NULL");
    const std::string file =
        (path == nullptr || path[0] == '\0') ? draglab::Database::default_path() : path;
    auto handle = std::make_unique<draglab_db>();
    handle->db = std::make_unique<draglab::Database>(file, options);
    *db = handle.release();
  });
}

}  // namespace

extern "C" {

const char* draglab_version(void) { return draglab::kDragDbVersion; }

int draglab_db_open(const char* path, draglab_db** db) {
  return open_database("draglab_db_open", path, draglab::DatabaseOptions(), db);
}

int draglab_db_open_readonly(const char* path, draglab_db** db) {
  draglab::DatabaseOptions options;
  options.read_only = true;
  options.create_if_missing = false;
  return open_database("draglab_db_open_readonly", path, options, db);
}

void draglab_db_close(draglab_db* db) {
  // The destructor closes SQLite; it does not throw, but stay on the safe side of the ABI.
  try {
    delete db;
  } catch (...) {
  }
}

int draglab_law_load(draglab_db* db, const char* ref, draglab_law** law) {
  if (db == nullptr || !db->db)
    return fail(DRAGLAB_INVALID_ARGUMENT, "draglab_law_load: db is NULL");
  if (ref == nullptr) return fail(DRAGLAB_INVALID_ARGUMENT, "draglab_law_load: ref is NULL");
  if (law == nullptr) return fail(DRAGLAB_INVALID_ARGUMENT, "draglab_law_load: law is NULL");
  std::string warning;
  const int status = guarded([&] {
    auto handle = std::make_unique<draglab_law>();
    handle->law = db->db->load(ref, draglab::RangePolicy::kError, &warning);
    const draglab::LawRecord& r = handle->law->record();
    handle->name = r.name;
    handle->form = r.form;
    handle->hash = r.content_hash;
    *law = handle.release();
  });
  // A retracted (or draft) version loads with a warning for the caller to show; a clean load
  // clears the message so that the caller can tell the two apart.
  if (status == DRAGLAB_OK) set_last_error(warning.c_str());
  return status;
}

void draglab_law_free(draglab_law* law) { delete law; }

const char* draglab_law_name(const draglab_law* law) {
  if (law == nullptr) {
    fail(DRAGLAB_INVALID_ARGUMENT, "draglab_law_name: law is NULL");
    return "";
  }
  return law->name.c_str();
}

int draglab_law_version(const draglab_law* law) {
  if (law == nullptr || !law->law) {
    fail(DRAGLAB_INVALID_ARGUMENT, "draglab_law_version: law is NULL");
    return -1;
  }
  return law->law->record().version;
}

const char* draglab_law_form(const draglab_law* law) {
  if (law == nullptr) {
    fail(DRAGLAB_INVALID_ARGUMENT, "draglab_law_form: law is NULL");
    return "";
  }
  return law->form.c_str();
}

const char* draglab_law_hash(const draglab_law* law) {
  if (law == nullptr) {
    fail(DRAGLAB_INVALID_ARGUMENT, "draglab_law_hash: law is NULL");
    return "";
  }
  return law->hash.c_str();
}

int draglab_law_num_extra(const draglab_law* law) {
  if (law == nullptr || !law->law) {
    fail(DRAGLAB_INVALID_ARGUMENT, "draglab_law_num_extra: law is NULL");
    return -1;
  }
  return law->law->num_extra_inputs();
}

int draglab_law_validity(const draglab_law* law, double* phi_min, double* phi_max, double* re_min,
                         double* re_max) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_validity");
    require(phi_min != nullptr && phi_max != nullptr && re_min != nullptr && re_max != nullptr,
            "draglab_law_validity: an output pointer is NULL");
    const draglab::ValidityBox& box = l.record().validity;
    *phi_min = box.phi.min;
    *phi_max = box.phi.max;
    *re_min = box.re.min;
    *re_max = box.re.max;
  });
}

int draglab_law_set_range_policy(draglab_law* law, int policy) {
  return guarded([&] {
    law_of(law, "draglab_law_set_range_policy");
    switch (policy) {
      case DRAGLAB_RANGE_ERROR:
        law->law->set_range_policy(draglab::RangePolicy::kError);
        break;
      case DRAGLAB_RANGE_CLAMP:
        law->law->set_range_policy(draglab::RangePolicy::kClamp);
        break;
      case DRAGLAB_RANGE_EXTRAPOLATE:
        law->law->set_range_policy(draglab::RangePolicy::kExtrapolate);
        break;
      default:
        throw Error(ErrorCode::kInvalidArgument,
                    "draglab_law_set_range_policy: policy " + std::to_string(policy) +
                        " is not one of DRAGLAB_RANGE_ERROR (0), DRAGLAB_RANGE_CLAMP (1), "
                        "DRAGLAB_RANGE_EXTRAPOLATE (2)");
    }
  });
}

int draglab_law_range_policy(const draglab_law* law, int* policy) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_range_policy");
    require(policy != nullptr, "draglab_law_range_policy: policy is NULL");
    switch (l.range_policy()) {
      case draglab::RangePolicy::kClamp:
        *policy = DRAGLAB_RANGE_CLAMP;
        break;
      case draglab::RangePolicy::kExtrapolate:
        *policy = DRAGLAB_RANGE_EXTRAPOLATE;
        break;
      case draglab::RangePolicy::kError:
      default:
        *policy = DRAGLAB_RANGE_ERROR;
        break;
    }
  });
}

int draglab_law_out_of_range_count(const draglab_law* law, long long* count) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_out_of_range_count");
    require(count != nullptr, "draglab_law_out_of_range_count: count is NULL");
    *count = static_cast<long long>(l.out_of_range_count());
  });
}

int draglab_law_F(const draglab_law* law, double phi, double re, double* F) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_F");
    require(F != nullptr, "draglab_law_F: F is NULL");
    *F = l.F(phi, re);
  });
}

int draglab_law_F_extra(const draglab_law* law, double phi, double re, const double* extra,
                        double* F) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_F_extra");
    require(F != nullptr, "draglab_law_F_extra: F is NULL");
    *F = l.F(phi, re, extra);
  });
}

int draglab_law_F_n(const draglab_law* law, size_t n, const double* phi, const double* re,
                    double* F) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_F_n");
    if (n == 0) return;
    require(phi != nullptr && re != nullptr && F != nullptr,
            "draglab_law_F_n: phi, re or F is NULL");
    l.F(n, phi, re, F);
  });
}

int draglab_law_beta_d2_over_mu(const draglab_law* law, double phi, double re, double* value) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_beta_d2_over_mu");
    require(value != nullptr, "draglab_law_beta_d2_over_mu: value is NULL");
    *value = l.beta_d2_over_mu(phi, re);
  });
}

int draglab_law_K(const draglab_law* law, double phi, double re, double* K) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_K");
    require(K != nullptr, "draglab_law_K: K is NULL");
    *K = l.K(phi, re);
  });
}

int draglab_law_beta(const draglab_law* law, double eps_g, double mu_g, double rho_g, double slip,
                     double d_p, double rho_s, double* beta) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_beta");
    require(beta != nullptr, "draglab_law_beta: beta is NULL");
    check_rho_s(l, rho_s);
    *beta = l.beta(eps_g, mu_g, rho_g, slip, d_p);
  });
}

int draglab_law_dga(const draglab_law* law, double eps_g, double mu_g, double rho_g, double slip,
                    double d_p, double rho_s, double* dga_out) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_dga");
    require(dga_out != nullptr, "draglab_law_dga: dga is NULL");
    check_rho_s(l, rho_s);
    *dga_out = l.dga(eps_g, mu_g, rho_g, slip, d_p);
  });
}

int draglab_law_particle_drag(const draglab_law* law, double eps_g, double mu_g, double rho_g,
                              double slip, double d_i, double d_mean, double* gamma, double* re) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_particle_drag");
    require(gamma != nullptr, "draglab_law_particle_drag: gamma is NULL");
    double re_used = 0.0;
    const double value = l.particle_drag(eps_g, mu_g, rho_g, slip, d_i, d_mean, &re_used);
    *gamma = value;
    if (re != nullptr) *re = re_used;
  });
}

int draglab_law_beta_n(const draglab_law* law, size_t n, const double* eps_g, const double* mu_g,
                       const double* rho_g, const double* slip, const double* d_p, double* beta) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_beta_n");
    if (n == 0) return;
    require(eps_g != nullptr && mu_g != nullptr && rho_g != nullptr && slip != nullptr &&
                d_p != nullptr && beta != nullptr,
            "draglab_law_beta_n: an array is NULL");
    for (size_t i = 0; i < n; ++i) {
      try {
        beta[i] = l.beta(eps_g[i], mu_g[i], rho_g[i], slip[i], d_p[i]);
      } catch (const Error& e) {
        throw Error(e.code(), std::string(e.what()) + " (at index " + std::to_string(i) + ")");
      }
    }
  });
}

int draglab_law_export(const draglab_law* law, const char* format, char* buffer, size_t size,
                       size_t* length) {
  return guarded([&] {
    const draglab::Law& l = law_of(law, "draglab_law_export");
    require(format != nullptr, "draglab_law_export: format is NULL");
    require(length != nullptr, "draglab_law_export: length is NULL");
    const std::string text =
        draglab::export_law(l.record(), draglab::export_format_from_string(format));
    *length = text.size();
    if (buffer == nullptr && size == 0) return;  // length query
    require(buffer != nullptr, "draglab_law_export: buffer is NULL but size is not 0");
    if (size < text.size() + 1) {
      throw Error(ErrorCode::kInvalidArgument, "draglab_law_export: buffer of " +
                                                   std::to_string(size) + " bytes is too small, " +
                                                   std::to_string(text.size() + 1) + " needed");
    }
    std::memcpy(buffer, text.c_str(), text.size() + 1);
  });
}

const char* draglab_last_error(void) { return g_last_error.c_str(); }

}  // extern "C"
