// draglab/arrays/packing.h: periodic sphere packings, random and ordered, and their statistics.
//
// A Packing is N non-overlapping spheres in a periodic cuboid box. Lengths are in units of the
// reference diameter d_ref: the sphere diameter for monodisperse packings, the Sauter mean
// diameter <d> = sum d^3 / sum d^2 otherwise (the diameter polydisperse drag laws use). The
// solids fraction phi = sum (pi/6) d_i^3 / V_box is exact by construction (box size chosen from
// the sphere volumes), not approximate.
//
// Random packings (generate_random_packing): radii drawn from the size distribution, box set
// from the target phi, random positions relaxed to zero overlap by FIRE minimisation of a
// harmonic overlap energy, then equilibrated with hard-sphere Monte-Carlo displacement moves so
// that the configuration samples the hard-sphere fluid (the disordered, metastable fluid above
// freezing at phi = 0.494). Crystallised configurations are detected with the bond-orientational
// order (Steinhardt Q6 and the local q6.q6 crystal criterion) and regenerated.
// Limits: random phi <= 0.64 (random close packing; in practice <= 0.62 for monodisperse);
// ordered phi up to close packing of the lattice (SC pi/6, BCC sqrt(3) pi/8, FCC sqrt(2) pi/6).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace draglab {
namespace arrays {

using Vec3 = std::array<double, 3>;

/// Progress report: fraction in [0, 1] of the current stage, and the stage's name.
using ProgressCallback = std::function<void(double fraction, const std::string& stage)>;

/// Size distributions of random packings.
enum class SizeDistribution {
  kMonodisperse,
  kBidisperse,  ///< Two sizes: ratio d_large/d_small and the volume share of the large ones.
  kLognormal,   ///< ln d normally distributed with standard deviation sigma.
};
const char* to_string(SizeDistribution d);
SizeDistribution size_distribution_from_string(const std::string& s);

/// Ordered lattices.
enum class Lattice { kSimpleCubic, kBodyCentredCubic, kFaceCentredCubic };
const char* to_string(Lattice l);
Lattice lattice_from_string(const std::string& s);  ///< "sc", "bcc", "fcc".
/// Close-packing solids fraction of a lattice: pi/6, sqrt(3) pi/8, sqrt(2) pi/6.
double close_packing_phi(Lattice l);

/// Largest phi accepted for random packings (random close packing).
constexpr double kMaxRandomPhi = 0.64;

/// N spheres in a periodic box. Positions in [0, box_length) per axis.
struct Packing {
  Vec3 box_length{1.0, 1.0, 1.0};
  std::vector<Vec3> centers;
  std::vector<double> radii;
  // Provenance (written to the HDF5 file).
  std::string generator;      ///< e.g. "random: FIRE overlap removal + hard-sphere MC".
  std::string settings_json;  ///< The generator's options as JSON text.
  std::uint64_t seed = 0;

