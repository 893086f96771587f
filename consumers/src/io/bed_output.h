// io/bed_output.h: the cell fields of any bed model (the DPM's gas, the
// two-fluid model's two phases) and the DPM's particles to HDF5 with an XDMF index that ParaView
// opens (only when a scene's [outputs] asks for them).
//
// One HDF5 file per run (<directory>/<scene>_<law>.h5, law "name@v" written "name_v") holds one
// group per output time, "/t000000", "/t000001", ... (attribute time_s):
//  - fields (outputs.fields): cell-centred arrays; the DPM writes eps, p [Pa], u_x, u_z [m/s]
//    (interstitial face velocities averaged to the centres), beta [kg m^-3 s^-1], the TFM (via
//    WriteFields) eps, phi, p, u_x, u_z, v_x, v_z, theta [m^2/s^2], beta, on the grid, one cell
//    across the depth, written as float64 datasets of shape (1, nz, nx) (C order: depth slowest, x
//    fastest, the XDMF 3DCoRectMesh convention checked with ParaView 5.11's XDMFReader);
//    attribute cell_size_m = (dx, dz, depth);
//  - particles (outputs.particles): position (N, 3) [m], velocity (N, 3) [m/s] in the DEM axes
//    (x width, y height, z depth), diameter (N) [m], id (N, int64), layer (N, int32, the
//    initial layer, BedSnapshot::layers).
// The root carries the attributes scene, scene_hash, law, draglab_version and layout.
// The XDMF file (<same stem>.xmf, XDMF 2) has two temporal collections, "gas" and "particles"
// (only those asked for), with one uniform grid per output time: the gas as a 3DCoRectMesh with
// ORIGIN_DXDYDZ (every triple in z y x order; x width, y height, z depth mapped to the VTK x, y,
// z axes, so the bed stands upright), the particles as a Polyvertex with XYZ geometry. Open it
// in ParaView with the "XDMF Reader" (docs/dpm.md, "Output files").
// Units SI. Nothing is written unless Write() is called; Finish() writes the XDMF.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "draglab/consumers/dem.h"
#include "draglab/consumers/gas_phase.h"
#include "draglab/consumers/scene.h"

namespace draglab {
namespace consumers {

/// Named cell-centred arrays (each nx x nz, Eigen index (i, j)) of one output time on a MAC
/// grid of cells dx x dz and the bed's depth.
struct CellFields {
  int nx = 0, nz = 0;
  double dx = 0.0, dz = 0.0, depth = 0.0;
  std::vector<std::pair<std::string, Eigen::ArrayXXd>> arrays;
};

/// The DPM gas's cell fields: eps, p, u_x, u_z (face velocities averaged to the centres), beta.
CellFields gas_cell_fields(const GasPhase& gas);

/// Writes the output times of one run. Throws Error(kInvalidArgument) naming the path when a
/// file cannot be created or written. The HDF5 file is opened for each Write() and closed after
/// it, so a run that stops early leaves a complete file with every finished output time; a
/// Write() that fails leaves no group behind. With neither fields nor particles asked for, the
/// writer creates nothing and Write() does nothing. Not thread-safe (HDF5 is serial here).
class BedOutputWriter {
 public:
  /// `directory` is created if missing (empty: the scene's outputs.directory, else
  /// out/<scene name>, as DpmOptions::output_directory). `law` is "name@version". Throws when
  /// the directory cannot be created, is not a directory or is not writable.
  BedOutputWriter(const Scene& scene, const std::string& law, const std::string& directory,
                  bool fields, bool particles);
  ~BedOutputWriter();
  BedOutputWriter(const BedOutputWriter&) = delete;
  BedOutputWriter& operator=(const BedOutputWriter&) = delete;

  /// Appends one output time (t_s: time since the background flow started, finite and after
  /// the previous output time). `layer_by_id` maps Particles::id to the initial layer; every
  /// particle's id must index it (with particles asked for).
  void Write(double t_s, const GasPhase& gas, const Particles& particles,
             const std::vector<int>& layer_by_id);
  /// Appends one output time of cell fields only (a continuum model: no particles asked for).
  /// Throws Error(kInvalidArgument) for unnamed or misshapen arrays, or a writer made for
  /// particles.
  void WriteFields(double t_s, const CellFields& cells);
  /// Writes (rewrites) the XDMF index of the output times so far (the HDF5 file is closed after
  /// every Write already); called by the destructor too, which swallows errors: call it
  /// yourself to see them. Write() may go on afterwards; call Finish() again then.
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
