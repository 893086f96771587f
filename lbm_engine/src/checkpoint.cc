// checkpoint.cc: writing and reading the checkpoint file (checkpoint.h).
#include "checkpoint.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

#include <nlohmann/json.hpp>

#include "drag_db_version.h"
#include "draglab/core/files.h"
#include "draglab/core/text.h"
#include "draglab/error.h"

namespace draglab {
namespace lbm {
namespace {

constexpr char kMagic[] = "draglab lbm checkpoint, format 1\n";
constexpr std::size_t kMagicBytes = sizeof(kMagic) - 1;
/// The largest header or section name a reader accepts (a damaged length is caught before any
/// allocation).
constexpr std::uint64_t kMaxHeaderBytes = std::uint64_t{1} << 30;
constexpr std::uint64_t kMaxNameBytes = 256;

constexpr char kField[] = "checkpoint";

/// 64-bit FNV-1a, continued over the pieces of the file in order.
struct Fnv1a {
  std::uint64_t state = 1469598103934665603ull;
  void add(const void* data, std::size_t bytes) { state = fnv1a(data, bytes, state); }
};

using Json = nlohmann::json;

Json doubles_json(const std::vector<double>& v) {
  Json a = Json::array();
  for (double x : v) a.push_back(double_bits(x));
  return a;
}

std::vector<double> json_doubles(const Json& a) {
  std::vector<double> v;
  v.reserve(a.size());
  for (const Json& x : a) v.push_back(bits_double(x.get<std::uint64_t>()));
  return v;
}

/// The loop state's double scalars, in the order the header stores them.
template <typename State>
auto scalar_fields(State& s) {
  return std::array{&s.stepping_s,      &s.force,   &s.last_log_force, &s.last_log_re,
                    &s.relative_change, &s.balance, &s.F_mean,         &s.U,
                    &s.re_lattice,      &s.mach,    &s.mach_max,       &s.last_max_speed};
}

Json state_json(const LoopState& s) {
  Json j;
  j["step"] = s.step;
  j["adjustments"] = s.adjustments;
  j["re_reached"] = s.re_control.reached;
  j["fine_corrections"] = s.re_control.fine_corrections;
  j["averaging"] = s.averaging;
  j["averaging_restarts"] = s.averaging_restarts;
  j["averaging_start"] = s.averaging_start;
  j["mach_warned"] = s.mach_warned;
  j["last_max_node"] = s.last_max_node;
  j["last_check_step"] = s.last_check_step;
  std::vector<double> scalars;
  for (const double* x : scalar_fields(s)) scalars.push_back(*x);
  j["scalars"] = doubles_json(scalars);
  std::vector<double> window;
  for (const auto& w : s.window) {
    window.push_back(w.first);
    window.push_back(w.second);
  }
  j["window"] = doubles_json(window);
  j["series_F"] = doubles_json(s.series_F);
  j["series_re"] = doubles_json(s.series_re);
  j["series_body"] = Json::array();
  for (const auto& b : s.series_body) j["series_body"].push_back(doubles_json(b));
  std::vector<double> history;
  for (const HistoryPoint& h : s.history) {
    history.insert(history.end(), {static_cast<double>(h.step), h.F, h.re, h.relative_change});
  }
  j["history"] = doubles_json(history);
  j["warnings"] = s.warnings;
  j["measured_pore_speed_ratio"] = double_bits(s.measured_pore_speed_ratio);
  j["elapsed_s"] = double_bits(s.elapsed_s);
  return j;
}

LoopState json_state(const Json& j) {
  LoopState s;
  s.step = j.at("step").get<std::int64_t>();
  s.adjustments = j.at("adjustments").get<int>();
  // (absent from checkpoints written before the finite-Re hold: counted from the resume on)
  s.re_control.reached = j.value("re_reached", false);
  s.re_control.fine_corrections = j.value("fine_corrections", 0);
  s.averaging = j.at("averaging").get<bool>();
  s.averaging_restarts = j.at("averaging_restarts").get<int>();
  s.averaging_start = j.at("averaging_start").get<std::int64_t>();
  s.mach_warned = j.at("mach_warned").get<bool>();
  s.last_max_node = j.at("last_max_node").get<std::int64_t>();
  s.last_check_step = j.at("last_check_step").get<std::int64_t>();
  const std::vector<double> scalars = json_doubles(j.at("scalars"));
  const auto fields = scalar_fields(s);
  if (scalars.size() != fields.size()) throw std::runtime_error("scalars");
  for (std::size_t k = 0; k < fields.size(); ++k) *fields[k] = scalars[k];
  const std::vector<double> window = json_doubles(j.at("window"));
  for (std::size_t k = 0; k + 1 < window.size(); k += 2) {
    s.window.push_back({window[k], window[k + 1]});
  }
  s.series_F = json_doubles(j.at("series_F"));
  s.series_re = json_doubles(j.at("series_re"));
  for (const Json& b : j.at("series_body")) s.series_body.push_back(json_doubles(b));
  const std::vector<double> history = json_doubles(j.at("history"));
  for (std::size_t k = 0; k + 3 < history.size(); k += 4) {
    s.history.push_back(
        {static_cast<std::int64_t>(history[k]), history[k + 1], history[k + 2], history[k + 3]});
  }
  s.warnings = j.at("warnings").get<std::vector<std::string>>();
  // (absent from the first checkpoints: the run then measures kappa again)
  s.measured_pore_speed_ratio = bits_double(j.value("measured_pore_speed_ratio", std::uint64_t{0}));
  // (absent from checkpoints written before the runs kept their time: the earlier parts count 0)
  s.elapsed_s = bits_double(j.value("elapsed_s", std::uint64_t{0}));
  return s;
}

[[noreturn]] void refuse(const std::string& field, const std::string& path,
                         const std::string& what) {
  throw Error(ErrorCode::kInvalidArgument, field + " '" + path + "': " + what +
                                               "; remedy: remove the file (the run then starts "
                                               "afresh) or name another checkpoint");
}

/// Sequential reader that keeps the checksum of what it has read.
class Reader {
 public:
  Reader(const std::string& path, const std::string& field) : path_(path), field_(field) {
    file_.reset(std::fopen(path.c_str(), "rb"));
    if (!file_) {
      throw Error(ErrorCode::kIo, field + " '" + path + "': cannot open: " + std::strerror(errno));
    }
    if (std::fseek(file_.get(), 0, SEEK_END) == 0) {
      const long size = std::ftell(file_.get());
      left_ = size > 0 ? static_cast<std::uint64_t>(size) : 0;
    }
    std::rewind(file_.get());
  }
  void read(void* data, std::size_t bytes, const char* what) {
    // A damaged length is caught against what the file holds, before any allocation or read.
    if (bytes > left_ || (bytes > 0 && std::fread(data, 1, bytes, file_.get()) != bytes)) {
      refuse(field_, path_,
             std::string("not a complete draglab checkpoint (it ends in the ") + what + ")");
    }
    checksum_.add(data, bytes);
    left_ -= bytes;
  }
  std::uint64_t left() const { return left_; }
  std::uint64_t read_u64(const char* what) {
    std::uint64_t x = 0;
    read(&x, sizeof x, what);
    return x;
  }
  std::string read_text(std::uint64_t limit, const char* what) {
    const std::uint64_t bytes = read_u64(what);
    if (bytes > limit || bytes > left_) refuse(field_, path_, std::string("a damaged ") + what);
    std::string text(static_cast<std::size_t>(bytes), '\0');
    read(text.data(), text.size(), what);
    return text;
  }
  /// The header, after checking the format line.
  std::string header() {
    char magic[kMagicBytes];
    if (left_ < kMagicBytes || std::fread(magic, 1, kMagicBytes, file_.get()) != kMagicBytes ||
        std::memcmp(magic, kMagic, kMagicBytes) != 0) {
      refuse(field_, path_, "not a draglab checkpoint (format 1)");
    }
    checksum_.add(magic, kMagicBytes);
    left_ -= kMagicBytes;
    return read_text(kMaxHeaderBytes, "header");
  }
  std::uint64_t checksum() const { return checksum_.state; }
  std::FILE* file() { return file_.get(); }

