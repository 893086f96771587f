// draglab/lbm/fields_io.h: the final flow field of a run in HDF5, with an XDMF file for ParaView.
//
// HDF5 layout (group /fields, C order, z slowest and x fastest, one entry per lattice node =
// one cell of the XDMF grid):
//   velocity [nz, ny, nx, 3] float32   lattice units (dx/dt), zero in solids
//   density  [nz, ny, nx]    float32   lattice units (rho0 = 1), 0 in solids where the run
//                                      leaves it so
//   solid    [nz, ny, nx]    uint8     1 = solid node
//   attributes: dims (nx, ny, nz), dx (node spacing in d_ref), length_unit, velocity_unit,
//               draglab_version, and `run` (JSON text of the run's settings and results, when
//               given).
// XDMF 2 file (same name, extension .xmf; the HDF5 file is referenced by its base name, so the
// two files move together): a 3DCoRectMesh whose Topology Dimensions are POINT counts
// "nz+1 ny+1 nx+1", Origin 0 0 0 and spacing dx in z y x order, with cell-centred attributes;
// node (i, j, k) at ((i + 1/2) dx, ...) is the centre of cell (i, j, k).
// Opening in ParaView: use the "XDMF Reader" (legacy Xdmf2; Python: XDMFReader(FileNames=[...]))
// or give an absolute or ./-prefixed path: ParaView 5.11's default Xdmf3ReaderS mis-resolves the
// HDF5 path of a .xmf opened by a bare relative name.
#pragma once

#include <string>

#include "draglab/lbm/lbm.h"

namespace draglab {
namespace lbm {

struct FieldsWriteOptions {
  double dx = 1.0;       ///< Node spacing in d_ref (1/resolution), > 0; XDMF geometry spacing.
  std::string run_json;  ///< Optional JSON text stored as the `run` attribute.
};

/// The XDMF file written next to `h5_path`: its extension (.h5, .hdf5, .hdf) replaced by .xmf,
/// or .xmf appended.
std::string xdmf_path_for(const std::string& h5_path);

/// Writes the HDF5 file and its XDMF file atomically (temporary files renamed into place: on any
/// error neither file is left behind). Throws Error(kInvalidArgument) for inconsistent fields
/// (array sizes not matching dims), a non-positive dx or an unwritable path (the message names
/// it). Size: 17 bytes per node.
void write_fields(const std::string& h5_path, const Fields& fields,
                  const FieldsWriteOptions& options = FieldsWriteOptions());

/// Reads a file written by write_fields; *dx (optional) receives the spacing. Throws
/// Error(kInvalidArgument) naming the path and the missing or malformed item.
Fields read_fields(const std::string& h5_path, double* dx = nullptr);

}  // namespace lbm
}  // namespace draglab
