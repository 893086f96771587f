/* draglab.h: the C ABI of libdraglab, for solvers written in C, Fortran (draglab_mod) or Python
 * (draglab.py, ctypes).
 *
 *   draglab_db* db;  draglab_law* law;  double F;
 *   if (draglab_db_open("draglab.db", &db) != 0) fprintf(stderr, "%s\n", draglab_last_error());
 *   draglab_law_load(db, "bvk2007@1", &law);
 *   draglab_law_F(law, 0.3, 50.0, &F);         // canonical drag-only F(phi, Re)
 *   draglab_law_free(law);  draglab_db_close(db);
 *
 * Conventions (docs/conventions.md): phi solids fraction; Re = rho eps d u / mu with u the
 * interstitial slip; F = F_d / (3 pi mu d eps u), drag only; beta = 18 mu phi eps F / d^2.
 *
 * Every function returns an integer status (0 = ok, see DRAGLAB_* below); no C++ exception
 * crosses this interface. On error the output is left untouched and draglab_last_error() returns
 * a message (thread-local, valid until the next failing call on the same thread).
 * A loaded law is immutable and may be evaluated from many threads at once; it does not need the
 * database after loading (the database handle may be closed first).
 */
#ifndef DRAGLAB_DRAGLAB_H_
#define DRAGLAB_DRAGLAB_H_

#include <stddef.h>

#if defined(_WIN32)
#define DRAGLAB_EXPORT __declspec(dllexport)
#else
#define DRAGLAB_EXPORT __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes (same values as draglab::ErrorCode). */
#define DRAGLAB_OK 0
#define DRAGLAB_INVALID_ARGUMENT 1  /* NaN/inf, eps outside (0,1], Re < 0, null pointer, ... */
#define DRAGLAB_OUT_OF_VALIDITY 2   /* outside the law's validity box with the "error" policy */
#define DRAGLAB_NOT_FOUND 3         /* unknown law, version or hash prefix */
#define DRAGLAB_IMMUTABLE 4         /* change to a published/retracted version */
#define DRAGLAB_DATABASE_ERROR 5    /* SQLite failure */
#define DRAGLAB_SCHEMA_TOO_NEW 6    /* database written by a newer draglab */
#define DRAGLAB_NOT_A_DATABASE 7    /* corrupt or non-SQLite file */
#define DRAGLAB_INTERNAL 8
#define DRAGLAB_IO_ERROR 9          /* a file could not be written or read (disk full, ...) */

/* Range policies for inputs inside physical bounds but outside the law's validity box. */
#define DRAGLAB_RANGE_ERROR 0       /* default: return DRAGLAB_OUT_OF_VALIDITY */
#define DRAGLAB_RANGE_CLAMP 1       /* clamp into the box, count the event */
#define DRAGLAB_RANGE_EXTRAPOLATE 2 /* evaluate as is, count the event */

typedef struct draglab_db draglab_db;
typedef struct draglab_law draglab_law;

/* Library version string, e.g. "0.1.0 (g1234abc)". */
DRAGLAB_EXPORT const char* draglab_version(void);

/* Opens (creating and seeding if missing) a database. path NULL or "" -> $DRAGLAB_DB, else
 * ./draglab.db. */
DRAGLAB_EXPORT int draglab_db_open(const char* path, draglab_db** db);
/* Opens an existing database read-only, for solvers reading a shared installation: never
 * writes, creates, migrates or seeds it, and works on a file and directory the caller cannot
 * write (in a directory it cannot write, the file is read as immutable: changes made while it is
 * open are not seen). path NULL or "" as for draglab_db_open. A missing file gives
 * DRAGLAB_NOT_FOUND, a missing directory or a directory as path DRAGLAB_INVALID_ARGUMENT. */
DRAGLAB_EXPORT int draglab_db_open_readonly(const char* path, draglab_db** db);
DRAGLAB_EXPORT void draglab_db_close(draglab_db* db);

/* Loads "name", "name@3", "name@latest" or "name@<hash prefix>". A retracted (or draft) version
 * loads with status 0 and a warning in draglab_last_error(); any other successful load sets
 * draglab_last_error() to "". */
DRAGLAB_EXPORT int draglab_law_load(draglab_db* db, const char* ref, draglab_law** law);
DRAGLAB_EXPORT void draglab_law_free(draglab_law* law);

/* Name, version, form key and content hash of a loaded law (pointers valid while law lives). */
DRAGLAB_EXPORT const char* draglab_law_name(const draglab_law* law);
DRAGLAB_EXPORT int draglab_law_version(const draglab_law* law);
DRAGLAB_EXPORT const char* draglab_law_form(const draglab_law* law);
DRAGLAB_EXPORT const char* draglab_law_hash(const draglab_law* law);
/* Number of extra inputs (polydisperse forms: 1, the size ratio y = d_i/<d>; else 0). */
DRAGLAB_EXPORT int draglab_law_num_extra(const draglab_law* law);

/* Validity box of the law: phi in [phi_min, phi_max], Re in [re_min, re_max] (a bound may be
 * +-HUGE_VAL where the law is unbounded on that side). */
