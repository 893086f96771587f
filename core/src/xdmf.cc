// core/src/xdmf.cc: see draglab/core/xdmf.h.
#include "draglab/core/xdmf.h"

#include <cstdio>
#include <cstdlib>

namespace draglab {
namespace core {
namespace xdmf {

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string number(double value) {
  char text[40];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return text;
}

std::string begin_document() {
  return "<?xml version=\"1.0\" ?>\n"
         "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
         "<Xdmf Version=\"2.0\">\n"
         " <Domain>\n";
}

std::string end_document() { return " </Domain>\n</Xdmf>\n"; }

std::string hdf_item(const std::string& dims, const std::string& number_type, int precision,
                     const std::string& h5_name, const std::string& dataset,
                     const std::string& indent) {
  return indent + "<DataItem Dimensions=\"" + dims + "\" NumberType=\"" + number_type +
         "\" Precision=\"" + std::to_string(precision) + "\" Format=\"HDF\">" + escape(h5_name) +
         ":" + dataset + "</DataItem>\n";
}

std::string cell_dims(std::int64_t nx, std::int64_t ny, std::int64_t nz) {
  return std::to_string(nz) + " " + std::to_string(ny) + " " + std::to_string(nx);
}

std::string corect_mesh(std::int64_t nx, std::int64_t ny, std::int64_t nz, double dx, double dy,
                        double dz, const std::string& indent) {
  const std::string in = indent + " ";
  return indent + "<Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"" +
         cell_dims(nx + 1, ny + 1, nz + 1) + "\"/>\n" + indent +
         "<Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n" + in +
         "<DataItem Name=\"Origin\" Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
         "Format=\"XML\">0 0 0</DataItem>\n" +
         in +
         "<DataItem Name=\"Spacing\" Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
         "Format=\"XML\">" +
         number(dz) + " " + number(dy) + " " + number(dx) + "</DataItem>\n" + indent +
         "</Geometry>\n";
}

}  // namespace xdmf
}  // namespace core
}  // namespace draglab
