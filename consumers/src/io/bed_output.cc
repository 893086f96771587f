// Gas fields and particles of a DPM run to HDF5 (C API, Debian's libhdf5 1.10) with an XDMF 2
// index for ParaView's XDMFReader. Layout and axis mapping: bed_output.h and docs/dpm.md.
#include "io/bed_output.h"

#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "drag_db_version.h"
#include "draglab/core/files.h"
#include "draglab/core/hdf5_file.h"
#include "draglab/core/xdmf.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

using Handle = core::Hdf5Handle;
namespace xdmf = core::xdmf;

[[noreturn]] void Fail(const std::string& path, const std::string& what) {
  throw Error(ErrorCode::kInvalidArgument, "DPM output '" + path + "': " + what);
}

/// "name@version" -> "name_version"; anything outside [A-Za-z0-9_.-] becomes '_' too, so the
/// stem is a plain file name.
std::string FileSafe(const std::string& s) {
  std::string out = s;
  for (char& c : out) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '_' || c == '-' || c == '.';
    if (!plain) c = '_';
  }
  return out;
}

void WriteDataset(hid_t group, const std::string& name, const std::vector<hsize_t>& dims,
                  hid_t file_type, hid_t mem_type, const void* data, const std::string& path,
                  const std::string& group_name) {
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose);
  Handle set(space.ok() ? H5Dcreate2(group, name.c_str(), file_type, space.get(), H5P_DEFAULT,
                                     H5P_DEFAULT, H5P_DEFAULT)
                        : -1,
             H5Dclose);
  if (!set.ok() || H5Dwrite(set.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    Fail(path, "cannot write dataset /" + group_name + "/" + name + " (disk full?)");
  }
}

void WriteAttribute(hid_t object, const char* name, hid_t file_type, hid_t mem_type,
                    const std::vector<hsize_t>& dims, const void* value, const std::string& path) {
  Handle space(dims.empty() ? H5Screate(H5S_SCALAR)
                            : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
               H5Sclose);
  Handle attr(
      space.ok() ? H5Acreate2(object, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT) : -1,
      H5Aclose);
  if (!attr.ok() || H5Awrite(attr.get(), mem_type, value) < 0) {
    Fail(path, std::string("cannot write attribute ") + name);
  }
}

void WriteString(hid_t object, const char* name, const std::string& value,
                 const std::string& path) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), H5T_VARIABLE);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  const char* c = value.c_str();
  WriteAttribute(object, name, type.get(), type.get(), {}, &c, path);
}

/// What the index needs to know about one written output time.
struct OutputTime {
  std::string group;  // "t000000"
  double t_s = 0.0;
  bool fields = false;
  int nx = 0, nz = 0;                      // gas cells (width, height)
  double dx = 0.0, dz = 0.0, depth = 0.0;  // gas cell size [m]
  std::vector<std::string> field_names;    // the cell fields of this time, in file order
  bool particles = false;
  std::size_t particle_count = 0;
};

std::string GasGrid(const OutputTime& o, const std::string& h5_name) {
  // VTK x = width (nx cells), VTK y = height (nz gas cells), VTK z = depth (one cell).
  const std::string cells = xdmf::cell_dims(o.nx, o.nz, 1);
  const char* in = "      ";
  std::ostringstream x;
  x << "    <Grid Name=\"gas\" GridType=\"Uniform\">\n"
    << "     <Time Value=\"" << xdmf::number(o.t_s) << "\"/>\n"
    << xdmf::corect_mesh(o.nx, o.nz, 1, o.dx, o.dz, o.depth, "     ");
  for (const std::string& name : o.field_names) {
    x << "     <Attribute Name=\"" << name << "\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
      << xdmf::hdf_item(cells, "Float", 8, h5_name, "/" + o.group + "/" + name, in)
      << "     </Attribute>\n";
  }
  x << "    </Grid>\n";
  return x.str();
}