  std::size_t size() const { return radii.size(); }
  double box_volume() const { return box_length[0] * box_length[1] * box_length[2]; }
  /// Exact solids fraction sum (4/3) pi r^3 / V_box.
  double phi() const;
  /// Sauter mean diameter sum d^3 / sum d^2.
  double sauter_diameter() const;
  /// Minimum-image separation vector c_j - c_i.
  Vec3 separation(std::size_t i, std::size_t j) const;
};

/// Options of a random packing.
struct RandomPackingOptions {
  double phi = 0.3;  ///< Target solids fraction, (0, 0.64].
  int n = 100;       ///< Number of spheres, >= 1.
  SizeDistribution distribution = SizeDistribution::kMonodisperse;
  double size_ratio = 2.0;             ///< Bidisperse d_large/d_small, (1, 4].
  double large_volume_fraction = 0.5;  ///< Bidisperse volume share of the large spheres, [0, 1].
  double lognormal_sigma = 0.2;        ///< Lognormal sigma of ln d, (0, 0.5].
  std::uint64_t seed = 1;
  double min_gap = 0.0;             ///< Minimum surface gap between spheres, in d_ref, [0, 0.5].
  Vec3 aspect{1.0, 1.0, 1.0};       ///< Box edge ratios (cuboid boxes), each in [0.25, 4].
  int equilibration_sweeps = 1000;  ///< Hard-sphere MC sweeps (N moves each) after relaxation.
  double max_crystalline_fraction = 0.05;  ///< Reject above this fraction of crystal-like spheres.
  int max_attempts = 5;  ///< Regenerations (new sub-seed) after a crystallised result.
  /// True if valid; otherwise *error names the field and its allowed range.
  bool IsValid(std::string* error) const;
};

/// How a bidisperse packing of n spheres splits: the number fraction x of large spheres solves
/// x R^3 / (x R^3 + 1 - x) = s for the asked volume share s, rounded to whole spheres.
struct BidisperseCounts {
  int large = 0, small = 0;
  double large_volume_fraction = 0.0;  ///< What the whole spheres achieve.
};
BidisperseCounts bidisperse_counts(int n, double size_ratio, double large_volume_fraction);

/// The fewest spheres whose split keeps both sizes and the achieved large volume share within
/// kBidisperseShareTolerance of the asked one (0 if none up to 10^7).
int bidisperse_min_spheres(double size_ratio, double large_volume_fraction);
constexpr double kBidisperseShareTolerance = 0.05;

/// What a random generation did. Iterations and sweeps are totals over all attempts; the other
/// fields describe the returned (last) attempt.
struct GenerationSummary {
  int attempts = 0;
  long long relaxation_iterations = 0;
  long long mc_sweeps = 0;
  double mc_acceptance = 0.0;  ///< Acceptance of the fixed-step sweeps (after the adaptation).
  double mc_step = 0.0;        ///< Final MC step size in d_ref.
  double wall_s = 0.0;
  double q6 = 0.0;
  double crystalline_fraction = 0.0;
  std::string BriefReport() const;
  std::string FullReport() const;
};

/// Generates a random packing; throws draglab::Error(kInvalidArgument) for invalid options (also
/// when n is too small for phi: box edge below the largest diameter plus min_gap; or when the
/// spheres padded by min_gap/2 would exceed kMaxRandomPhi) and Error(kInternal) if no
/// non-crystalline, non-overlapping configuration was found (jammed twice, or crystallised in
/// all max_attempts). The same options and seed give the same packing bit for bit, whatever the
/// thread count. Large spheres come first in bidisperse packings. Equilibration: the contact
/// value of g relaxes within ~100 sweeps at phi = 0.35, but on the structural relaxation time
/// above phi ~ 0.5 (a few thousand sweeps at 0.55); the default 1000 sweeps leave denser
/// packings slightly over-contacted compared with the (metastable) equilibrium fluid.
Packing generate_random_packing(const RandomPackingOptions& options,
                                GenerationSummary* summary = nullptr,
                                const ProgressCallback& progress = nullptr);

/// Options of an ordered packing: `cells` unit cells per box edge.
struct OrderedPackingOptions {
  Lattice lattice = Lattice::kSimpleCubic;
  double phi = 0.1;  ///< (0, close_packing_phi(lattice)].
  int cells = 1;     ///< Unit cells per box edge, [1, 64].
  bool IsValid(std::string* error) const;
};

/// Generates an ordered packing (monodisperse, d = 1, exact phi).
Packing generate_ordered_packing(const OrderedPackingOptions& options);

/// Options of compute_statistics.
struct StatisticsOptions {
  double g_r_max = 3.0;            ///< g(x) computed for x = r_ij / (r_i + r_j) in [0, g_r_max].
  double g_r_bin = 0.01;           ///< Bin width in x.
  double contact_fit_width = 0.1;  ///< g(1+) extrapolated from a linear fit over [1, 1 + width].
};

/// Statistics of a packing.
struct PackingStatistics {
  std::size_t n = 0;
  double phi = 0.0;
  /// Smallest surface gap |r_ij| - r_i - r_j over all pairs and periodic images (a sphere's own
  /// images included), in d_ref (< 0: overlap).
  double min_gap = 0.0;
  /// Pairs (and image pairs) with gap < -1e-12 (r_i + r_j): touching spheres of a close-packed
  /// lattice are not counted through round-off.
  std::size_t overlapping_pairs = 0;
  /// Global Steinhardt Q6 over all neighbour bonds. Bonds: x = r_ij/(r_i + r_j) below
  /// x_c = (1 + sqrt 2)/2 (phi_fcc/phi)^(1/3), i.e. halfway between the first and second
  /// neighbour shells of an FCC crystal of the same phi (SC 0.3536 with 6 bonds, BCC 0.5107 with
  /// 8 + 6, FCC 0.5745 with 12; random packings ~ 1/sqrt(bonds)).
  double q6 = 0.0;
  /// Fraction of spheres with >= 7 bonds whose normalised q6(i).q6(j) > 0.7 (ten Wolde, Ruiz-
  /// Montero & Frenkel 1996). 1 for FCC and BCC, 0 for SC (6 bonds only), ~0 for fluids.
  double crystalline_fraction = 0.0;
  double mean_neighbours = 0.0;  ///< Bonds per sphere within the neighbour cutoff.
  /// g(x = 1+), x = r_ij/(r_i + r_j), from the least-squares line over [1, 1 + width] evaluated at
  /// x = 1 (underestimates a convex g by about g k^2 width^2 / 12, k = -g'/g at contact). 0 if
  /// n < 2.
  double g_contact = 0.0;
  std::vector<double> g_r_x;  ///< Bin centres of x.
  /// g(x): pair counts in [x_lo, x_hi) over the ideal-gas count
  /// sum_{i<j} (r_i + r_j)^3 (4 pi/3)(x_hi^3 - x_lo^3) / V. The
  /// usual g(r/d) for monodisperse packings; for polydisperse ones the (r_i + r_j)^3-weighted
  /// mean of the partial g_ab at x (r_a + r_b). Pairs are counted over all periodic images, so g
  /// is meaningful where x (r_i + r_j) is below half the box edge.
  std::vector<double> g_r;
};

/// O(N) with a cell list. Throws Error(kInvalidArgument) for invalid options (g_r_bin in
/// (0, 0.5], contact_fit_width in [2 g_r_bin, 1], g_r_max in [1 + contact_fit_width, 20]) or a
/// malformed packing (no spheres, non-positive radii or box edges, non-finite centres).
PackingStatistics compute_statistics(const Packing& packing,
                                     const StatisticsOptions& options = StatisticsOptions());

/// Carnahan-Starling contact value of the hard-sphere fluid, (1 - phi/2)/(1 - phi)^3; phi in
/// [0, 1) (Error(kInvalidArgument) otherwise), meaningful for the fluid below ~0.55.
double carnahan_starling_contact(double phi);

}  // namespace arrays
}  // namespace draglab
