// Packings in HDF5 through the HDF5 C API (Debian's libhdf5 1.10).
#include "draglab/arrays/packing_io.h"

#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "drag_db_version.h"
#include "draglab/core/hdf5_file.h"
#include "draglab/core/isolated.h"
#include "draglab/error.h"

namespace draglab {
namespace arrays {
namespace {

using Handle = core::Hdf5Handle;
using core::silence_hdf5;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw Error(ErrorCode::kInvalidArgument, "packing file '" + path + "': " + what);
}

// Limits on what a file may declare, checked before anything is allocated for it: a damaged or
// hostile file can declare any shape (an unallocated chunked dataset of 2^40 rows costs a few
// bytes on disk). Packings have at most 10^7 spheres (RandomPackingOptions::n).
constexpr hsize_t kMaxSpheres = 10000000;
constexpr hsize_t kMaxValues = 3 * kMaxSpheres;   // centers [N, 3]
constexpr std::size_t kMaxStringBytes = 1 << 20;  // generator, settings (JSON text)

void write_dataset(hid_t group, const char* name, const std::vector<hsize_t>& dims,
                   const double* data, const std::string& path) {
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
  Handle set(
      H5Dcreate2(group, name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
      H5Dclose);
  if (!space.ok() || !set.ok() ||
      H5Dwrite(set.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    fail(path, std::string("cannot write dataset ") + name);
  }
}

void write_attribute(hid_t object, const char* name, hid_t file_type, hid_t mem_type,
                     const void* value, const std::string& path) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(object, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attr.ok() || H5Awrite(attr.get(), mem_type, value) < 0) {
    fail(path, std::string("cannot write attribute ") + name);
  }
}

void write_double(hid_t o, const char* name, double v, const std::string& path) {
  write_attribute(o, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &v, path);
}

void write_string(hid_t o, const char* name, const std::string& value, const std::string& path) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), H5T_VARIABLE);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  const char* c = value.c_str();
  write_attribute(o, name, type.get(), type.get(), &c, path);
}

std::vector<double> read_dataset(hid_t group, const char* name, std::vector<hsize_t>* dims,
                                 const std::string& path) {
  if (H5Lexists(group, name, H5P_DEFAULT) <= 0)
    fail(path, std::string("no dataset /packing/") + name);
  Handle set(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose);
  Handle space(H5Dget_space(set.get()), H5Sclose);
  if (!set.ok() || !space.ok()) fail(path, std::string("cannot open dataset ") + name);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 1 || rank > 2)
    fail(path, std::string("dataset ") + name + " has rank " + std::to_string(rank));
  dims->assign(static_cast<std::size_t>(rank), 0);
  if (H5Sget_simple_extent_dims(space.get(), dims->data(), nullptr) != rank) {
    fail(path, std::string("cannot read the shape of dataset ") + name);
  }
  hsize_t count = 1;
  for (hsize_t d : *dims) {
    // Each factor is checked before the product, so the product cannot overflow (rank <= 2).
    if (d > kMaxValues || count * d > kMaxValues) {
      std::string shape;
      for (hsize_t e : *dims) shape += (shape.empty() ? "" : ", ") + std::to_string(e);
      fail(path, std::string("dataset ") + name + " has shape [" + shape + "]: more than " +
                     std::to_string(kMaxValues) + " values (a packing has at most " +
                     std::to_string(kMaxSpheres) + " spheres)");
    }
    count *= d;
  }
  std::vector<double> data(count);
  if (count > 0 &&
      H5Dread(set.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0) {
    fail(path, std::string("cannot read dataset ") + name + " as double");
  }
  return data;
}

hssize_t attribute_elements(hid_t attr) {
  Handle space(H5Aget_space(attr), H5Sclose);
  if (!space.ok()) return -1;
  return H5Sget_simple_extent_npoints(space.get());
}

