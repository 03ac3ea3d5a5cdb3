// An oriented point cloud as text: one point per line, "x y z nx ny nz"; '#' comments and
// blank lines are skipped. Normals are required: they tell inside from outside.
#include <string>

#include "io/readers.h"
#include "io/text.h"

namespace pic::detail {

RawGeometry read_xyz(Bytes bytes) {
  TextCursor t(bytes.chars(), bytes.chars() + bytes.size);
  RawGeometry g;
  g.point_cloud = true;
  while (!t.at_end()) {
    const size_t line = t.line();
    double v[6];
    int n = 0;
    while (true) {
      const std::string_view tok = t.token_on_line();
      if (tok.empty() || tok[0] == '#') break;
      if (n == 6) throw InvalidInput("XYZ: line " + std::to_string(line) + ": more than 6 numbers (expected x y z nx ny nz)");
      v[n++] = parse_double(tok, line);
    }
    t.skip_line();
    if (n == 0) continue;
    if (n == 3)
      throw InvalidInput("XYZ: line " + std::to_string(line) +
                         " has x y z but no normals: point clouds need normals (x y z nx ny nz) to tell inside from outside");
    if (n != 6) throw InvalidInput("XYZ: line " + std::to_string(line) + ": expected 6 numbers x y z nx ny nz, found " + std::to_string(n));
    g.positions.push_back({v[0], v[1], v[2]});
    g.normals.push_back({v[3], v[4], v[5]});
  }
  return g;
}

}  // namespace pic::detail
