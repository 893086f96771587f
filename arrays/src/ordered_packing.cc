// Ordered arrays: simple cubic, body-centred cubic and face-centred cubic lattices of spheres of
// diameter 1 (= d_ref) in a cubic periodic box of `cells` unit cells per edge.
//
// The lattice constant follows exactly from phi: a^3 = n_basis (pi/6) / phi. The basis is shifted
// by (1/4, 1/4, 1/4) a so that no centre sits on the box boundary.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "draglab/arrays/packing.h"
#include "draglab/error.h"

namespace draglab {
namespace arrays {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<Vec3> basis_of(Lattice lattice) {
  switch (lattice) {
    case Lattice::kBodyCentredCubic:
      return {{0.0, 0.0, 0.0}, {0.5, 0.5, 0.5}};
    case Lattice::kFaceCentredCubic:
      return {{0.0, 0.0, 0.0}, {0.5, 0.5, 0.0}, {0.5, 0.0, 0.5}, {0.0, 0.5, 0.5}};
    case Lattice::kSimpleCubic:
    default:
      return {{0.0, 0.0, 0.0}};
  }
}

}  // namespace

Packing generate_ordered_packing(const OrderedPackingOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, error);

  const std::vector<Vec3> basis = basis_of(options.lattice);
  const double phi = std::min(options.phi, close_packing_phi(options.lattice));
  const double a = std::cbrt(static_cast<double>(basis.size()) * (kPi / 6.0) / phi);
  const int m = options.cells;

  Packing packing;
  const double edge = a * m;
  packing.box_length = {edge, edge, edge};
  packing.centers.reserve(basis.size() * m * m * m);
  for (int k = 0; k < m; ++k) {
    for (int j = 0; j < m; ++j) {
      for (int i = 0; i < m; ++i) {
        for (const Vec3& b : basis) {
          packing.centers.push_back(
              {(i + b[0] + 0.25) * a, (j + b[1] + 0.25) * a, (k + b[2] + 0.25) * a});
        }
      }
    }
  }
  packing.radii.assign(packing.centers.size(), 0.5);
  packing.generator = std::string("ordered: ") + to_string(options.lattice) + " lattice";
  nlohmann::json settings;
  settings["kind"] = "ordered";
  settings["lattice"] = to_string(options.lattice);
  settings["phi"] = options.phi;
  settings["cells"] = options.cells;
  settings["lattice_constant"] = a;
  settings["d_ref"] = "sphere diameter";
  packing.settings_json = settings.dump();
  packing.seed = 0;
  return packing;
}

}  // namespace arrays
}  // namespace draglab
