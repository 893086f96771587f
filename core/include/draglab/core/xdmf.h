// draglab/core/xdmf.h: the pieces of an XDMF 2 index that describes HDF5 datasets for
// ParaView's XDMFReader (LBM fields, DPM gas fields and particles).
//
// XDMF 2 lists every triple slowest axis first (z y x): the topology's point counts, the origin
// and the spacing; a cell attribute's Dimensions are "nz ny nx", the HDF5 shape with x fastest.
// Checked with ParaView 5.11's XDMFReader.
#pragma once

#include <cstdint>
#include <string>

namespace draglab {
namespace core {
namespace xdmf {

/// XML-escapes &, <, > and " (file names and values in the index).
std::string escape(const std::string& s);

/// The shortest of %.15g..%.17g that reads back as `value` (times, spacings).
std::string number(double value);

/// The XML declaration, <Xdmf Version="2.0"> and <Domain>.
std::string begin_document();
/// </Domain></Xdmf>.
std::string end_document();

/// One HDF DataItem on its own line: `dims` the XDMF Dimensions ("nz ny nx", "n 3"),
/// `number_type` Float / Int / UChar, `precision` in bytes, `h5_name` relative to the index
/// (escaped here), `dataset` the path inside the file.
std::string hdf_item(const std::string& dims, const std::string& number_type, int precision,
                     const std::string& h5_name, const std::string& dataset,
                     const std::string& indent);

/// Topology and geometry of a uniform 3-D grid of nx*ny*nz cells with cell sizes dx, dy, dz and
/// its origin at 0 (a 3DCoRectMesh of (nz+1)(ny+1)(nx+1) points).
std::string corect_mesh(std::int64_t nx, std::int64_t ny, std::int64_t nz, double dx, double dy,
                        double dz, const std::string& indent);

/// "nz ny nx": the Dimensions of a cell attribute of that grid.
std::string cell_dims(std::int64_t nx, std::int64_t ny, std::int64_t nz);

}  // namespace xdmf
}  // namespace core
}  // namespace draglab
