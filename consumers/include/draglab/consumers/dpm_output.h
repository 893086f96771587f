// draglab/consumers/dpm_output.h: gas fields and particles of a DPM run to HDF5 with an XDMF
// index that ParaView opens (only when a scene's [outputs] asks for them).
//
// One HDF5 file per run (<directory>/<scene>_<law>.h5, law "name@v" written "name_v") holds one
// group per output time, "/t000000", "/t000001", ...:
//  - fields (outputs.fields): cell-centred eps, p [Pa], u_x, u_z [m/s] (face velocities averaged
//    to the centres), beta [kg m^-3 s^-1] on the gas grid, one cell across the depth, written as
//    datasets of shape (1, nz, nx) (C order: depth slowest, x fastest, the XDMF 3DCoRectMesh
//    convention, docs/dem_peer-style checked with ParaView's XDMFReader);
//  - particles (outputs.particles): position (N, 3) [m], velocity (N, 3) [m/s], diameter (N),
//    id (N), layer (N, the initial layer, dpm.h kInitialLayers).
// The XDMF file (<same stem>.xmf, XDMF 2, a temporal collection) has per output time one
// uniform grid "gas" (3DCoRectMesh, ORIGIN_DXDYDZ, z y x order; x width, y height, z depth
// mapped to the VTK x, y, z axes) and one "particles" grid (Polyvertex, XYZ geometry).
// Units SI. Nothing is written unless Write() is called; Finish() writes the XDMF.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "draglab/consumers/dem.h"
#include "draglab/consumers/gas_phase.h"
#include "draglab/consumers/scene.h"

namespace draglab {
namespace consumers {

/// Writes the output times of one run. Throws Error(kInvalidArgument) naming the path when a
/// file cannot be created or written.
class DpmOutputWriter {
 public:
  /// `directory` is created if missing. `law` is "name@version".
  DpmOutputWriter(const Scene& scene, const std::string& law, const std::string& directory,
                  bool fields, bool particles);
  ~DpmOutputWriter();
  DpmOutputWriter(const DpmOutputWriter&) = delete;
  DpmOutputWriter& operator=(const DpmOutputWriter&) = delete;

  /// Appends one output time (t_s: time since the background flow started). `layer_by_id`
  /// maps Particles::id to the initial layer.
  void Write(double t_s, const GasPhase& gas, const Particles& particles,
             const std::vector<int>& layer_by_id);
  /// Writes (rewrites) the XDMF index and closes the HDF5 file; called by the destructor too.
  void Finish();
  /// The files written so far (the .h5 and, after Finish, the .xmf).
  std::vector<std::string> files() const;
  int outputs() const;  ///< Output times written.

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace consumers
}  // namespace draglab