DRAGLAB_EXPORT int draglab_law_validity(const draglab_law* law, double* phi_min, double* phi_max,
                                        double* re_min, double* re_max);

/* Range policy (DRAGLAB_RANGE_*); set it before sharing the law between threads. */
DRAGLAB_EXPORT int draglab_law_set_range_policy(draglab_law* law, int policy);
DRAGLAB_EXPORT int draglab_law_range_policy(const draglab_law* law, int* policy);
/* Number of clamped/extrapolated evaluations since load. */
DRAGLAB_EXPORT int draglab_law_out_of_range_count(const draglab_law* law, long long* count);

/* Canonical drag-only F(phi, Re). */
DRAGLAB_EXPORT int draglab_law_F(const draglab_law* law, double phi, double re, double* F);
/* Same with extra inputs (num_extra values). */
DRAGLAB_EXPORT int draglab_law_F_extra(const draglab_law* law, double phi, double re,
                                       const double* extra, double* F);
/* Array path: F[i] = F(phi[i], re[i]). n = 0 is a no-op (the pointers may then be NULL). On error
 * the message names the first bad index and the contents of F are unspecified (the arrays are
 * evaluated in blocks; no copy of the output is made). */
DRAGLAB_EXPORT int draglab_law_F_n(const draglab_law* law, size_t n, const double* phi,
                                   const double* re, double* F);
/* beta d^2/mu = 18 phi (1-phi) F and K = F/(1-phi) (total force incl. mean pressure part). */
DRAGLAB_EXPORT int draglab_law_beta_d2_over_mu(const draglab_law* law, double phi, double re,
                                               double* value);
DRAGLAB_EXPORT int draglab_law_K(const draglab_law* law, double phi, double re, double* K);
/* Friction coefficient beta [kg m^-3 s^-1], argument order of MFiX's usr_drag: gas fraction,
 * gas viscosity [Pa s], gas density [kg/m^3], interstitial slip [m/s], particle diameter [m],
 * particle density [kg/m^3] (accepted for signature compatibility; must be > 0; unused). */
DRAGLAB_EXPORT int draglab_law_beta(const draglab_law* law, double eps_g, double mu_g,
                                    double rho_g, double slip, double d_p, double rho_s,
                                    double* beta);

/* MFiX's DRAG_USR output lDgA = beta / phi = 18 mu_g eps_g F / d_p^2 [kg m^-3 s^-1], the model-A
 * coefficient per unit solids fraction (MFiX multiplies it by EP_SM, EP_SM/EPg for model B, or
 * by the particle volume in DES). Same arguments and checks as draglab_law_beta; finite at
 * eps_g = 1. */
DRAGLAB_EXPORT int draglab_law_dga(const draglab_law* law, double eps_g, double mu_g,
                                   double rho_g, double slip, double d_p, double rho_s,
                                   double* dga);
/* Array path of draglab_law_beta over cells or particles: beta[i] from eps_g[i], mu_g[i],
 * rho_g[i], slip[i], d_p[i] (SI units). On error the message names the first bad index and the
 * contents of beta are unspecified. */
DRAGLAB_EXPORT int draglab_law_beta_n(const draglab_law* law, size_t n, const double* eps_g,
                                      const double* mu_g, const double* rho_g,
                                      const double* slip, const double* d_p, double* beta);

/* CFD-DEM per-particle drag (CFDEM/LIGGGHTS style): the coefficient gamma [kg/s] with which the
 * fluid drags one particle, F_i = gamma (u_f - u_p), and the particle Reynolds number re used.
 * eps_g: local voidage; mu_g [Pa s], rho_g [kg/m^3]: fluid; slip = |u_f - u_p| [m/s]; d_i [m]:
 * the particle's diameter; d_mean [m]: the Sauter mean diameter of the particles around it, used
 * by polydisperse laws (y = d_i/d_mean, Re with d_mean) and ignored by the others (Re with d_i).
 * gamma = 3 pi mu_g d_i eps_g F(phi, Re), Re = rho_g eps_g d slip / mu_g; for equal spheres
 * gamma = beta V_p / phi. re may be NULL. */
DRAGLAB_EXPORT int draglab_law_particle_drag(const draglab_law* law, double eps_g, double mu_g,
                                             double rho_g, double slip, double d_i, double d_mean,
                                             double* gamma, double* re);

/* Standalone source of the loaded law version, as `draglab law export`: format "c", "fortran" or
 * "json". Writes at most `size` bytes including the terminating NUL into `buffer` and the full
 * length (without NUL) into *length. Query the length with buffer = NULL, size = 0 (status 0);
 * a non-NULL buffer that is too small gives DRAGLAB_INVALID_ARGUMENT (with *length set). */
DRAGLAB_EXPORT int draglab_law_export(const draglab_law* law, const char* format, char* buffer,
                                      size_t size, size_t* length);

/* Message of the last failing call on this thread ("" if none). */
DRAGLAB_EXPORT const char* draglab_last_error(void);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* DRAGLAB_DRAGLAB_H_ */
