// DemSystem's state as bytes (dem.h: SaveState, LoadState): a checkpoint that continues bit for
// bit. Layout: a magic line, the particle count, then each member in a fixed order, every array
// with its length (native byte order; a checkpoint is read back by the build that wrote it).
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "draglab/consumers/dem.h"
#include "draglab/error.h"

namespace draglab {
namespace consumers {
namespace {

constexpr char kStateMagic[] = "draglab dem state 1\n";

class ByteWriter {
 public:
  template <typename T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    out_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <typename T>
  void array(const std::vector<T>& v) {
    value(static_cast<std::uint64_t>(v.size()));
    out_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  std::string& bytes() { return out_; }

 private:
  std::string out_;
};

class ByteReader {
 public:
  explicit ByteReader(const std::string& bytes) : bytes_(bytes) {}
  template <typename T>
  T value() {
    T v;
    take(&v, sizeof(T));
    return v;
  }
  template <typename T>
  std::vector<T> array() {
    const auto n = value<std::uint64_t>();
    if (n > (bytes_.size() - at_) / sizeof(T)) Bad("an array runs past the end");
    std::vector<T> v(n);
    take(v.data(), n * sizeof(T));
    return v;
  }
  bool at_end() const { return at_ == bytes_.size(); }
  [[noreturn]] static void Bad(const std::string& why) {
    throw Error(ErrorCode::kInvalidArgument,
                "DEM state: not a state SaveState wrote (" + why + ")");
  }

 private:
  void take(void* to, std::size_t size) {
    if (size > bytes_.size() - at_) Bad("it ends early");
    std::memcpy(to, bytes_.data() + at_, size);
    at_ += size;
  }
  const std::string& bytes_;
  std::size_t at_ = 0;
};

std::vector<std::vector<double>*> ParticleArrays(Particles& p) {
  return {&p.x,  &p.y,  &p.z,      &p.vx,     &p.vy,     &p.vz,       &p.wx,
          &p.wy, &p.wz, &p.fx_ext, &p.fy_ext, &p.fz_ext, &p.diameter, &p.density};
}

}  // namespace

std::string DemSystem::SaveState() const {
  ByteWriter w;
  w.bytes().append(kStateMagic);
  Particles p = p_;  // ParticleArrays takes mutable arrays
  for (std::vector<double>* a : ParticleArrays(p)) w.array(*a);
  w.array(p.id);
  w.value(time_);
  w.value(steps_);
  w.array(force_);
  w.array(elastic_);
  w.value(skin_);
  w.array(nbr_start_);
  w.array(nbr_);
  w.array(x_built_);
  w.array(y_built_);
  w.array(z_built_);
  w.value(list_builds_);
  for (int b = 0; b < 2; ++b) {
    w.array(hist_count_[b]);
    w.array(hist_partner_[b]);
    w.array(hist_xi_[b]);
  }
  w.value(hist_cur_);
  w.value(contacts_);
  w.value(wall_contacts_);
  w.value(max_overlap_);
  w.value(wall_force_);
  w.value(overflow_particle_);
  return std::move(w.bytes());
}

std::unique_ptr<DemSystem> DemSystem::LoadState(const DemOptions& options,
                                                const std::string& bytes) {
  const std::size_t magic = sizeof(kStateMagic) - 1;
  if (bytes.compare(0, magic, kStateMagic) != 0) ByteReader::Bad("no magic line");
  const std::string body = bytes.substr(magic);
  ByteReader r(body);
  Particles p;
  for (std::vector<double>* a : ParticleArrays(p)) *a = r.array<double>();
  p.id = r.array<std::int64_t>();
  std::string why;
  if (!p.IsValid(&why)) ByteReader::Bad(why);
  // The constructor derives what the options and particles fix (masses, step, cells); the state
  // that history made is then put back as it was.
  std::unique_ptr<DemSystem> dem(new DemSystem(options, std::move(p)));
  const std::size_t n = dem->p_.size();
  dem->time_ = r.value<double>();
  dem->steps_ = r.value<std::int64_t>();
  dem->force_ = r.array<double>();
  dem->elastic_ = r.array<double>();
  const double skin = r.value<double>();
  dem->nbr_start_ = r.array<int>();
  dem->nbr_ = r.array<int>();
  dem->x_built_ = r.array<double>();
  dem->y_built_ = r.array<double>();
  dem->z_built_ = r.array<double>();
  dem->list_builds_ = r.value<std::int64_t>();
  for (int b = 0; b < 2; ++b) {
    dem->hist_count_[b] = r.array<int>();
    dem->hist_partner_[b] = r.array<int>();
    dem->hist_xi_[b] = r.array<double>();
  }
  dem->hist_cur_ = r.value<int>();
  dem->contacts_ = r.value<std::int64_t>();
  dem->wall_contacts_ = r.value<std::int64_t>();
  dem->max_overlap_ = r.value<double>();
  dem->wall_force_ = r.value<std::array<double, 18>>();
  dem->overflow_particle_ = r.value<int>();
  if (!r.at_end()) ByteReader::Bad("bytes after the last member");
  if (skin != dem->skin_) ByteReader::Bad("saved with other options (neighbour skin)");
  bool sizes = dem->force_.size() == 6 * n && dem->elastic_.size() == n &&
               dem->nbr_start_.size() == n + 1 && dem->x_built_.size() == n &&
               dem->y_built_.size() == n && dem->z_built_.size() == n &&
               (dem->hist_cur_ == 0 || dem->hist_cur_ == 1);
  for (int b = 0; b < 2; ++b) {
    sizes = sizes && dem->hist_count_[b].size() == n &&
            dem->hist_partner_[b].size() == dem->hist_xi_[b].size() / 3 &&
            dem->hist_xi_[b].size() % 3 == 0;
  }
  if (!sizes || static_cast<std::size_t>(dem->nbr_start_[n]) != dem->nbr_.size()) {
    ByteReader::Bad("its arrays do not fit its particle count");
  }
  for (int j : dem->nbr_) {
    if (j < 0 || static_cast<std::size_t>(j) >= n) ByteReader::Bad("a neighbour out of range");
  }
  dem->pack_state();
  return dem;
}

}  // namespace consumers
}  // namespace draglab
