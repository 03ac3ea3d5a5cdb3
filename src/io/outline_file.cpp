// 2D outlines out: SVG (paths, y pointing down as SVG has it, millimetre units as OpenSCAD
// writes them) and DXF (one closed LWPOLYLINE per ring).
#include <cstdio>
#include <fstream>
#include <string>

#include "io/file_util.h"
#include "pic/scad.h"
#include "pic/types.h"
#include "geometry/tolerances.h"

namespace pic {
namespace {

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x == 0 ? 0.0 : x);
  return buf;
}

void write_svg(const Outline& o, std::ofstream& out) {
  double lo[2] = {detail::kHuge, detail::kHuge}, hi[2] = {-detail::kHuge, -detail::kHuge};
  for (const auto& r : o.rings)
    for (const auto& p : r)
      for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  if (o.rings.empty()) lo[0] = lo[1] = hi[0] = hi[1] = 0;
  const double w = hi[0] - lo[0], h = hi[1] - lo[1];
  out << "<?xml version=\"1.0\" standalone=\"no\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" << num(w) << "mm\" height=\"" << num(h)
      << "mm\" viewBox=\"" << num(lo[0]) << " " << num(-hi[1]) << " " << num(w) << " " << num(h) << "\">\n"
      << "<path fill-rule=\"evenodd\" fill=\"lightgray\" stroke=\"black\" stroke-width=\"0.1\" d=\"";
  for (const auto& r : o.rings) {
    for (size_t i = 0; i < r.size(); ++i) out << (i ? " L " : "\nM ") << num(r[i][0]) << "," << num(-r[i][1]);
    out << " z";
  }
  out << "\"/>\n</svg>\n";
}

void write_dxf(const Outline& o, std::ofstream& out) {
  out << "0\nSECTION\n2\nENTITIES\n";
  for (const auto& r : o.rings) {
    out << "0\nLWPOLYLINE\n8\n0\n90\n" << r.size() << "\n70\n1\n";
    for (const auto& p : r) out << "10\n" << num(p[0]) << "\n20\n" << num(p[1]) << "\n";
  }
  out << "0\nENDSEC\n0\nEOF\n";
}

}  // namespace

void write_outline(const Outline& outline, const std::filesystem::path& path) {
  const std::string ext = detail::lower_extension(path);
  if (ext != ".svg" && ext != ".dxf") throw InvalidInput(path.string() + ": a 2D outline is written as .svg or .dxf");
  detail::write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw IoError("cannot write " + tmp.string());
    if (ext == ".svg") write_svg(outline, out);
    else write_dxf(outline, out);
    if (!out.flush()) throw IoError("cannot write " + tmp.string());
  });
}

}  // namespace pic
