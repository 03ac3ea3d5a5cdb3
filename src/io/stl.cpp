// STL, binary and ASCII. Binary is recognised by its size (84 + 50 n bytes for the n
// triangles its header declares), not by a "solid" prefix: many binary writers start the
// 80-byte header with "solid" too. ASCII facets with more than three vertices are fanned.
#include <cstring>
#include <string>
#include <vector>

#include "io/readers.h"
#include "io/text.h"

namespace pic::detail {
namespace {

[[noreturn]] void fail(const std::string& what) { throw InvalidInput("STL: " + what); }

RawGeometry read_binary(Bytes bytes, uint32_t n) {
  RawGeometry g;
  g.positions.reserve(size_t(n) * 3);
  g.triangles.reserve(n);
  for (uint32_t f = 0; f < n; ++f) {
    const uint8_t* rec = bytes.data + 84 + size_t(f) * 50 + 12;  // skip the facet normal
    for (int v = 0; v < 3; ++v) {
      float xyz[3];
      std::memcpy(xyz, rec + 12 * v, 12);  // little-endian on every machine PIC builds on
      g.positions.push_back({xyz[0], xyz[1], xyz[2]});
    }
    const auto b = uint32_t(3 * f);
    g.triangles.push_back({b, b + 1, b + 2});
  }
  return g;
}

RawGeometry read_ascii(Bytes bytes) {
  TextCursor t(bytes.chars(), bytes.chars() + bytes.size);
  RawGeometry g;
  std::vector<uint32_t> facet;
  bool in_facet = false;
  while (true) {
    const std::string_view tok = t.token();
    if (tok.empty()) break;
    const size_t line = t.line();
    if (tok == "solid" || tok == "endsolid" || tok == "outer" || tok == "endloop") {
      t.skip_line();  // a name, "loop"
    } else if (tok == "facet") {
      if (in_facet) fail("line " + std::to_string(line) + ": 'facet' inside a facet");
      in_facet = true;
      facet.clear();
      t.skip_line();  // the normal: PIC uses the vertex order
    } else if (tok == "vertex") {
      if (!in_facet) fail("line " + std::to_string(line) + ": 'vertex' outside a facet");
      Vec3 p;
      for (double& x : p) {
        const std::string_view v = t.token_on_line();
        if (v.empty()) fail("line " + std::to_string(line) + ": a vertex needs x y z");
        x = parse_double(v, line);
      }
      facet.push_back(uint32_t(g.positions.size()));
      g.positions.push_back(p);
    } else if (tok == "endfacet") {
      if (!in_facet || facet.size() < 3)
        fail("line " + std::to_string(line) + ": a facet needs three vertices");
      add_fan(facet.data(), facet.size(), g.triangles);
      in_facet = false;
    } else {
      fail("line " + std::to_string(line) + ": unexpected " + quoted(tok));
    }
  }
  if (in_facet) fail("the file ends inside a facet");
  return g;
}

}  // namespace

RawGeometry read_stl(Bytes bytes) {
  if (bytes.size >= 84) {
    uint32_t n = 0;
    std::memcpy(&n, bytes.data + 80, 4);
    if (uint64_t(bytes.size) == 84 + 50 * uint64_t(n)) return read_binary(bytes, n);
  }
  size_t i = 0;
  while (i < bytes.size && (is_blank(bytes.chars()[i]) || bytes.chars()[i] == '\n')) ++i;
  if (bytes.size - i >= 5 && std::memcmp(bytes.data + i, "solid", 5) == 0) return read_ascii(bytes);
  if (bytes.size < 84) fail("neither ASCII (no 'solid') nor binary (shorter than 84 bytes)");
  uint32_t n = 0;
  std::memcpy(&n, bytes.data + 80, 4);
  fail("binary header declares " + std::to_string(n) + " triangles (" + std::to_string(84 + 50 * uint64_t(n)) +
       " bytes) but the file has " + std::to_string(bytes.size) + " bytes");
}

}  // namespace pic::detail
