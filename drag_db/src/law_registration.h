// Turns a law class (one file pair in laws/) into a registered LawForm. Private to drag_db.
//
// A law class provides:
//   static constexpr int kNumParameters, kNumExtraInputs;
//   static constexpr NativeConvention kConvention;
//   static LawFormDescription describe();
//   template <typename T> static T native(const T& phi, const T& re_native,
//                                         const T* extra, const T* params);
// `native` returns the quantity of kConvention.normalisation as a function of the Reynolds number
// of kConvention.reynolds; the conversion to canonical F happens here, once, via conventions.h.
#pragma once

#include <cstddef>

#include "ceres/jet.h"
#include "codegen/expr.h"
#include "draglab/drag_db/conventions.h"
#include "draglab/drag_db/law_form.h"

namespace draglab {

/// Canonical drag-only F(phi, Re) of a law class, for any scalar type.
template <class LawClass, typename T>
T canonical_F(const T& phi, const T& re, const T* extra, const T* params) {
  constexpr NativeConvention c = LawClass::kConvention;
  const T re_native = conventions::native_reynolds(c.reynolds, phi, re);
  const T value = LawClass::template native<T>(phi, re_native, extra, params);
  return conventions::canonical_F_from_native(c, phi, re_native, value);
}

template <class LawClass>
double canonical_F_double(double phi, double re, const double* extra, const double* params) {
  return canonical_F<LawClass, double>(phi, re, extra, params);
}

template <class LawClass>
AutoDiffScalar canonical_F_autodiff(const AutoDiffScalar& phi, const AutoDiffScalar& re,
                                    const AutoDiffScalar* extra, const AutoDiffScalar* params) {
  return canonical_F<LawClass, AutoDiffScalar>(phi, re, extra, params);
}

template <class LawClass>
codegen::Expr canonical_F_symbolic(const codegen::Expr& phi, const codegen::Expr& re,
                                   const codegen::Expr* extra, const codegen::Expr* params) {
  return canonical_F<LawClass, codegen::Expr>(phi, re, extra, params);
}

/// The array path: a plain loop over the inlined formula (the compiler sees the whole body).
template <class LawClass>
void canonical_F_array(std::size_t n, const double* phi, const double* re, const double* extra,
                       const double* params, double* out) {
  constexpr int kExtra = LawClass::kNumExtraInputs;
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = canonical_F<LawClass, double>(phi[i], re[i], kExtra > 0 ? extra + i * kExtra : nullptr,
                                           params);
  }
}

template <class LawClass>
LawForm make_law_form() {
  LawForm form;
  form.description = LawClass::describe();
  form.convention = LawClass::kConvention;
  form.num_parameters = LawClass::kNumParameters;
  form.num_extra_inputs = LawClass::kNumExtraInputs;
  form.F = &canonical_F_double<LawClass>;
  form.F_autodiff = &canonical_F_autodiff<LawClass>;
  form.F_symbolic = &canonical_F_symbolic<LawClass>;
  form.F_array = &canonical_F_array<LawClass>;
  return form;
}

}  // namespace draglab

/// Registers a law class by its key when libdraglab is loaded (LAMMPS-style self-registration;
/// drag_db is a shared library, so no object file is dropped by the linker).
#define DRAGLAB_REGISTER_LAW_FORM(LawClass)                                       \
  namespace {                                                                     \
  const bool kRegistered##LawClass =                                              \
      (::draglab::register_law_form(::draglab::make_law_form<LawClass>()), true); \
  }