 private:
  struct Close {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Close> file_;
  std::string path_, field_;
  Fnv1a checksum_;
  std::uint64_t left_ = 0;  ///< Bytes of the file not read yet.
};

}  // namespace

std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t seed) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  std::uint64_t h = seed;
  for (std::size_t k = 0; k < bytes; ++k) {
    h ^= p[k];
    h *= 1099511628211ull;
  }
  return h;
}

void save_run_checkpoint(const std::string& path, const Fingerprint& fingerprint,
                         const LoopState& state, const std::vector<StateSection>& sections) {
  Json header;
  header["code"] = kDragDbVersion;
  header["fingerprint"] = Json::array();
  for (const auto& entry : fingerprint)
    header["fingerprint"].push_back({entry.first, entry.second});
  header["state"] = state_json(state);
  write_checkpoint(path, header.dump(), sections, kField);
}

std::string load_run_checkpoint(const std::string& path, const Fingerprint& fingerprint,
                                LoopState* state, const std::vector<StateSection>& sections) {
  Json header;
  std::string code;
  try {
    header = Json::parse(read_checkpoint_header(path, kField));
    code = header.at("code").get<std::string>();
    const Json& theirs = header.at("fingerprint");
    if (theirs.size() != fingerprint.size()) throw std::runtime_error("fingerprint size");
    for (std::size_t k = 0; k < fingerprint.size(); ++k) {
      const std::string name = theirs[k].at(0).get<std::string>();
      const std::string value = theirs[k].at(1).get<std::string>();
      if (name != fingerprint[k].first || value != fingerprint[k].second) {
        refuse(kField, path,
               "written by another run (its " + name + " is " + value + ", this run's " +
                   fingerprint[k].first + " is " + fingerprint[k].second + ")");
      }
    }
    *state = json_state(header.at("state"));
  } catch (const nlohmann::json::exception&) {
    refuse(kField, path, "a damaged header");
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const Error*>(&e) != nullptr) throw;
    refuse(kField, path, "a damaged header");
  }
  read_checkpoint_sections(path, sections, kField);
  return code;
}

