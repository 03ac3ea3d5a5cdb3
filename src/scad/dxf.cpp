// DXF for import(): see dxf.h. The file is a list of (group code, value) line pairs; entities
// are read from the ENTITIES section and, for INSERT, from the BLOCKS section. Curves become
// line segments with OpenSCAD's fragment count; segments are then chained where their ends
// meet (to 1e-9 of the drawing's extent).
#include "scad/dxf.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "pic/types.h"
#include "geometry/tolerances.h"

namespace pic::detail::scad {
namespace {

struct Entity {
  std::string type, layer, block;  // block: an INSERT's block name
  std::multimap<int, double> num;  // numeric group codes in order of appearance
  std::vector<P2> vertices;        // LWPOLYLINE / POLYLINE points
  bool closed = false;
  double get(int code, double fallback = 0) const {
    const auto it = num.find(code);
    return it == num.end() ? fallback : it->second;
  }
};

struct Drawing {
  std::vector<Entity> entities;
  std::map<std::string, std::vector<Entity>> blocks;
  std::map<std::string, P2> block_base;
};

bool numeric_code(int code) { return (code >= 10 && code <= 59) || (code >= 70 && code <= 79) || (code >= 90 && code <= 99) || (code >= 210 && code <= 239); }

Drawing parse(std::istream& in, const std::string& name) {
  Drawing d;
  std::string section, code_line, value;
  std::vector<Entity>* target = nullptr;
  Entity* current = nullptr;
  std::string block_name;
  bool in_block_header = false;
  P2 pending{0, 0};
  bool have_x = false;
  while (std::getline(in, code_line) && std::getline(in, value)) {
    const auto trim = [](std::string& s) {
      s.erase(0, s.find_first_not_of(" \t\r"));
      s.erase(s.find_last_not_of(" \t\r") + 1);
    };
    trim(code_line);
    trim(value);
    char* end = nullptr;
    const long code = std::strtol(code_line.c_str(), &end, 10);
    if (end == code_line.c_str()) throw InvalidInput(name + ": malformed DXF group code '" + code_line + "'");
    if (code == 0) {
      current = nullptr;
      in_block_header = false;
      if (value == "SECTION" || value == "ENDSEC" || value == "EOF") {
        target = nullptr;
        if (value != "SECTION") section.clear();
        continue;
      }
      if (section == "BLOCKS" && value == "BLOCK") {
        in_block_header = true;
        block_name.clear();
        continue;
      }
      if (section == "BLOCKS" && value == "ENDBLK") {
        target = nullptr;
        continue;
      }
      if (value == "VERTEX" && target && !target->empty() && target->back().type == "POLYLINE") {
        current = nullptr;
        have_x = false;
        pending = {0, 0};
        // Vertices read below go to the polyline.
        current = &target->back();
        current->num.emplace(-1, 0);  // marks "reading a vertex"
        continue;
      }
      if (value == "SEQEND") continue;
      if (target || section == "ENTITIES") {
        if (!target && section == "ENTITIES") target = &d.entities;
        target->push_back(Entity{value, "", "", {}, {}, false});
        current = &target->back();
      }
      continue;
    }
    if (code == 2 && section.empty() && value != "") {
      section = value;
      if (section == "ENTITIES") target = &d.entities;
      continue;
    }
    if (in_block_header) {
      if (code == 2) {
        block_name = value;
        target = &d.blocks[block_name];
      } else if (code == 10 || code == 20) {
        d.block_base[block_name][code == 10 ? 0 : 1] = std::strtod(value.c_str(), nullptr);
      }
      continue;
    }
    if (!current) continue;
    if (code == 8) current->layer = value;
    else if (code == 2 && current->type == "INSERT") current->block = value;
    else if (numeric_code(int(code))) {
      const double v = std::strtod(value.c_str(), &end);
      if (end == value.c_str() || !std::isfinite(v)) throw InvalidInput(name + ": malformed DXF number '" + value + "'");
      const bool points = current->type == "LWPOLYLINE" || (current->type == "POLYLINE" && current->num.count(-1));
      if (points && code == 10) {
        pending[0] = v;
        have_x = true;
      } else if (points && code == 20 && have_x) {
        current->vertices.push_back({pending[0], v});
        have_x = false;
      } else if (code == 70 && (current->type == "LWPOLYLINE" || current->type == "POLYLINE") && !current->num.count(-1)) {
        current->closed = (int(v) & 1) != 0;
      } else {
        current->num.emplace(int(code), v);
      }
    }
  }
  return d;
}

// 2D affine map [a b tx; c d ty].
using Map = std::array<double, 6>;
P2 apply(const Map& m, const P2& p) { return {m[0] * p[0] + m[1] * p[1] + m[2], m[3] * p[0] + m[4] * p[1] + m[5]}; }
Map compose(const Map& a, const Map& b) {
  return {a[0] * b[0] + a[1] * b[3], a[0] * b[1] + a[1] * b[4], a[0] * b[2] + a[1] * b[5] + a[2],
          a[3] * b[0] + a[4] * b[3], a[3] * b[1] + a[4] * b[4], a[3] * b[2] + a[4] * b[5] + a[5]};
}


void arc_points(const P2& c, double r, double a0, double a1, const DxfImport& how, double stretch, std::vector<P2>& out) {
  while (a1 <= a0) a1 += 360;
  const int full = fragments_from_r(r * stretch, how.fn, how.fs, how.fa);
  const int n = std::max(1, static_cast<int>(std::ceil(full * (a1 - a0) / 360)));
  for (int i = 0; i <= n; ++i) {
    const double a = (a0 + (a1 - a0) * i / n) * std::numbers::pi / 180;
    out.push_back({c[0] + r * std::cos(a), c[1] + r * std::sin(a)});
  }
}

void collect(const Drawing& d, const std::vector<Entity>& list, const Map& m, const DxfImport& how, int depth,
             std::vector<Segment>& segs, std::vector<Ring>& rings) {
  if (depth > 16) return;  // blocks inserting themselves
  const double stretch = std::sqrt(std::abs(m[0] * m[4] - m[1] * m[3]));
  const auto polyline = [&](const std::vector<P2>& pts, bool closed) {
    for (size_t i = 0; i + 1 < pts.size(); ++i) segs.push_back({apply(m, pts[i]), apply(m, pts[i + 1])});
    if (closed && pts.size() > 2) segs.push_back({apply(m, pts.back()), apply(m, pts.front())});
  };
  for (const Entity& e : list) {
    if (e.type == "INSERT") {
      const auto it = d.blocks.find(e.block);
      if (it == d.blocks.end()) continue;
      const P2 base = d.block_base.count(e.block) ? d.block_base.at(e.block) : P2{0, 0};
      const double sx = e.get(41, 1), sy = e.get(42, 1), rot = e.get(50) * std::numbers::pi / 180;
      const double c = std::cos(rot), s = std::sin(rot);
      // Insert: translate(p) rotate(rot) scale(sx, sy) translate(-base).
      const Map local{c * sx, -s * sy, 0, s * sx, c * sy, 0};
      const P2 shift = apply(local, {-base[0], -base[1]});
      const Map place{local[0], local[1], shift[0] + e.get(10), local[3], local[4], shift[1] + e.get(20)};
      collect(d, it->second, compose(m, place), how, depth + 1, segs, rings);
      continue;
    }
    if (!how.layer.empty() && e.layer != how.layer) continue;
    if (e.type == "LINE") {
      segs.push_back({apply(m, {e.get(10), e.get(20)}), apply(m, {e.get(11), e.get(21)})});
    } else if (e.type == "LWPOLYLINE" || e.type == "POLYLINE") {
      polyline(e.vertices, e.closed);
    } else if (e.type == "CIRCLE") {
      const double r = e.get(40);
      if (!(r > 0)) continue;
      const Ring ring = circle_ring(r, fragments_from_r(r * stretch, how.fn, how.fs, how.fa));
      Ring placed;
      for (const P2& p : ring) placed.push_back(apply(m, {e.get(10) + p[0], e.get(20) + p[1]}));
      rings.push_back(std::move(placed));
    } else if (e.type == "ARC") {
      std::vector<P2> pts;
      arc_points({e.get(10), e.get(20)}, e.get(40), e.get(50), e.get(51), how, stretch, pts);
      polyline(pts, false);
    } else if (e.type == "ELLIPSE") {
      // Centre, major axis end (relative), minor/major ratio, parameter range.
      const P2 c{e.get(10), e.get(20)}, major{e.get(11), e.get(21)};
      const double ratio = e.get(40, 1), t0 = e.get(41, 0), t1 = e.get(42, 2 * std::numbers::pi);
      const double rmaj = std::hypot(major[0], major[1]);
      if (!(rmaj > 0)) continue;
      double span = t1 - t0;
      while (span <= 0) span += 2 * std::numbers::pi;
      const int n = std::max(1, static_cast<int>(std::ceil(fragments_from_r(rmaj * stretch, how.fn, how.fs, how.fa) * span /
                                                           (2 * std::numbers::pi))));
      std::vector<P2> pts;
      for (int i = 0; i <= n; ++i) {
        const double t = t0 + span * i / n, x = std::cos(t), y = std::sin(t) * ratio;
        pts.push_back({c[0] + x * major[0] - y * major[1], c[1] + x * major[1] + y * major[0]});
      }
      polyline(pts, false);
    }
  }
}

}  // namespace

Region read_dxf(const std::filesystem::path& path, const DxfImport& how) {
  std::ifstream in(path);
  if (!in) throw IoError("cannot read " + path.string());
  const Drawing d = parse(in, path.string());
  std::vector<Segment> segs;
  std::vector<Ring> rings;
  const Map m{how.scale, 0, -how.origin[0] * how.scale, 0, how.scale, -how.origin[1] * how.scale};
  collect(d, d.entities, m, how, 0, segs, rings);
  double extent = 0;
  for (const Segment& s : segs)
    for (const P2& p : s) extent = std::max({extent, std::abs(p[0]), std::abs(p[1])});
  for (Ring& r : rings_from_segments(segs, std::max(extent, 1.0) * kDxfJoin)) rings.push_back(std::move(r));
  return region_even_odd(rings);
}

}  // namespace pic::detail::scad
