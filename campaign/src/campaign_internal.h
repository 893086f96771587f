// Private helpers of the campaign module, exposed to its tests: resolution extrapolation,
// deterministic seeds, content hashes and the unit cost model.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "draglab/arrays/packing.h"
#include "draglab/campaign/campaign.h"

namespace draglab {
namespace campaign {
namespace internal {

/// Result of a resolution extrapolation F(d) -> F(d = infinity).
struct Extrapolation {
  double F_inf = 0.0;
  double order = 0.0;                 ///< Convergence order p used (0: none).
  double discretisation_error = 0.0;  ///< |F_inf - F(finest)|, absolute.
  std::string method;                 ///< "richardson", "inverse_d" or "finest" (what was done).
  std::string note;                   ///< Why a fallback was taken ("" if none).
};

/// Richardson extrapolation from the three finest resolutions with the measured order: solves
/// (F1 - F2)/(F2 - F3) = (d1^-p - d2^-p)/(d2^-p - d3^-p) for p (bisection, p in [0.25, 6];
/// d1 < d2 < d3 need not be in constant ratio), then F_inf = F3 - (F2 - F3) d3^-p /
/// (d2^-p - d3^-p). Falls back to inverse_d (with a note) for fewer than 3 resolutions, for
/// non-monotone data, or for an order outside [0.5, 4] (noise, not asymptotic convergence).
/// `d` and `F` are in the same order; d need not be sorted.
Extrapolation extrapolate_richardson(const std::vector<double>& d, const std::vector<double>& F);

/// The seed's extrapolation: least-squares fit of F(d) = F_inf + a/d over all resolutions (>= 2;
/// with 1 it returns "finest" with zero discretisation error and a note).
Extrapolation extrapolate_inverse_d(const std::vector<double>& d, const std::vector<double>& F);

/// Deterministic packing seed of (spec seed, phi index, realization): splitmix64 mixing, masked to
/// 63 bits so that it fits SQLite's signed INTEGER. Independent of Re and resolution, so every
/// Re and resolution of a realization sees the same geometry.
std::uint64_t packing_seed(std::uint64_t spec_seed, int phi_index, int realization);

/// SHA-256 of the packing's box, centres and diameters written as %.17g.
std::string packing_hash(const arrays::Packing& packing);

/// Random-packing options of a unit (phi, spheres from spheres or box_size, distribution, gap).
arrays::RandomPackingOptions packing_options(const CampaignSpec& spec, double phi,
                                             std::uint64_t seed);

/// Largest solids fraction of the spheres padded by min_gap/2 accepted in a spec: the packing
/// generator's "safe" limit for monodisperse spheres (arrays: they jam near 0.64). Close to it
/// a small box can still jam (measured: phi = 0.4 with gap 0.15, padded 0.608, 16 spheres jammed
/// in both attempts); such units fail with the generator's diagnosis. Keep padded <= ~0.58.
constexpr double kMaxPaddedPhi = 0.62;

/// The minimum surface gap (in d) the packings of `spec` use: spec.min_gap. The default 0 packs
/// the equilibrium hard-sphere structure (as the seed's LB studies did), with near contacts that
/// the engine runs as sub-node gaps; a forced gap changes the structure and raises F (docs).
double effective_min_gap(const CampaignSpec& spec);

/// The spec stored as CampaignSpec::to_json() text.
CampaignSpec spec_from_json(const std::string& text);

/// Cost of a unit in fluid-node updates: fluid nodes x lbm::predicted_steps. Orders the work,
/// drives the ETA, and (times the measured seconds per update) the plan's predicted time.
double unit_cost_estimate(const CampaignSpec& spec, double phi, double re, double resolution);

}  // namespace internal
}  // namespace campaign
}  // namespace draglab