std::string ParticleGrid(const OutputTime& o, const std::string& h5_name) {
  // DEM axes (x width, y height, z depth) are the VTK axes: positions go in unchanged.
  const std::string n = std::to_string(o.particle_count);
  const std::string n3 = n + " 3";
  const std::string at = "/" + o.group + "/";
  const char* in = "      ";
  std::ostringstream x;
  x << "    <Grid Name=\"particles\" GridType=\"Uniform\">\n"
    << "     <Time Value=\"" << xdmf::number(o.t_s) << "\"/>\n"
    << "     <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << n
    << "\" NodesPerElement=\"1\"/>\n"
    << "     <Geometry GeometryType=\"XYZ\">\n"
    << xdmf::hdf_item(n3, "Float", 8, h5_name, at + "position", in) << "     </Geometry>\n"
    << "     <Attribute Name=\"velocity\" AttributeType=\"Vector\" Center=\"Node\">\n"
    << xdmf::hdf_item(n3, "Float", 8, h5_name, at + "velocity", in) << "     </Attribute>\n"
    << "     <Attribute Name=\"diameter\" AttributeType=\"Scalar\" Center=\"Node\">\n"
    << xdmf::hdf_item(n, "Float", 8, h5_name, at + "diameter", in) << "     </Attribute>\n"
    << "     <Attribute Name=\"id\" AttributeType=\"Scalar\" Center=\"Node\">\n"
    << xdmf::hdf_item(n, "Int", 8, h5_name, at + "id", in) << "     </Attribute>\n"
    << "     <Attribute Name=\"layer\" AttributeType=\"Scalar\" Center=\"Node\">\n"
    << xdmf::hdf_item(n, "Int", 4, h5_name, at + "layer", in) << "     </Attribute>\n"
    << "    </Grid>\n";
  return x.str();
}

std::string XdmfText(const std::vector<OutputTime>& outputs, const std::string& h5_name,
                     const std::string& scene, const std::string& law) {
  std::ostringstream x;
  x << xdmf::begin_document() << "  <Information Name=\"scene\" Value=\"" << xdmf::escape(scene)
    << "\"/>\n"
    << "  <Information Name=\"law\" Value=\"" << xdmf::escape(law) << "\"/>\n";
  // One temporal collection per kind, so ParaView's reader lists "gas" and "particles" as
  // separate grids (blocks) that can be switched on and off.
  bool any_fields = false, any_particles = false;
  for (const OutputTime& o : outputs) {
    any_fields = any_fields || o.fields;
    // A Polyvertex with no elements makes a degenerate grid: steps without particles are left out.
    any_particles = any_particles || (o.particles && o.particle_count > 0);
  }
  if (any_fields) {
    x << "  <Grid Name=\"gas\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (const OutputTime& o : outputs) {
      if (o.fields) x << GasGrid(o, h5_name);
    }
    x << "  </Grid>\n";
  }
  if (any_particles) {
    x << "  <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (const OutputTime& o : outputs) {
      if (o.particles && o.particle_count > 0) x << ParticleGrid(o, h5_name);
    }
    x << "  </Grid>\n";
  }
  x << xdmf::end_document();
  return x.str();
}

}  // namespace

struct BedOutputWriter::Impl {
  std::string scene_name, scene_hash, law;
  bool fields = false, particles = false;
  std::string h5_path, xmf_path, h5_name;
  bool h5_created = false, xmf_written = false, index_current = true;
  std::vector<OutputTime> outputs;

  void WriteGroup(hid_t file, const OutputTime& o, double t_s, const CellFields* cells,
                  const Particles* p, const std::vector<int>* layers);
  /// The checks, the file handling and the bookkeeping of one output time.
  void Append(double t_s, const CellFields* cells, const Particles* particles,
              const std::vector<int>* layer_by_id);
};