/// H5Aread writes every element of the attribute: one value is read into one value only.
void require_single_value(hid_t attr, const char* name, const std::string& path) {
  const hssize_t n = attribute_elements(attr);
  if (n != 1) {
    fail(path, std::string("attribute /packing/") + name + " must hold one value, not " +
                   (n < 0 ? std::string("an unreadable dataspace") : std::to_string(n)));
  }
}

bool read_string(hid_t o, const char* name, std::string* out, const std::string& path) {
  if (H5Aexists(o, name) <= 0) return false;
  Handle attr(H5Aopen(o, name, H5P_DEFAULT), H5Aclose);
  Handle type(H5Aget_type(attr.get()), H5Tclose);
  if (!attr.ok() || !type.ok() || H5Tget_class(type.get()) != H5T_STRING) return false;
  require_single_value(attr.get(), name, path);
  if (H5Tis_variable_str(type.get()) > 0) {
    char* value = nullptr;
    Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mem.get(), H5T_VARIABLE);
    H5Tset_cset(mem.get(), H5Tget_cset(type.get()));
    if (H5Aread(attr.get(), mem.get(), &value) < 0) return false;
    *out = value ? value : "";
    Handle space(H5Aget_space(attr.get()), H5Sclose);
    H5Dvlen_reclaim(mem.get(), space.get(), H5P_DEFAULT, &value);
    return true;
  }
  const std::size_t size = H5Tget_size(type.get());
  if (size == 0 || size > kMaxStringBytes) {
    fail(path, std::string("attribute /packing/") + name + " is a string of " +
                   std::to_string(size) + " bytes (at most " + std::to_string(kMaxStringBytes) +
                   ")");
  }
  std::string value(size, '\0');
  if (H5Aread(attr.get(), type.get(), value.data()) < 0) return false;
  value.resize(value.find('\0') == std::string::npos ? size : value.find('\0'));
  *out = value;
  return true;
}

bool read_number(hid_t o, const char* name, hid_t mem_type, void* out, const std::string& path) {
  if (H5Aexists(o, name) <= 0) return false;
  Handle attr(H5Aopen(o, name, H5P_DEFAULT), H5Aclose);
  if (!attr.ok()) return false;
  require_single_value(attr.get(), name, path);
  return H5Aread(attr.get(), mem_type, out) >= 0;
}

}  // namespace