double checkpoint_pore_speed_ratio(const std::string& path) {
  if (!core::file_exists(path)) return 0.0;
  try {
    const Json header = Json::parse(read_checkpoint_header(path, kField));
    const double kappa =
        bits_double(header.at("state").value("measured_pore_speed_ratio", std::uint64_t{0}));
    return std::isfinite(kappa) && kappa > 0.0 ? kappa : 0.0;
  } catch (const std::exception&) {
    return 0.0;
  }
}

CheckpointProgress read_checkpoint_progress(const std::string& path) {
  if (!core::file_exists(path)) {
    throw Error(ErrorCode::kNotFound, std::string(kField) + " '" + path + "' does not exist");
  }
  LoopState state;
  CheckpointProgress p;
  try {
    const Json header = Json::parse(read_checkpoint_header(path, kField));
    p.code = header.at("code").get<std::string>();
    state = json_state(header.at("state"));
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const Error*>(&e) != nullptr) throw;
    refuse(kField, path, "a damaged header");
  }
  const double nan = std::nan("");
  p.step = state.step;
  p.checks = state.history.size();
  p.force_adjustments = state.adjustments;
  p.F = p.re = p.relative_change = nan;
  p.recent_F_min = p.recent_F_max = p.recent_re_min = p.recent_re_max = nan;
  if (!state.history.empty()) {
    const HistoryPoint& last = state.history.back();
    p.F = last.F;
    p.re = last.re;
    p.relative_change = last.relative_change;
    const std::size_t first =
        state.history.size() - std::min(state.history.size(), CheckpointProgress::kRecentChecks);
    p.recent_F_min = p.recent_F_max = last.F;
    p.recent_re_min = p.recent_re_max = last.re;
    for (std::size_t k = first; k < state.history.size(); ++k) {
      const HistoryPoint& h = state.history[k];
      p.recent_F_min = std::min(p.recent_F_min, h.F);
      p.recent_F_max = std::max(p.recent_F_max, h.F);
      p.recent_re_min = std::min(p.recent_re_min, h.re);
      p.recent_re_max = std::max(p.recent_re_max, h.re);
    }
  }
  p.averaging = state.averaging;
  p.averaging_start = state.averaging_start;
  p.averaged_samples = state.series_F.size();
  p.F_average = p.F_average_standard_error = nan;
  if (state.averaging && state.series_F.size() >= 2) {
    const TimeAverage a = time_average(state.series_F);
    p.F_average = a.mean;
    p.F_average_standard_error = a.standard_error;
  }
  return p;
}

