// Flow fields in HDF5 (HDF5 C API, Debian's libhdf5 1.10) plus an XDMF 2 description.
#include "draglab/lbm/fields_io.h"

#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "drag_db_version.h"
#include "draglab/core/files.h"
#include "draglab/core/hdf5_file.h"
#include "draglab/core/xdmf.h"
#include "draglab/error.h"

namespace draglab {
namespace lbm {
namespace {

using Handle = core::Hdf5Handle;
using core::silence_hdf5;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw Error(ErrorCode::kInvalidArgument, "fields file '" + path + "': " + what);
}

void write_dataset(hid_t group, const char* name, const std::vector<hsize_t>& dims, hid_t file_type,
                   hid_t mem_type, const void* data, const std::string& path) {
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
  Handle set(H5Dcreate2(group, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
             H5Dclose);
  if (!space.ok() || !set.ok() ||
      H5Dwrite(set.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    fail(path, std::string("cannot write dataset /fields/") + name);
  }
}

void write_attribute(hid_t object, const char* name, hid_t file_type, hid_t mem_type,
                     const std::vector<hsize_t>& dims, const void* value, const std::string& path) {
  Handle space(dims.empty() ? H5Screate(H5S_SCALAR)
                            : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
               H5Sclose);
  Handle attr(H5Acreate2(object, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attr.ok() || H5Awrite(attr.get(), mem_type, value) < 0) {
    fail(path, std::string("cannot write attribute ") + name);
  }
}

void write_string(hid_t o, const char* name, const std::string& value, const std::string& path) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), H5T_VARIABLE);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  const char* c = value.c_str();
  write_attribute(o, name, type.get(), type.get(), {}, &c, path);
}

/// Base name of a path (the XDMF file refers to the HDF5 file relative to itself).
std::string base_name(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string xdmf_text(const std::string& h5_name, const Fields& f, double dx) {
  namespace xdmf = core::xdmf;
  const std::int64_t nx = f.dims[0], ny = f.dims[1], nz = f.dims[2];
  const std::string cells = xdmf::cell_dims(nx, ny, nz);
  const std::string in = "    ";
  return xdmf::begin_document() + "  <Grid Name=\"lbm\" GridType=\"Uniform\">\n" +
         xdmf::corect_mesh(nx, ny, nz, dx, dx, dx, "   ") +
         "   <Attribute Name=\"velocity\" AttributeType=\"Vector\" Center=\"Cell\">\n" +
         xdmf::hdf_item(cells + " 3", "Float", 4, h5_name, "/fields/velocity", in) +
         "   </Attribute>\n"
         "   <Attribute Name=\"density\" AttributeType=\"Scalar\" Center=\"Cell\">\n" +
         xdmf::hdf_item(cells, "Float", 4, h5_name, "/fields/density", in) +
         "   </Attribute>\n"
         "   <Attribute Name=\"solid\" AttributeType=\"Scalar\" Center=\"Cell\">\n" +
         xdmf::hdf_item(cells, "UChar", 1, h5_name, "/fields/solid", in) +
         "   </Attribute>\n"
         "  </Grid>\n" +
         xdmf::end_document();
}

void check_fields(const Fields& f, const std::string& path) {
  for (int a = 0; a < 3; ++a) {
    if (f.dims[a] < 1) fail(path, "dims must be >= 1 along every axis");
  }
  const std::size_t n = static_cast<std::size_t>(f.dims[0] * f.dims[1] * f.dims[2]);
  if (f.velocity.size() != 3 * n) {
    fail(path, "velocity has " + std::to_string(f.velocity.size()) + " values, expected 3 x " +
                   std::to_string(n));
  }
  if (f.density.size() != n) fail(path, "density has the wrong size");
  if (f.solid.size() != n) fail(path, "solid has the wrong size");
}

std::vector<hsize_t> read_shape(hid_t group, const char* name, const std::string& path) {
  if (H5Lexists(group, name, H5P_DEFAULT) <= 0)
    fail(path, std::string("no dataset /fields/") + name);
  Handle set(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose);
  Handle space(H5Dget_space(set.get()), H5Sclose);
  if (!set.ok() || !space.ok()) fail(path, std::string("cannot open dataset ") + name);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 1 || rank > 4) fail(path, std::string("dataset ") + name + " has a bad rank");
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

void read_values(hid_t group, const char* name, hid_t mem_type, void* out,
                 const std::string& path) {
  Handle set(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose);
  if (!set.ok() || H5Dread(set.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) < 0) {
    fail(path, std::string("cannot read dataset ") + name);
  }
}

}  // namespace

std::string xdmf_path_for(const std::string& h5_path) {
  for (const char* ext : {".h5", ".hdf5", ".hdf"}) {
    const std::string e(ext);
    if (h5_path.size() > e.size() && h5_path.compare(h5_path.size() - e.size(), e.size(), e) == 0 &&
        h5_path[h5_path.size() - e.size() - 1] != '/') {
      return h5_path.substr(0, h5_path.size() - e.size()) + ".xmf";
    }
  }
  return h5_path + ".xmf";
}

void write_fields(const std::string& h5_path, const Fields& fields,
                  const FieldsWriteOptions& options) {
  silence_hdf5();
  const std::string& path = h5_path;
  if (path.empty()) fail(path, "empty output path");
  if (!(options.dx > 0.0) || !std::isfinite(options.dx)) fail(path, "dx must be finite and > 0");
  check_fields(fields, path);
  const std::string xmf = xdmf_path_for(path);
  // Built in memory and saved whole: a failed write (disk full) leaves no file and no half-closed
  // HDF5 handle behind (core/hdf5_file.h).
  core::Hdf5MemoryFile file("fields file");
  {
    Handle group(H5Gcreate2(file.id(), "fields", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    if (!group.ok()) fail(path, "cannot create group /fields");
    const hsize_t nx = static_cast<hsize_t>(fields.dims[0]);
    const hsize_t ny = static_cast<hsize_t>(fields.dims[1]);
    const hsize_t nz = static_cast<hsize_t>(fields.dims[2]);
    write_dataset(group.get(), "velocity", {nz, ny, nx, 3}, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT,
                  fields.velocity.data(), path);
    write_dataset(group.get(), "density", {nz, ny, nx}, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT,
                  fields.density.data(), path);
    write_dataset(group.get(), "solid", {nz, ny, nx}, H5T_STD_U8LE, H5T_NATIVE_UINT8,
                  fields.solid.data(), path);
    const long long dims[3] = {fields.dims[0], fields.dims[1], fields.dims[2]};
    write_attribute(group.get(), "dims", H5T_STD_I64LE, H5T_NATIVE_LLONG, {3}, dims, path);
    write_attribute(group.get(), "dx", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {}, &options.dx, path);
    write_string(group.get(), "layout",
                 "C order [nz, ny, nx(, 3)]: x fastest; node (i, j, k) at ((i + 1/2) dx, "
                 "(j + 1/2) dx, (k + 1/2) dx)",
                 path);
    write_string(group.get(), "length_unit", "reference diameter d_ref (dx = d_ref/resolution)",
                 path);
    write_string(group.get(), "velocity_unit", "lattice units (dx/dt)", path);
    write_string(group.get(), "draglab_version", kDragDbVersion, path);
    if (!options.run_json.empty()) write_string(group.get(), "run", options.run_json, path);
  }
  file.save(path);
  // The XDMF file describes the HDF5 file: without it the pair is incomplete, so a failure
  // removes the HDF5 file too.
  try {
    core::write_file_atomically(xmf, xdmf_text(base_name(path), fields, options.dx), "XDMF file");
  } catch (...) {
    std::remove(path.c_str());
    throw;
  }
}

Fields read_fields(const std::string& h5_path, double* dx) {
  silence_hdf5();
  const std::string& path = h5_path;
  if (access(path.c_str(), R_OK) != 0) fail(path, "does not exist or is not readable");
  if (H5Fis_hdf5(path.c_str()) <= 0) fail(path, "is not an HDF5 file");
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.ok()) fail(path, "cannot open");
  if (H5Lexists(file.get(), "fields", H5P_DEFAULT) <= 0) fail(path, "no group /fields");
  Handle group(H5Gopen2(file.get(), "fields", H5P_DEFAULT), H5Gclose);
  if (!group.ok()) fail(path, "cannot open group /fields");
  const std::vector<hsize_t> v = read_shape(group.get(), "velocity", path);
  if (v.size() != 4 || v[3] != 3) fail(path, "velocity must have shape [nz, ny, nx, 3]");
  Fields f;
  f.dims = {static_cast<std::int64_t>(v[2]), static_cast<std::int64_t>(v[1]),
            static_cast<std::int64_t>(v[0])};
  const std::vector<hsize_t> cells{v[0], v[1], v[2]};
  if (read_shape(group.get(), "density", path) != cells) {
    fail(path, "density must have shape [nz, ny, nx] like velocity");
  }
  if (read_shape(group.get(), "solid", path) != cells) {
    fail(path, "solid must have shape [nz, ny, nx] like velocity");
  }
  const std::size_t n = static_cast<std::size_t>(v[0] * v[1] * v[2]);
  f.velocity.resize(3 * n);
  f.density.resize(n);
  f.solid.resize(n);
  read_values(group.get(), "velocity", H5T_NATIVE_FLOAT, f.velocity.data(), path);
  read_values(group.get(), "density", H5T_NATIVE_FLOAT, f.density.data(), path);
  read_values(group.get(), "solid", H5T_NATIVE_UINT8, f.solid.data(), path);
  if (dx) {
    *dx = std::nan("");
    if (H5Aexists(group.get(), "dx") > 0) {
      Handle attr(H5Aopen(group.get(), "dx", H5P_DEFAULT), H5Aclose);
      if (!attr.ok() || H5Aread(attr.get(), H5T_NATIVE_DOUBLE, dx) < 0) {
        fail(path, "cannot read attribute dx");
      }
    }
  }
  return f;
}

}  // namespace lbm
}  // namespace draglab
