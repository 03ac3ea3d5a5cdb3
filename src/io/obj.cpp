// Wavefront OBJ: "v x y z" and "f" lines whose corners are i, i/t, i//n or i/t/n, with
// negative indices counting back from the latest vertex; polygons are fanned. Every other
// line (vt, vn, g, o, s, usemtl, l, p, ...) carries no solid geometry and is skipped.
#include <string>
#include <vector>

#include "io/readers.h"
#include "io/text.h"

namespace pic::detail {
namespace {

[[noreturn]] void fail(size_t line, const std::string& what) {
  throw InvalidInput("OBJ: line " + std::to_string(line) + ": " + what);
}

}  // namespace

RawGeometry read_obj(Bytes bytes) {
  TextCursor t(bytes.chars(), bytes.chars() + bytes.size);
  RawGeometry g;
  std::vector<int64_t> polygon;  // 1-based, resolved when all vertices are known
  std::vector<uint32_t> corners;
  struct Face {
    size_t line, first, count;
  };
  std::vector<Face> faces;
  std::vector<int64_t> all;  // every face's corners, absolute and 1-based
  while (!t.at_end()) {
    const size_t line = t.line();
    const std::string_view key = t.token_on_line();
    if (key == "v") {
      Vec3 p;
      for (double& x : p) {
        const std::string_view v = t.token_on_line();
        if (v.empty() || v[0] == '#') fail(line, "a vertex needs x y z");
        x = parse_double(v, line);
      }
      g.positions.push_back(p);
    } else if (key == "f") {
      const size_t first = all.size();
      while (true) {
        const std::string_view c = t.token_on_line();
        if (c.empty() || c[0] == '#') break;
        const int64_t i = parse_int(c.substr(0, c.find('/')), line);
        const auto nv = int64_t(g.positions.size());
        if (i == 0) fail(line, "vertex index 0 (OBJ counts from 1)");
        if (i < 0 && -i > nv) fail(line, "relative vertex index " + std::to_string(i) + " before the first vertex");
        all.push_back(i > 0 ? i : nv + i + 1);
      }
      faces.push_back({line, first, all.size() - first});
    }
    t.skip_line();
  }
  for (const Face& f : faces) {
    corners.clear();
    for (size_t k = 0; k < f.count; ++k) {
      const int64_t i = all[f.first + k];
      if (i > int64_t(g.positions.size()))
        fail(f.line, "vertex index " + std::to_string(i) + " out of range (" + std::to_string(g.positions.size()) +
                         " vertices)");
      corners.push_back(uint32_t(i - 1));
    }
    add_fan(corners.data(), corners.size(), g.triangles);
  }
  return g;
}

}  // namespace pic::detail