std::string CheckpointProgress::BriefReport() const {
  using core::format_fixed;
  std::string s = "step " + std::to_string(step);
  if (checks == 0) return s + ", no check yet";
  const std::string recent =
      "last " + std::to_string(std::min(checks, kRecentChecks)) + " checks: ";
  s += ", F " + format_fixed("%.6g", F) + " (" + recent + format_fixed("%.6g", recent_F_min) +
       " - " + format_fixed("%.6g", recent_F_max) + "), Re " + format_fixed("%.5g", re) + " (" +
       format_fixed("%.5g", recent_re_min) + " - " + format_fixed("%.5g", recent_re_max) + ")";
  // (no change per characteristic time yet after a correction of the force restarts its window)
  if (std::isfinite(relative_change)) s += ", change/T " + format_fixed("%.2g", relative_change);
  s += ", " + std::to_string(force_adjustments) + " force corrections";
  if (!averaging) return s + "; not averaging";
  s += "; averaging since step " + std::to_string(averaging_start) + ", " +
       std::to_string(averaged_samples) + " samples";
  if (std::isfinite(F_average)) {
    s += ": F " + format_fixed("%.6g", F_average) + " +- " +
         format_fixed("%.2g", F_average_standard_error);
  }
  return s;
}

void check_checkpoint_file(const std::string& path) {
  if (core::file_exists(path)) read_checkpoint_header(path, kField);
}

std::uint64_t double_bits(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  return bits;
}

double bits_double(std::uint64_t bits) {
  double x;
  std::memcpy(&x, &bits, sizeof x);
  return x;
}

void write_checkpoint(const std::string& path, const std::string& header,
                      const std::vector<StateSection>& sections, const std::string& field) {
  // Lengths and names live here until the write: the pieces point into them.
  std::vector<std::uint64_t> lengths;
  lengths.reserve(2 * sections.size() + 3);
  std::vector<core::FilePiece> pieces;
  Fnv1a checksum;
  auto add = [&](const void* data, std::size_t bytes) {
    pieces.push_back({data, bytes});
    checksum.add(data, bytes);
  };
  add(kMagic, kMagicBytes);
  lengths.push_back(header.size());
  add(&lengths.back(), sizeof(std::uint64_t));
  add(header.data(), header.size());
  lengths.push_back(sections.size());
  add(&lengths.back(), sizeof(std::uint64_t));
  for (const StateSection& s : sections) {
    lengths.push_back(std::strlen(s.name));
    add(&lengths.back(), sizeof(std::uint64_t));
    add(s.name, std::strlen(s.name));
    lengths.push_back(s.bytes);
    add(&lengths.back(), sizeof(std::uint64_t));
    add(s.data, s.bytes);
  }
  lengths.push_back(checksum.state);
  pieces.push_back({&lengths.back(), sizeof(std::uint64_t)});
  core::write_file_atomically(path, pieces, field);
}

std::string read_checkpoint_header(const std::string& path, const std::string& field) {
  Reader reader(path, field);
  return reader.header();
}

void read_checkpoint_sections(const std::string& path, const std::vector<StateSection>& sections,
                              const std::string& field) {
  Reader reader(path, field);
  reader.header();
  const std::uint64_t count = reader.read_u64("section count");
  if (count != sections.size()) {
    refuse(field, path,
           "its state has " + std::to_string(count) + " sections where this run has " +
               std::to_string(sections.size()));
  }
  for (const StateSection& s : sections) {
    const std::string name = reader.read_text(kMaxNameBytes, "section name");
    const std::uint64_t bytes = reader.read_u64("section size");
    if (name != s.name || bytes != s.bytes) {
      refuse(field, path,
             "its state section '" + name + "' (" + std::to_string(bytes) +
                 " bytes) does not fit this run's '" + s.name + "' (" + std::to_string(s.bytes) +
                 " bytes)");
    }
    reader.read(s.data, s.bytes, s.name);
  }
  const std::uint64_t computed = reader.checksum();
  std::uint64_t stored = 0;
  if (std::fread(&stored, 1, sizeof stored, reader.file()) != sizeof stored || stored != computed) {
    refuse(field, path, "damaged (its checksum does not match its contents)");
  }
}

}  // namespace lbm
}  // namespace draglab
