// d3q19.h: the D3Q19 velocity set of the engine (the ordering of arrays/voxelization.h: 0 rest,
// then opposite pairs (1,2), (3,4), ..., (17,18)), weights and the lattice sound speed.
#pragma once

#include <array>

#include "draglab/arrays/voxelization.h"

namespace draglab {
namespace lbm {
namespace d3q19 {

constexpr int kQ = arrays::kD3Q19;
inline constexpr std::array<std::array<int, 3>, kQ> kC = arrays::kD3Q19Velocities;
inline constexpr std::array<int, kQ> kOpposite = arrays::kD3Q19Opposite;

constexpr double kW0 = 1.0 / 3.0;      ///< Rest weight.
constexpr double kWAxis = 1.0 / 18.0;  ///< Weight of the 6 axis directions (|c| = 1).
constexpr double kWDiag = 1.0 / 36.0;  ///< Weight of the 12 face diagonals (|c| = sqrt 2).

constexpr double weight(int i) { return i == 0 ? kW0 : (i <= 6 ? kWAxis : kWDiag); }

/// c_s^2 = 1/3: nu = (tau - 1/2)/3 in lattice units.
constexpr double kCs2 = 1.0 / 3.0;

}  // namespace d3q19
}  // namespace lbm
}  // namespace draglab
