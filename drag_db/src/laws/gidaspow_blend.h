// gidaspow_blend: Ergun and Wen-Yu blended with an arctan switch function (Lathouwers & Bellan
// 2000; also known as "Huilin-Gidaspow").
//
//   psi = atan[150 * 1.75 (eps - 0.8)]/pi + 1/2
//   beta = (1 - psi) beta_Ergun + psi beta_WenYu
//
// Native convention: beta d^2/(mu phi), superficial Re, TFM model A, as MFiX DRAG_GIDASPOW_BLEND
// and MFiX-Exa ComputeDragGidaspow (whose "Gidaspow" is this blended law); Grains3D "Huilin" is the
// same with 0.2 - phi. The blend slope 150 * 1.75 = 262.5 is a fixed constant of the published
// switch function, not tied to the Ergun parameters a, b. Continuous in phi; the only switch left
// is the Schiller-Naumann C_d switch at Re = 1000 inside the Wen-Yu arm. Note psi(eps = 1) =
// 0.99394, not 1: the blend keeps 0.6 % Ergun at eps = 1, so F(phi -> 0, Re -> 0) = 0.99394 rather
// than 1.
#pragma once

#include "laws/gidaspow.h"
#include "laws/law_math.h"

namespace draglab {
namespace laws {

struct GidaspowBlend {
  static constexpr int kNumParameters = 3;
  static constexpr int kNumExtraInputs = 0;
  static constexpr NativeConvention kConvention{
      ForceKind::kDragOnly, Normalisation::kBetaD2OverMuPhi,
      ReynoldsDefinition::kSuperficialDiameter, TfmModel::kModelA};
  static LawFormDescription describe();

  /// Slope of the arctan switch function (150 * 1.75 in MFiX).
  static constexpr double kBlendSlope = 150.0 * 1.75;
  static constexpr double kPi = 3.14159265358979323846;

  /// Weight of the Wen-Yu arm, psi(eps) in (0, 1).
  template <typename T>
  static T wen_yu_weight(const T& eps) {
    return atan((eps - Gidaspow::kSwitchEps) * kBlendSlope) / kPi + 0.5;
  }

  /// p = {a, b, n}; `re` superficial.
  template <typename T>
  static T native(const T& phi, const T& re, const T* /*extra*/, const T* p) {
    const T psi = wen_yu_weight<T>(T(1.0) - phi);
    return (T(1.0) - psi) * Gidaspow::ergun_arm(phi, re, p) +
           psi * WenYu::native<T>(phi, re, nullptr, p + 2);
  }
};

}  // namespace laws
}  // namespace draglab