BedOutputWriter::BedOutputWriter(const Scene& scene, const std::string& law,
                                 const std::string& directory, bool fields, bool particles)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.scene_name = scene.name;
  m.scene_hash = scene.hash();
  m.law = law;
  m.fields = fields;
  m.particles = particles;
  // The same default as DpmOptions::output_directory, so a writer made directly agrees with it.
  std::string dir = directory;
  if (dir.empty()) dir = scene.outputs.directory;
  if (dir.empty()) dir = "out/" + (scene.name.empty() ? std::string("scene") : scene.name);
  const std::filesystem::path stem =
      std::filesystem::path(dir) / (FileSafe(scene.name.empty() ? "scene" : scene.name) + "_" +
                                    FileSafe(law.empty() ? "law" : law));
  m.h5_path = stem.string() + ".h5";
  m.xmf_path = stem.string() + ".xmf";
  m.h5_name = stem.filename().string() + ".h5";
  if (!fields && !particles) return;  // nothing asked for: touch nothing
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) Fail(dir, "cannot create the output directory (" + ec.message() + ")");
  if (!std::filesystem::is_directory(dir, ec)) Fail(dir, "exists but is not a directory");
  if (access(dir.c_str(), W_OK) != 0) Fail(dir, "the output directory is not writable");
}

BedOutputWriter::~BedOutputWriter() {
  try {
    Finish();
  } catch (...) {
    // A destructor must not throw; callers who need the error call Finish() themselves.
  }
}