void write_packing_hdf5(const std::string& path, const Packing& packing,
                        const PackingStatistics* statistics) {
  silence_hdf5();
  if (path.empty()) fail(path, "empty output path");
  // Built in memory and saved whole: a failed write (disk full) leaves no file and no half-closed
  // HDF5 handle behind (core/hdf5_file.h).
  core::Hdf5MemoryFile file("packing file");
  {
    Handle group(H5Gcreate2(file.id(), "packing", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    if (!group.ok()) fail(path, "cannot create group /packing");
    const hsize_t n = packing.size();
    write_dataset(group.get(), "centers", {n, 3}, n ? packing.centers.front().data() : nullptr,
                  path);
    write_dataset(group.get(), "radii", {n}, packing.radii.data(), path);
    write_dataset(group.get(), "box_length", {3}, packing.box_length.data(), path);
    const long long count = static_cast<long long>(n);
    const unsigned long long seed = packing.seed;
    write_double(group.get(), "phi", packing.phi(), path);
    write_attribute(group.get(), "n", H5T_STD_I64LE, H5T_NATIVE_LLONG, &count, path);
    write_attribute(group.get(), "seed", H5T_STD_U64LE, H5T_NATIVE_ULLONG, &seed, path);
    write_string(group.get(), "generator", packing.generator, path);
    write_string(group.get(), "settings", packing.settings_json, path);
    write_string(group.get(), "length_unit",
                 "reference diameter d_ref (Sauter mean diameter; the diameter if monodisperse)",
                 path);
    write_string(group.get(), "draglab_version", kDragDbVersion, path);
    if (statistics) {
      write_double(group.get(), "min_gap", statistics->min_gap, path);
      write_double(group.get(), "q6", statistics->q6, path);
      write_double(group.get(), "g_contact", statistics->g_contact, path);
      write_double(group.get(), "crystalline_fraction", statistics->crystalline_fraction, path);
      write_double(group.get(), "mean_neighbours", statistics->mean_neighbours, path);
    }
  }
  file.save(path);
}

Packing read_packing_hdf5_in_process(const std::string& path) {
  silence_hdf5();
  if (access(path.c_str(), R_OK) != 0) fail(path, "does not exist or is not readable");
  if (H5Fis_hdf5(path.c_str()) <= 0) fail(path, "is not an HDF5 file");
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.ok()) fail(path, "cannot open");
  if (H5Lexists(file.get(), "packing", H5P_DEFAULT) <= 0) fail(path, "no group /packing");
  Handle group(H5Gopen2(file.get(), "packing", H5P_DEFAULT), H5Gclose);
  if (!group.ok()) fail(path, "cannot open group /packing");

  Packing p;
  std::vector<hsize_t> dims;
  const std::vector<double> centers = read_dataset(group.get(), "centers", &dims, path);
  if (dims.size() != 2 || dims[1] != 3) fail(path, "centers must have shape [N, 3]");
  const std::size_t n = dims[0];
  const std::vector<double> radii = read_dataset(group.get(), "radii", &dims, path);
  if (dims.size() != 1 || dims[0] != n)
    fail(path, "radii must have shape [N] with N = rows of centers");
  const std::vector<double> box = read_dataset(group.get(), "box_length", &dims, path);
  if (dims.size() != 1 || dims[0] != 3) fail(path, "box_length must have shape [3]");
  if (n == 0) fail(path, "contains no spheres");
  for (int a = 0; a < 3; ++a) {
    if (!(box[a] > 0.0 && std::isfinite(box[a])))
      fail(path, "box_length must be positive and finite");
    p.box_length[a] = box[a];
  }
  const double min_edge = std::min({box[0], box[1], box[2]});
  p.centers.resize(n);
  p.radii = radii;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(radii[i] > 0.0)) fail(path, "radius " + std::to_string(i) + " is not positive");
    // A sphere wider than the box overlaps its own periodic image: not a packing (a damaged file
    // can hold such values where libhdf5 read garbage without failing).
    if (!(2.0 * radii[i] <= min_edge)) {
      fail(path, "radius " + std::to_string(i) + " exceeds half the smallest box edge");
    }
    for (int a = 0; a < 3; ++a) {
      const double x = centers[3 * i + a];
      if (!(x >= 0.0 && x < box[a])) {
        fail(path, "center " + std::to_string(i) + " lies outside [0, box_length)");
      }
      p.centers[i][a] = x;
    }
  }
  if (!(p.phi() <= 1.0)) fail(path, "the spheres' volume exceeds the box volume (phi > 1)");
  read_string(group.get(), "generator", &p.generator, path);
  read_string(group.get(), "settings", &p.settings_json, path);
  unsigned long long seed = 0;
  if (read_number(group.get(), "seed", H5T_NATIVE_ULLONG, &seed, path)) p.seed = seed;
  return p;
}

Packing read_packing_hdf5(const std::string& path) {
  // Damaged files can crash, hang or exhaust memory inside libhdf5 1.10 (fuzz/regressions/):
  // the read is tried in a child first. A packing of the largest accepted size reads in seconds
  // within a few hundred MB.
  constexpr unsigned kSeconds = 120;
  constexpr unsigned long long kMemoryBytes = 8ULL << 30;
  core::run_isolated([&path] { read_packing_hdf5_in_process(path); }, "packing file '" + path + "'",
                     kSeconds, kMemoryBytes);
  return read_packing_hdf5_in_process(path);
}

}  // namespace arrays
}  // namespace draglab
