// Code export: a stored law version as standalone source for solvers that cannot link libdraglab
// (`draglab law export NAME@V --format c|fortran|json`; C ABI: draglab_law_export).
//
// C and Fortran are generated from the symbolic trace of the law's own template formula
// (law_form.h: F_symbolic), so the exported code performs the same floating-point operations in
// the same order as the library and agrees with Law::F to rounding (tested to 1e-12 relative).
// Branches written with select() become if/else blocks: only the selected arm is evaluated, so the
// exported code raises no floating-point exception from an unused arm (e.g. Re^-0.343 at Re = 0),
// which matters for solvers built with -ffpe-trap.
//
// What the exported C file defines, for a law `name@version` with identifier ID = name_vVERSION
// (characters outside [A-Za-z0-9_] replaced by '_'):
//   double ID_F(double phi, double re[, const double* extra]);
//       canonical drag-only F; no input checks (precondition: 0 <= phi < 1, 0 <= Re < inf).
//   double ID_beta(double eps_g, double mu_g, double rho_g, double slip, double d_p[, extra]);
//       friction coefficient beta [kg m^-3 s^-1], no input checks.
//   double ID_dga(...same arguments...);
//       MFiX's lDgA = beta / phi = 18 mu_g eps_g F / d_p^2 [kg m^-3 s^-1] (DRAG_USR output).
//   int ID_F_checked(double phi, double re[, extra], int range_policy, double* F);
//   int ID_beta_checked(eps_g, mu_g, rho_g, slip, d_p[, extra], int range_policy, double* beta);
//       status 0 ok; 1 invalid input (NaN/inf, phi outside [0,1), Re < 0, ...), output untouched;
//       2 outside the validity box: output untouched with range_policy 0 (error), written with
//       1 (clamp into the box) or 2 (extrapolate), so the caller can count the events;
//       8 non-finite result (a bug), output untouched. Same codes as draglab.h.
// The Fortran module ID_drag has the same procedures (pure functions, and pure subroutines
// ID_F_checked / ID_beta_checked with a `stat` argument).
#pragma once

#include <string>

#include "draglab/drag_db/law.h"

namespace draglab {

enum class ExportFormat { kC, kFortran, kJson };

/// "c", "fortran" (also "f90") or "json"; throws Error(kInvalidArgument) naming the valid ones.
ExportFormat export_format_from_string(const std::string& s);
const char* to_string(ExportFormat format);
/// Conventional file extension without the dot: "c", "f90", "json".
const char* file_extension(ExportFormat format);

/// The identifier of exported code for a record: name_vVERSION made a valid C/Fortran name.
std::string export_identifier(const LawRecord& record);

/// Standalone source (C, Fortran) or the full JSON record of `record`. The record's form must be
/// registered (Error(kNotFound) otherwise) and its parameters must match the form's
/// (Error(kInvalidArgument)). The C code needs only <math.h>; the Fortran code only
/// iso_c_binding.
std::string export_law(const LawRecord& record, ExportFormat format);

}  // namespace draglab
