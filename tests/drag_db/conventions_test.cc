// Conversions between the drag normalisations of conventions.h: exact identities and round trips.
#include "draglab/drag_db/conventions.h"

#include <gtest/gtest.h>

namespace draglab {
namespace {

TEST(Conventions, BetaKAndCdAreTheBriefIdentities) {
  const double phi = 0.3, F = 7.0;
  // beta d^2/mu = 18 phi (1-phi) F (brief; drag_laws.md 0.3).
  EXPECT_DOUBLE_EQ(conventions::beta_d2_over_mu(phi, F), 18.0 * 0.3 * 0.7 * 7.0);
  // K = F / (1 - phi) (drag_laws.md 0.2).
  EXPECT_DOUBLE_EQ(conventions::total_force_K(phi, F), 10.0);
  // Cd Re_p = 24 eps F.
  EXPECT_DOUBLE_EQ(conventions::drag_coefficient_times_re_p(phi, F), 24.0 * 0.7 * 7.0);
  // beta with dimensions: 18 mu phi eps F / d^2.
  EXPECT_NEAR(conventions::beta(phi, F, 1.8e-5, 5e-4), 18 * 1.8e-5 * 0.3 * 0.7 * 7.0 / 25e-8,
              1e-9);
}

TEST(Conventions, RoundTripFBetaIsExactToRounding) {
  for (double phi : {0.01, 0.1, 0.35, 0.6}) {
    for (double F : {1.0, 3.3, 250.0}) {
      const double b = conventions::beta_d2_over_mu(phi, F);
      EXPECT_NEAR(conventions::F_from_beta_d2_over_mu(phi, b), F, 4e-16 * F);
    }
  }
}

TEST(Conventions, NativeReynoldsDefinitions) {
  const double phi = 0.4, re = 12.0;
  EXPECT_DOUBLE_EQ(conventions::native_reynolds(ReynoldsDefinition::kSuperficialDiameter, phi, re),
                   12.0);
  EXPECT_DOUBLE_EQ(
      conventions::native_reynolds(ReynoldsDefinition::kInterstitialDiameter, phi, re), 20.0);
  EXPECT_DOUBLE_EQ(conventions::native_reynolds(ReynoldsDefinition::kSuperficialRadius, phi, re),
                   6.0);
}

TEST(Conventions, NativeToCanonical) {
  const double phi = 0.25;
  NativeConvention total{ForceKind::kTotal, Normalisation::kForce,
                         ReynoldsDefinition::kSuperficialRadius, TfmModel::kNotApplicable};
  // F_d = (1 - phi) F_tot (drag_laws.md 0.1).
  EXPECT_DOUBLE_EQ(conventions::canonical_F_from_native(total, phi, 3.0, 8.0), 6.0);
  // beta d^2/(mu phi) = 18 eps F.
  NativeConvention beta{ForceKind::kDragOnly, Normalisation::kBetaD2OverMuPhi,
                        ReynoldsDefinition::kInterstitialDiameter, TfmModel::kModelA};
  EXPECT_DOUBLE_EQ(conventions::canonical_F_from_native(beta, phi, 3.0, 18.0 * 0.75 * 2.0), 2.0);
  // Single sphere: Cd Re_p / (24 eps); at phi = 0 this is Cd Re / 24 = 1 in Stokes flow.
  NativeConvention cd{ForceKind::kDragOnly, Normalisation::kDragCoefficient,
                      ReynoldsDefinition::kInterstitialDiameter, TfmModel::kNotApplicable};
  EXPECT_DOUBLE_EQ(conventions::canonical_F_from_native(cd, 0.0, 0.5, 24.0 / 0.5), 1.0);
}

}  // namespace
}  // namespace draglab
