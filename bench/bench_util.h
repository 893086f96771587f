// bench/bench_util.h: helpers shared by the DEM benchmarks (bench_dem, bench_dpm): command-line
// numbers and thread lists, and the bed file (a particle state handed over from another code).
//
// Bed file: text; a line whose first non-blank character is '#' is a comment; one sphere per line
// with 11 numbers in SI units and draglab's DEM axes (x width, y up, z depth):
//   x y z vx vy vz wx wy wz diameter density
// bench/liggghts/run_side_by_side.sh writes it from the bed that LIGGGHTS settled.
#pragma once

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "draglab/consumers/dem.h"

namespace draglab {
namespace bench {

/// Parses a whole argument as a number; throws std::invalid_argument naming the option otherwise.
inline double ParseNumber(const std::string& option, const char* text) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0') throw std::invalid_argument(option + ": not a number: " + text);
  return v;
}

/// The value of the option argv[*index] (the next argument); advances *index past it. Throws
/// std::invalid_argument naming the option when it is the last argument.
inline const char* OptionValue(int argc, char** argv, int* index) {
  const std::string option = argv[*index];
  if (*index + 1 >= argc) throw std::invalid_argument(option + ": missing value");
  return argv[++*index];
}

/// OptionValue as an integer; throws std::invalid_argument naming the option otherwise.
inline int OptionInteger(int argc, char** argv, int* index) {
  const std::string option = argv[*index];
  const double v = ParseNumber(option, OptionValue(argc, argv, index));
  if (v != static_cast<int>(v)) throw std::invalid_argument(option + ": not an integer");
  return static_cast<int>(v);
}

/// "1,2" -> {1, 2}: OpenMP thread counts, each an integer in [1, 256].
inline std::vector<int> ParseThreadList(const char* text) {
  std::vector<int> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    const double v = ParseNumber("--threads", item.c_str());
    if (v < 1 || v > 256 || v != static_cast<int>(v))
      throw std::invalid_argument("--threads: each count must be an integer in [1, 256], got " +
                                  item);
    out.push_back(static_cast<int>(v));
  }
  if (out.empty()) throw std::invalid_argument("--threads: empty list");
  return out;
}

/// Reads a bed file (format above). Throws std::invalid_argument naming the file and the line
/// for an unreadable file, a malformed line, or a file without particles. Values are not
/// range-checked here: DemSystem / DpmSimulation check them.
inline consumers::Particles ReadBedFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("--bed: cannot open " + path);
  consumers::Particles p;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream s(line);
    double v[11];
    for (double& x : v)
      if (!(s >> x))
        throw std::invalid_argument("--bed: " + path + " line " + std::to_string(number) +
                                    ": expected 11 numbers (x y z vx vy vz wx wy wz d rho)");
    p.add(v[0], v[1], v[2], v[9], v[10], v[3], v[4], v[5]);
    p.wx.back() = v[6];
    p.wy.back() = v[7];
    p.wz.back() = v[8];
  }
  if (p.size() == 0) throw std::invalid_argument("--bed: " + path + " holds no particles");
  return p;
}

}  // namespace bench
}  // namespace draglab