void BedOutputWriter::Impl::WriteGroup(hid_t file, const OutputTime& o, double t_s,
                                       const CellFields* cells, const Particles* particles,
                                       const std::vector<int>* layer_by_id) {
  Handle group(H5Gcreate2(file, o.group.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  if (!group.ok()) Fail(h5_path, "cannot create group /" + o.group);
  const hid_t g = group.get();
  WriteAttribute(g, "time_s", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {}, &t_s, h5_path);
  if (o.fields) {
    // Eigen arrays are column-major with index (i, j): i (x) fastest, exactly the C order of
    // shape (1, nz, nx), so cell-centred arrays are written as they are.
    const std::vector<hsize_t> dims{1, static_cast<hsize_t>(o.nz), static_cast<hsize_t>(o.nx)};
    for (const auto& [name, values] : cells->arrays) {
      WriteDataset(g, name.c_str(), dims, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, values.data(), h5_path,
                   o.group);
    }
    const double cell[3] = {o.dx, o.dz, o.depth};
    WriteAttribute(g, "cell_size_m", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {3}, cell, h5_path);
  }
  if (o.particles) {
    const Particles& p = *particles;
    const std::vector<int>& layers = *layer_by_id;
    const std::size_t n = o.particle_count;
    std::vector<double> position(3 * n), velocity(3 * n);
    std::vector<std::int64_t> id(n);
    std::vector<std::int32_t> layer(n);
    for (std::size_t k = 0; k < n; ++k) {
      position[3 * k] = p.x[k];
      position[3 * k + 1] = p.y[k];
      position[3 * k + 2] = p.z[k];
      velocity[3 * k] = p.vx[k];
      velocity[3 * k + 1] = p.vy[k];
      velocity[3 * k + 2] = p.vz[k];
      id[k] = p.id[k];
      layer[k] = layers[static_cast<std::size_t>(p.id[k])];
    }
    const hsize_t hn = static_cast<hsize_t>(n);
    WriteDataset(g, "position", {hn, 3}, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, position.data(),
                 h5_path, o.group);
    WriteDataset(g, "velocity", {hn, 3}, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, velocity.data(),
                 h5_path, o.group);
    WriteDataset(g, "diameter", {hn}, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, p.diameter.data(), h5_path,
                 o.group);
    WriteDataset(g, "id", {hn}, H5T_STD_I64LE, H5T_NATIVE_INT64, id.data(), h5_path, o.group);
    WriteDataset(g, "layer", {hn}, H5T_STD_I32LE, H5T_NATIVE_INT32, layer.data(), h5_path, o.group);
  }
}

CellFields gas_cell_fields(const GasPhase& gas) {
  CellFields c;
  c.nx = gas.options().nx;
  c.nz = gas.options().nz;
  c.dx = gas.dx();
  c.dz = gas.dz();
  c.depth = gas.options().depth_m;
  const Eigen::ArrayXXd& u = gas.u();
  const Eigen::ArrayXXd& w = gas.w();
  Eigen::ArrayXXd ux(c.nx, c.nz), uz(c.nx, c.nz);
  for (int j = 0; j < c.nz; ++j) {
    for (int i = 0; i < c.nx; ++i) {
      ux(i, j) = 0.5 * (u(i, j) + u(i + 1, j));
      uz(i, j) = 0.5 * (w(i, j) + w(i, j + 1));
    }
  }
  c.arrays = {{"eps", gas.eps()}, {"p", gas.p()}, {"u_x", ux}, {"u_z", uz}, {"beta", gas.beta()}};
  return c;
}

void BedOutputWriter::Write(double t_s, const GasPhase& gas, const Particles& particles,
                            const std::vector<int>& layer_by_id) {
  Impl& m = *impl_;
  if (!m.fields && !m.particles) return;
  const CellFields cells = m.fields ? gas_cell_fields(gas) : CellFields();
  m.Append(t_s, m.fields ? &cells : nullptr, m.particles ? &particles : nullptr, &layer_by_id);
}

void BedOutputWriter::WriteFields(double t_s, const CellFields& cells) {
  Impl& m = *impl_;
  if (!m.fields) return;
  if (m.particles) Fail(m.h5_path, "this writer was made for particles too: use Write()");
  if (cells.nx < 1 || cells.nz < 1 || cells.arrays.empty())
    Fail(m.h5_path, "cell fields need a grid (nx, nz >= 1) and at least one array");
  for (const auto& [name, values] : cells.arrays) {
    if (name.empty() || values.rows() != cells.nx || values.cols() != cells.nz)
      Fail(m.h5_path, "cell field '" + name + "' must be named and nx x nz = " +
                          std::to_string(cells.nx) + " x " + std::to_string(cells.nz));
  }
  m.Append(t_s, &cells, nullptr, nullptr);
}

void BedOutputWriter::Impl::Append(double t_s, const CellFields* cells,
                                   const Particles* particles_in,
                                   const std::vector<int>* layers_in) {
  Impl& m = *this;
  if (!std::isfinite(t_s)) Fail(m.h5_path, "output time t_s must be finite");
  if (!m.outputs.empty() && !(t_s > m.outputs.back().t_s)) {
    Fail(m.h5_path, "output time t_s = " + xdmf::number(t_s) +
                        " s must be after the previous one (" + xdmf::number(m.outputs.back().t_s) +
                        " s)");
  }
  OutputTime o;
  char group[32];
  std::snprintf(group, sizeof group, "t%06zu", m.outputs.size());
  o.group = group;
  o.t_s = t_s;
  o.fields = cells != nullptr;
  if (o.fields) {
    o.nx = cells->nx;
    o.nz = cells->nz;
    o.dx = cells->dx;
    o.dz = cells->dz;
    o.depth = cells->depth;
    for (const auto& a : cells->arrays) o.field_names.push_back(a.first);
  }
  o.particles = particles_in != nullptr;
  if (o.particles) {
    const Particles& p = *particles_in;
    const std::vector<int>& layer_by_id = *layers_in;
    const std::size_t n = p.size();
    if (p.y.size() != n || p.z.size() != n || p.vx.size() != n || p.vy.size() != n ||
        p.vz.size() != n || p.diameter.size() != n || p.id.size() != n) {
      Fail(m.h5_path, "particle arrays (x, y, z, vx, vy, vz, diameter, id) differ in size");
    }
    for (std::size_t k = 0; k < n; ++k) {
      if (p.id[k] < 0 || static_cast<std::size_t>(p.id[k]) >= layer_by_id.size()) {
        Fail(m.h5_path, "particle id " + std::to_string(p.id[k]) +
                            " has no initial layer (layer_by_id holds ids 0 .. " +
                            std::to_string(static_cast<long long>(layer_by_id.size()) - 1) + ")");
      }
    }
    o.particle_count = n;
  }

  // HDF5 prints its own error stack by default; our messages name the path instead.
  core::silence_hdf5();
  // The file is opened for each output time and closed after it, so what a crashed or killed
  // run leaves behind is a complete file holding every finished output time.
  const bool create = !m.h5_created;
  if (create) {
    std::remove(m.xmf_path.c_str());  // a previous run's index would not match the new file
    m.xmf_written = false;
  }
  Handle file(create ? H5Fcreate(m.h5_path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT)
                     : H5Fopen(m.h5_path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT),
              H5Fclose);
  if (!file.ok()) {
    Fail(m.h5_path, create ? "cannot create the file (is the directory writable?)"
                           : "cannot reopen the file to append an output time");
  }
  m.h5_created = true;
  try {
    if (create) {
      const hid_t f = file.get();
      WriteString(f, "scene", m.scene_name, m.h5_path);
      WriteString(f, "scene_hash", m.scene_hash, m.h5_path);
      WriteString(f, "law", m.law, m.h5_path);
      WriteString(f, "draglab_version", kDragDbVersion, m.h5_path);
      WriteString(f, "layout",
                  "one group per output time /t000000, /t000001, ... (attribute time_s [s] since "
                  "the background flow started). Cell fields (cell centres, shape (1, nz, nx), C "
                  "order, x fastest; cell (i, j) centre at ((i + 1/2) dx, (j + 1/2) dz), dx dz "
                  "depth in attribute cell_size_m): DPM eps, p [Pa], u_x u_z [m/s] interstitial, "
                  "beta [kg m^-3 s^-1]; TFM eps, phi, p [Pa], u_x u_z v_x v_z [m/s] interstitial "
                  "gas and solids, theta [m^2/s^2], beta. Particles (N rows): position, velocity "
                  "(N, 3) [m, m/s] in (x width, y height, z depth), diameter [m], id, layer "
                  "(initial, 0 = bottom).",
                  m.h5_path);
    }
    m.WriteGroup(file.get(), o, t_s, cells, particles_in, layers_in);
    if (H5Fflush(file.get(), H5F_SCOPE_GLOBAL) < 0) Fail(m.h5_path, "cannot flush the file");
  } catch (...) {
    // Drop the unfinished group so the file holds only complete output times; the index never
    // refers to it either way.
    if (H5Lexists(file.get(), o.group.c_str(), H5P_DEFAULT) > 0) {
      H5Ldelete(file.get(), o.group.c_str(), H5P_DEFAULT);
    }
    throw;
  }
  if (file.close() < 0) Fail(m.h5_path, "cannot close the file (disk full?)");
  m.outputs.push_back(o);
  m.index_current = false;
}

void BedOutputWriter::Finish() {
  Impl& m = *impl_;
  if (m.index_current || m.outputs.empty()) return;
  // Written whole and renamed into place: ParaView never sees half an index.
  core::write_file_atomically(m.xmf_path, XdmfText(m.outputs, m.h5_name, m.scene_name, m.law),
                              "XDMF index");
  m.xmf_written = true;
  m.index_current = true;
}

std::vector<std::string> BedOutputWriter::files() const {
  std::vector<std::string> out;
  if (impl_->h5_created) out.push_back(impl_->h5_path);
  if (impl_->xmf_written) out.push_back(impl_->xmf_path);
  return out;
}

int BedOutputWriter::outputs() const { return static_cast<int>(impl_->outputs.size()); }

}  // namespace consumers
}  // namespace draglab
