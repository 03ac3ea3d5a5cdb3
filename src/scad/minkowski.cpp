// minkowski(): the sum of operands that are unions of convex parts, or of one operand with
// non-convex parts and others without, as a union of convex hulls (and moved copies) that the
// evaluator samples and unites on the octrees.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <unordered_map>

#include "mesh/clean.h"
#include "pic/measure.h"
#include "pic/volume.h"
#include "scad/lower.h"
#include "scad/region.h"
#include "geometry/tolerances.h"
#include "geometry/union_find.h"
#include "geometry/vec3.h"
#include "geometry/winding.h"

namespace pic::detail::scad {
namespace {

// Edge-neighbouring triangles on one plane (within `tol`, world units, with parallel or
// opposite normals: a sliver along a crease has its vertices on both faces' planes), in groups.
std::vector<std::vector<uint32_t>> coplanar_groups(const TriMesh& m, double tol) {
  const size_t nt = m.triangles.size();
  std::vector<Vec3> normal(nt);  // unit, or zero for a degenerate triangle
  for (size_t f = 0; f < nt; ++f) {
    const auto& t = m.triangles[f];
    const Vec3 n = cross3(sub3(m.positions[t[1]], m.positions[t[0]]), sub3(m.positions[t[2]], m.positions[t[0]]));
    const double len = norm3(n);
    normal[f] = len > 0 ? scale3(n, 1 / len) : Vec3{0, 0, 0};
  }
  std::unordered_map<uint64_t, uint32_t> by_edge;  // directed edge -> triangle
  by_edge.reserve(3 * nt);
  for (uint32_t f = 0; f < nt; ++f)
    for (int e = 0; e < 3; ++e) by_edge.emplace(uint64_t(m.triangles[f][e]) << 32 | m.triangles[f][(e + 1) % 3], f);
  UnionFind groups(nt);
  for (uint32_t f = 0; f < nt; ++f) {
    const auto& t = m.triangles[f];
    for (int e = 0; e < 3; ++e) {
      const auto it = by_edge.find(uint64_t(t[(e + 1) % 3]) << 32 | t[e]);
      // Turned-over neighbours too: a fan over a non-convex face has triangles facing back.
      if (it == by_edge.end() || std::abs(dot3(normal[f], normal[it->second])) < 1 - kFlatNeighbourCosine) continue;
      bool flat = true;
      for (uint32_t v : m.triangles[it->second])
        flat = flat && std::abs(dot3(normal[f], sub3(m.positions[v], m.positions[t[0]]))) <= tol;
      if (flat) groups.join(f, it->second);
    }
  }
  // A flat triangle (three vertices on a line) in a fan breaks the chain of neighbours: its
  // neighbours that lie in one plane are one face through it (it also touches the face that
  // meets that one along its line, which it must not join).
  const auto in_plane = [&](uint32_t f, uint32_t g) {
    if (std::abs(dot3(normal[f], normal[g])) < 1 - kFlatNeighbourCosine) return false;
    for (uint32_t v : m.triangles[g])
      if (std::abs(dot3(normal[f], sub3(m.positions[v], m.positions[m.triangles[f][0]]))) > tol) return false;
    return true;
  };
  for (uint32_t f = 0; f < nt; ++f) {
    if (normal[f] != Vec3{0, 0, 0}) continue;
    std::vector<uint32_t> near;
    for (int e = 0; e < 3; ++e) {
      const auto& t = m.triangles[f];
      const auto it = by_edge.find(uint64_t(t[(e + 1) % 3]) << 32 | t[e]);
      if (it != by_edge.end() && normal[it->second] != Vec3{0, 0, 0}) near.push_back(it->second);
    }
    for (size_t i = 0; i < near.size(); ++i)
      for (size_t j = i + 1; j < near.size(); ++j)
        if (in_plane(near[i], near[j])) groups.join(near[i], near[j]), groups.join(f, near[i]);
  }
  std::unordered_map<size_t, size_t> slot;
  std::vector<std::vector<uint32_t>> out;
  for (uint32_t f = 0; f < nt; ++f) {
    const auto [it, fresh] = slot.emplace(groups.root(f), out.size());
    if (fresh) out.emplace_back();
    out[it->second].push_back(f);
  }
  return out;
}

// One group's convex pieces: a group flat within `tol` as a whole has its union taken
// (Clipper), and an outline that is not one convex ring is cut into trapezoids; any other group
// (neighbours within `tol` of each other can drift round a finely faceted curve) is one piece
// per triangle.
void group_pieces(const TriMesh& m, const std::vector<uint32_t>& tris, double tol,
                  std::vector<std::vector<Vec3>>& out) {
  // The group's plane: the area-weighted normal through its vertices' mean.
  Vec3 n{0, 0, 0}, o{0, 0, 0};
  for (uint32_t g : tris) {
    const auto& t = m.triangles[g];
    n = add3(n, cross3(sub3(m.positions[t[1]], m.positions[t[0]]), sub3(m.positions[t[2]], m.positions[t[0]])));
    for (uint32_t k : t) o = add3(o, scale3(m.positions[k], 1.0 / double(3 * tris.size())));
  }
  const double len = norm3(n);
  bool flat = tris.size() > 1 && len > 0;
  if (flat) n = scale3(n, 1 / len);
  for (size_t i = 0; i < tris.size() && flat; ++i)
    for (uint32_t k : m.triangles[tris[i]]) flat = flat && std::abs(dot3(n, sub3(m.positions[k], o))) <= tol;
  if (!flat) {
    for (uint32_t g : tris) {
      const auto& t = m.triangles[g];
      out.push_back({m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]});
    }
    return;
  }
  const Vec3 seed = std::abs(n[0]) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  Vec3 u = cross3(n, seed);
  u = scale3(u, 1 / norm3(u));
  const Vec3 v = cross3(n, u);
  Region shadow;
  for (uint32_t g : tris) {
    Ring ring;
    for (uint32_t k : m.triangles[g]) {
      const Vec3 d = sub3(m.positions[k], o);
      ring.push_back({dot3(d, u), dot3(d, v)});
    }
    // Kept as oriented: a non-convex face triangulated as a fan has triangles turned against
    // the face that cancel the others' overhang, and the union counts winding.
    shadow.push_back(std::move(ring));
  }
  const Region outline = without_straight_vertices(region_union({shadow}), tol);
  if (outline.size() == 1 && convex_ring(outline[0])) {
    // The group's own vertices: their hull is the outline, without Clipper's rounding.
    std::vector<Vec3> pts;
    for (uint32_t g : tris)
      for (uint32_t k : m.triangles[g]) pts.push_back(m.positions[k]);
    out.push_back(std::move(pts));
    return;
  }
  for (const Ring& r : convex_pieces(outline)) {
    std::vector<Vec3> pts;
    for (const P2& p : r) pts.push_back(add3(o, add3(scale3(u, p[0]), scale3(v, p[1]))));
    out.push_back(std::move(pts));
  }
}

/// Convex planar polygons covering a surface, each within `tol` of it: one hull per face of a
/// polyhedral solid in a sum, not one per triangle of its contour.
std::vector<std::vector<Vec3>> planar_pieces(const TriMesh& m, double tol) {
  std::vector<std::vector<Vec3>> out;
  for (const auto& tris : coplanar_groups(m, tol)) group_pieces(m, tris, tol, out);
  return out;
}

/// planar_pieces of a surface, flat within 1e-6 of its extent: float contour vertices on a
/// flat face sit within ~1e-7 of a cell of its plane. (Faces of a tessellated curve are not
/// recovered at any useful tolerance: the contour's vertices between them are the sampler's,
/// not the facets'.)
std::vector<std::vector<Vec3>> surface_pieces(const TriMesh& m) {
  const auto [lo, hi] = box_of(m.positions);
  return planar_pieces(m, kFlatFaceTolerance * norm3(sub3(hi, lo)));
}

// One part of a minkowski operand: a convex point set (its hull), or a closed non-convex
// surface.
struct Part {
  std::vector<Vec3> points;  // convex: the hull's vertices
  TriMesh surface;           // non-convex (empty when convex)
  bool convex() const { return surface.triangles.empty(); }
};

Part surface_part(const TriMesh& m) {
  if (is_convex(m)) return {convex_hull(m.positions).positions, {}};
  return {{}, m};
}

// ---- convex decomposition of differences and intersections of convex parts ----------------

using Convex = std::vector<Vec3>;  // a convex polytope: its hull's vertices

// Each part of a sum is sampled and united on its own (tens of milliseconds): an operand with
// more pieces than this is refused at once rather than left running for minutes (a difference
// that decomposes into more falls back to its contour's flat faces first).
constexpr size_t kMaxPieces = 4000;
// A decomposition's pieces overlap and are large (a sphere minus a ball would give one piece
// per face of the ball): past this many, the contour's flat faces serve better.
constexpr size_t kMaxConvexPieces = 256;

// A direction along which every vertex lies on one of two planes: a triangle's normal, the
// largest triangles first (a cap's; a wall's fails unless the prism is a box).
std::optional<Vec3> prism_axis(const TriMesh& m, double eps) {
  std::vector<std::pair<double, Vec3>> normals;
  for (const auto& t : m.triangles) {
    const Vec3 n = cross3(sub3(m.positions[t[1]], m.positions[t[0]]), sub3(m.positions[t[2]], m.positions[t[0]]));
    if (const double a = norm3(n); a > 0) normals.push_back({a, scale3(n, 1 / a)});
  }
  std::sort(normals.begin(), normals.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  for (size_t i = 0; i < normals.size() && i < 16; ++i) {
    const Vec3& axis = normals[i].second;
    double z0 = kHuge, z1 = -kHuge;
    for (const Vec3& p : m.positions) z0 = std::min(z0, dot3(axis, p)), z1 = std::max(z1, dot3(axis, p));
    bool two = z1 - z0 > eps;
    for (size_t k = 0; k < m.positions.size() && two; ++k) {
      const double z = dot3(axis, m.positions[k]);
      two = std::abs(z - z0) <= eps || std::abs(z - z1) <= eps;
    }
    if (two) return axis;
  }
  return std::nullopt;
}

// Whether two point sets are the same within eps.
bool same_points(std::vector<P2> a, std::vector<P2> b, double eps) {
  for (auto* v : {&a, &b}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::abs(a[i][0] - b[i][0]) > eps || std::abs(a[i][1] - b[i][1]) > eps) return false;
  return true;
}

/// A right prism (every vertex on one of two parallel planes, the two caps the same outline:
/// a linear extrusion without twist or scale, however it was moved) as convex prisms over the
/// convex pieces of its cap. False for any other mesh.
bool prism_pieces(const TriMesh& m, double eps, std::vector<Convex>& out) {
  const std::optional<Vec3> found = prism_axis(m, eps);
  if (!found) return false;
  const Vec3 axis = *found;
  double z0 = kHuge, z1 = -kHuge;
  for (const Vec3& p : m.positions) z0 = std::min(z0, dot3(axis, p)), z1 = std::max(z1, dot3(axis, p));
  const Vec3 seed = std::abs(axis[0]) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  Vec3 u = cross3(axis, seed);
  u = scale3(u, 1 / norm3(u));
  const Vec3 v = cross3(axis, u);
  std::vector<P2> bottom, top;
  for (const Vec3& p : m.positions) {
    const double z = dot3(axis, p);
    const P2 q{dot3(u, p), dot3(v, p)};
    if (std::abs(z - z0) <= eps) bottom.push_back(q);
    else if (std::abs(z - z1) <= eps) top.push_back(q);
    else return false;  // a vertex between the caps: twisted, scaled in slices, or no prism
  }
  if (!same_points(bottom, top, eps)) return false;
  // The cap: the union of the triangles on the bottom plane, counted by winding. Each keeps its
  // orientation: a non-convex face triangulated as a fan has triangles turned against the face
  // that cancel the others' overhang (turned one by one, they would fill its notches).
  Region cap;
  for (const auto& t : m.triangles) {
    bool on = true;
    for (uint32_t k : t) on = on && std::abs(dot3(axis, m.positions[k]) - z0) <= eps;
    if (!on) continue;
    Ring ring;
    for (uint32_t k : t) ring.push_back({dot3(u, m.positions[k]), dot3(v, m.positions[k])});
    cap.push_back(std::move(ring));
  }
  const Region outline = region_union({cap});
  // The prism's volume must be the cap's area times its height (else the walls are not the
  // cap's outline moved straight up: a mesh with the same vertices but other faces).
  if (std::abs(region_area(outline) * (z1 - z0) - volume(m)) > kPrismVolume * std::abs(volume(m))) return false;
  for (const Ring& r : convex_pieces(outline)) {
    Convex c;
    for (const P2& q : r) {
      const Vec3 base = add3(scale3(u, q[0]), scale3(v, q[1]));
      c.push_back(add3(base, scale3(axis, z0)));
      c.push_back(add3(base, scale3(axis, z1)));
    }
    out.push_back(std::move(c));
  }
  return true;
}

// The part of a convex polytope on one side of a plane, as a hull (empty when none).
TriMesh hull_of_side(const TriMesh& hull, const Plane& p, bool outside, double eps) {
  const Convex c = clip_convex(hull, p, outside, eps);
  return c.empty() ? TriMesh{} : convex_hull(c);
}

// P n Q for convex P and Q: P clipped by each face of Q.
void intersect_convex(const Convex& part, const std::vector<Plane>& q_faces, double eps, std::vector<Convex>& out) {
  TriMesh cut = convex_hull(part);
  for (const Plane& pl : q_faces) {
    cut = hull_of_side(cut, pl, false, eps);
    if (cut.triangles.empty()) return;
  }
  out.push_back(cut.positions);
}

// P - Q for convex P and Q: outside Q's box, P in up to six slabs; inside it, P beyond each of
// Q's faces (a point outside Q is beyond one of them). Splitting only the part inside the box
// keeps a plate with holes in a row from being split by every hole once per piece of the
// others.
void subtract_convex(const Convex& part, const Convex& q, const std::vector<Plane>& q_faces, double eps,
                     std::vector<Convex>& out) {
  const auto [lo, hi] = box_of(q);
  if (boxes_apart(box_of(part), {lo, hi})) {
    out.push_back(part);
    return;
  }
  TriMesh rest = convex_hull(part);
  for (int k = 0; k < 3; ++k) {
    Vec3 axis{0, 0, 0};
    axis[k] = 1;
    for (const Plane& side : {Plane{scale3(axis, -1), -lo[k]}, Plane{axis, hi[k]}}) {
      if (Convex c = clip_convex(rest, side, true, eps); !c.empty()) out.push_back(std::move(c));
      rest = hull_of_side(rest, side, false, eps);
      if (rest.triangles.empty()) return;
    }
  }
  for (const Plane& pl : q_faces)
    if (Convex c = clip_convex(rest, pl, true, eps); !c.empty()) out.push_back(std::move(c));
}

// ---- convex decomposition of a non-convex polyhedron by its reflex edges' planes ----------

// A reflex edge (the solid's angle there over 180 degrees) and the plane of one of its faces:
// on either side of that plane the edge is no longer reflex.
struct ReflexEdge {
  Vec3 a, b;
  Plane cut;
};

// Triangle f's normal scaled by twice its area.
Vec3 area_normal(const TriMesh& m, uint32_t f) {
  const auto& t = m.triangles[f];
  return cross3(sub3(m.positions[t[1]], m.positions[t[0]]), sub3(m.positions[t[2]], m.positions[t[0]]));
}

// A surface's flat groups (coplanar_groups) and per triangle its face's outward unit normal:
// its flat group's (a non-convex face fanned into triangles that partly face back still has
// one), else its own; zero for a degenerate triangle alone.
struct Faces {
  std::vector<std::vector<uint32_t>> groups;
  std::vector<Vec3> normal;
};

Faces faces_of(const TriMesh& m, double tol) {
  Faces out{coplanar_groups(m, tol), std::vector<Vec3>(m.triangles.size())};
  for (const auto& g : out.groups) {
    Vec3 n{0, 0, 0};
    for (uint32_t f : g) n = add3(n, area_normal(m, f));
    const double len = norm3(n);
    bool flat = len > 0;
    if (flat) n = scale3(n, 1 / len);
    const Vec3& o = m.positions[m.triangles[g[0]][0]];
    for (uint32_t f : g)
      for (uint32_t k : m.triangles[f]) flat = flat && std::abs(dot3(n, sub3(m.positions[k], o))) <= tol;
    for (uint32_t f : g) {
      const Vec3 own = area_normal(m, f);
      const double l = norm3(own);
      out.normal[f] = flat ? n : l > 0 ? scale3(own, 1 / l) : Vec3{0, 0, 0};
    }
  }
  return out;
}

// The reflex edges of a closed, consistently oriented surface, or false when an edge is open
// or shared by more than two triangles.
bool reflex_edges(const TriMesh& m, const Faces& faces, double tol, std::vector<ReflexEdge>& out) {
  const std::vector<Vec3>& normal = faces.normal;
  std::unordered_map<uint64_t, uint32_t> by_edge;  // directed edge -> triangle
  const auto key = [](uint32_t a, uint32_t b) { return uint64_t(a) << 32 | b; };
  for (uint32_t f = 0; f < m.triangles.size(); ++f)
    for (int e = 0; e < 3; ++e)
      if (!by_edge.emplace(key(m.triangles[f][e], m.triangles[f][(e + 1) % 3]), f).second) return false;
  for (uint32_t f = 0; f < m.triangles.size(); ++f)
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = m.triangles[f][e], b = m.triangles[f][(e + 1) % 3];
      const auto twin = by_edge.find(key(b, a));
      if (twin == by_edge.end()) return false;
      const uint32_t g = twin->second;
      if (a > b || normal[f] == normal[g]) continue;  // each edge once; none inside a flat face
      // Face B turns from the edge, within its plane, along w = n_B x (a - b) (B holds b -> a):
      // above A's plane, the solid's angle at the edge is over 180 degrees.
      const Vec3 &pa = m.positions[a], &pb = m.positions[b];
      const Vec3 w = cross3(normal[g], sub3(pa, pb));
      if (dot3(normal[f], w) > tol * norm3(w)) out.push_back({pa, pb, {normal[f], dot3(normal[f], pa)}});
    }
  return true;
}

// Whether the segment ab passes through the inside of the convex cell (its face planes) by
// more than eps.
bool crosses_inside(const Vec3& a, const Vec3& b, const std::vector<Plane>& cell, double eps) {
  double t0 = 0, t1 = 1;
  for (const Plane& p : cell) {
    const double fa = dot3(p.n, a) - p.d + eps, fb = dot3(p.n, b) - p.d + eps;  // <= 0 inside
    if (fa > 0 && fb > 0) return false;
    if (fa > 0) t0 = std::max(t0, fa / (fa - fb));
    else if (fb > 0) t1 = std::min(t1, fa / (fa - fb));
  }
  return (t1 - t0) * norm3(sub3(b, a)) > eps;
}

// Clips a convex polygon (a ring) to n.x <= d.
std::vector<Vec3> clip_polygon(const std::vector<Vec3>& poly, const Plane& p) {
  std::vector<Vec3> out;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec3 &x = poly[i], &y = poly[(i + 1) % poly.size()];
    const double fx = dot3(p.n, x) - p.d, fy = dot3(p.n, y) - p.d;
    if (fx <= 0) out.push_back(x);
    if ((fx < 0 && fy > 0) || (fx > 0 && fy < 0)) out.push_back(add3(x, scale3(sub3(y, x), fx / (fx - fy))));
  }
  return out;
}

// Twice a ring's vector area.
Vec3 ring_area2(const std::vector<Vec3>& ring) {
  Vec3 a{0, 0, 0};
  for (size_t i = 0; i < ring.size(); ++i) a = add3(a, cross3(ring[i], ring[(i + 1) % ring.size()]));
  return a;
}

// A flat face's convex piece as a ring, with the face's outward normal.
struct FacePiece {
  std::vector<Vec3> ring;
  Vec3 normal;
};

// The surface's convex face pieces (planar_pieces, group by group) as rings about their
// centroids, each with its face's outward normal.
std::vector<FacePiece> face_rings(const TriMesh& m, const Faces& faces, double tol) {
  std::vector<FacePiece> out;
  const std::vector<Vec3>& normal = faces.normal;
  for (const auto& tris : faces.groups) {
    // Triangles that all face out tile their face exactly as they are; a fan with triangles
    // facing back is the union of its triangles by winding (group_pieces, rounded by Clipper).
    const bool facing_out =
        std::all_of(tris.begin(), tris.end(), [&](uint32_t f) { return dot3(normal[f], area_normal(m, f)) > 0; });
    std::vector<std::vector<Vec3>> pieces;
    if (facing_out) {
      for (uint32_t f : tris) {
        const auto& t = m.triangles[f];
        pieces.push_back({m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]});
      }
    } else {
      group_pieces(m, tris, tol, pieces);
    }
    for (size_t i = 0; i < pieces.size(); ++i) {
      // One piece per triangle, in order, or pieces of one flat face sharing its normal.
      const Vec3 n = normal[tris[pieces.size() == tris.size() ? i : 0]];
      if (n == Vec3{0, 0, 0}) continue;
      const Vec3 u = cross3(n, std::abs(n[0]) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}), v = cross3(n, u);
      std::vector<Vec3>& pts = pieces[i];
      Vec3 c{0, 0, 0};
      for (const Vec3& p : pts) c = add3(c, scale3(p, 1.0 / double(pts.size())));
      const auto angle = [&](const Vec3& p) { return std::atan2(dot3(sub3(p, c), v), dot3(sub3(p, c), u)); };
      std::sort(pts.begin(), pts.end(), [&](const Vec3& a, const Vec3& b) { return angle(a) < angle(b); });
      pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
      out.push_back({std::move(pts), n});
    }
  }
  return out;
}

// The convex cells a BSP by reflex-edge planes leaves around a solid (each its planes,
// n.x <= d), split until no reflex edge passes through a cell's inside: there the solid is
// locally convex, so each of its connected parts in the cell is convex. False past
// `max_cells`.
bool reflex_cells(const std::vector<Plane>& cell, const std::vector<ReflexEdge>& edges, std::vector<uint32_t> left,
                  double eps, size_t max_cells, std::vector<std::vector<Plane>>& out) {
  std::erase_if(left, [&](uint32_t e) { return !crosses_inside(edges[e].a, edges[e].b, cell, eps); });
  if (left.empty()) {
    out.push_back(cell);
    return out.size() <= max_cells;
  }
  const Plane& cut = edges[left.front()].cut;
  for (const Plane& side : {cut, Plane{scale3(cut.n, -1), -cut.d}}) {
    std::vector<Plane> half = cell;
    half.push_back(side);
    if (!reflex_cells(half, edges, left, eps, max_cells, out)) return false;
  }
  return true;
}

// The corners of a cell: where three of its planes meet, within eps of every other.
std::vector<Vec3> cell_corners(const std::vector<Plane>& cell, double eps) {
  std::vector<Vec3> out;
  for (size_t i = 0; i < cell.size(); ++i)
    for (size_t j = i + 1; j < cell.size(); ++j)
      for (size_t k = j + 1; k < cell.size(); ++k) {
        const Plane &a = cell[i], &b = cell[j], &c = cell[k];
        const Vec3 bc = cross3(b.n, c.n), ca = cross3(c.n, a.n), ab = cross3(a.n, b.n);
        const double det = dot3(a.n, bc);
        if (std::abs(det) < kSamePlaneCosine) continue;
        const Vec3 x = scale3(add3(add3(scale3(bc, a.d), scale3(ca, b.d)), scale3(ab, c.d)), 1 / det);
        if (std::all_of(cell.begin(), cell.end(), [&](const Plane& p) { return dot3(p.n, x) <= p.d + eps; }))
          out.push_back(x);
      }
  return out;
}

// Joins pieces with disjoint insides two by two where their union is convex (its hull adds no
// more than `slack` of volume), until no two join: a BSP cuts through parts that need no cut
// (a plane through one slice of an extrusion cuts every slice), and each piece left costs a
// hull per piece of the other operand.
void merge_convex_unions(std::vector<Convex>& pieces, double slack) {
  std::vector<double> vol(pieces.size());
  std::vector<std::array<Vec3, 2>> box(pieces.size());
  for (size_t i = 0; i < pieces.size(); ++i) vol[i] = volume(convex_hull(pieces[i])), box[i] = box_of(pieces[i]);
  for (bool joined = true; joined;) {
    joined = false;
    for (size_t i = 0; i < pieces.size(); ++i)
      for (size_t j = i + 1; j < pieces.size(); ++j) {
        if (boxes_apart(box[i], box[j])) continue;
        Convex both = pieces[i];
        both.insert(both.end(), pieces[j].begin(), pieces[j].end());
        const TriMesh hull = convex_hull(both);
        const double v = volume(hull);
        if (!(v - vol[i] - vol[j] <= slack)) continue;
        pieces[i] = hull.positions, vol[i] = v, box[i] = box_of(pieces[i]);
        pieces.erase(pieces.begin() + long(j)), vol.erase(vol.begin() + long(j)), box.erase(box.begin() + long(j));
        joined = true;
        --j;
      }
  }
}

// The corners of the solid's part in a convex cell (its planes): its faces' pieces clipped to
// the cell and the cell's corners inside the solid.
Convex solid_in_cell(const TriMesh& m, const std::vector<FacePiece>& faces, const std::vector<Plane>& planes,
                     double eps, double extent) {
  Convex points;
  for (const FacePiece& face : faces) {
    std::vector<Vec3> poly = face.ring;
    for (size_t k = 0; k < planes.size() && !poly.empty(); ++k) poly = clip_polygon(poly, planes[k]);
    // The part is the closure of the solid's inside: a face met only along a line, or lying
    // on the cell's side with the solid beyond it, is no part of it.
    if (norm3(ring_area2(poly)) <= eps * extent) continue;
    const bool beyond = std::any_of(planes.begin(), planes.end(), [&](const Plane& pl) {
      return dot3(pl.n, face.normal) < 0 &&
             std::all_of(poly.begin(), poly.end(), [&](const Vec3& x) { return std::abs(dot3(pl.n, x) - pl.d) <= eps; });
    });
    if (!beyond) points.insert(points.end(), poly.begin(), poly.end());
  }
  for (const Vec3& corner : cell_corners(planes, eps)) {
    double w = 0;
    for (const auto& t : m.triangles) w += triangle_winding(corner, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]);
    if (w > 0.75) points.push_back(corner);  // 1 inside, 1/2 on the surface (a face's piece has it)
  }
  return points;
}

// A closed, non-convex polyhedron as convex polytopes with disjoint insides whose union it is:
// the solid in each cell of a BSP by its reflex edges' planes, each the hull of its faces'
// pieces clipped to the cell and the cell's corners inside it. A cell may still hold two
// convex parts apart, whose hull fills the gap between them: the hulls' volumes must add up
// to the solid's (they can only exceed it), else false, as past `max_pieces`.
bool reflex_pieces(const TriMesh& mesh, double eps, size_t max_pieces, std::vector<Convex>& out) {
  const TriMesh m = weld(mesh);
  const double solid = volume(m);
  const Faces faces = faces_of(m, eps);
  std::vector<ReflexEdge> edges;
  if (!(solid > 0) || !reflex_edges(m, faces, eps, edges) || edges.empty() || edges.size() > max_pieces) return false;
  const auto [lo, hi] = box_of(m.positions);
  const double extent = norm3(sub3(hi, lo));
  std::vector<Plane> box;
  for (int k = 0; k < 3; ++k) {
    Vec3 axis{0, 0, 0};
    axis[k] = 1;
    box.push_back({axis, hi[k] + 0.01 * extent});
    box.push_back({scale3(axis, -1), -(lo[k] - 0.01 * extent)});
  }
  std::vector<uint32_t> all(edges.size());
  for (uint32_t e = 0; e < all.size(); ++e) all[e] = e;
  std::vector<std::vector<Plane>> cells;
  if (!reflex_cells(box, edges, all, eps, 4 * max_pieces, cells)) return false;
  const std::vector<FacePiece> rings = face_rings(m, faces, eps);
  std::vector<Convex> pieces;
  double total = 0;
  for (const std::vector<Plane>& planes : cells) {
    const Convex points = solid_in_cell(m, rings, planes, eps, extent);
    const TriMesh hull = points.size() < 4 ? TriMesh{} : convex_hull(points);
    const double v = hull.triangles.empty() ? 0 : volume(hull);
    if (!(v > 0)) continue;
    total += v;
    pieces.push_back(hull.positions);
    if (pieces.size() > max_pieces) return false;
  }
  if (!(std::abs(total - solid) <= kPieceVolume * solid)) return false;
  merge_convex_unions(pieces, kPieceVolume * solid);
  out.insert(out.end(), pieces.begin(), pieces.end());
  return true;
}

/// The solid as convex polytopes whose union it is (they may overlap), or false: a leaf that
/// is neither convex nor a prism, a hull of a difference, too many pieces.
bool convex_decomposition(const Solid& s, double eps, std::vector<Convex>& out) {
  switch (s.kind) {
    case Solid::Kind::Empty: return true;
    case Solid::Kind::Mesh:
      if (is_convex(s.mesh)) {
        out.push_back(convex_hull(s.mesh.positions).positions);
        return true;
      }
      if (prism_pieces(s.mesh, eps, out)) return out.size() <= kMaxConvexPieces;
      return reflex_pieces(s.mesh, eps, kMaxConvexPieces, out) && out.size() <= kMaxConvexPieces;
    case Solid::Kind::Union:
      for (const Solid& c : s.children)
        if (!convex_decomposition(c, eps, out)) return false;
      return out.size() <= kMaxConvexPieces;
    case Solid::Kind::Hull: {  // convex whatever its children, when they are meshes
      std::vector<Vec3> points;
      if (!hull_points(s, points)) return false;
      const TriMesh hull = convex_hull(points);
      if (!hull.triangles.empty()) out.push_back(hull.positions);
      return out.size() <= kMaxConvexPieces;
    }
    case Solid::Kind::Difference:
    case Solid::Kind::Intersect: {
      const bool difference = s.kind == Solid::Kind::Difference;
      std::vector<Convex> parts;
      if (s.children.empty() || !convex_decomposition(s.children[0], eps, parts)) return false;
      for (size_t i = 1; i < s.children.size(); ++i) {
        std::vector<Convex> cutters;
        if (!convex_decomposition(s.children[i], eps, cutters)) return false;
        if (!difference && cutters.size() != 1) return false;  // A n (B u C): not needed yet
        for (const Convex& q : cutters) {
          const std::vector<Plane> q_faces = face_planes(convex_hull(q));
          std::vector<Convex> next;
          for (const Convex& part : parts) {
            if (difference) subtract_convex(part, q, q_faces, eps, next);
            else intersect_convex(part, q_faces, eps, next);
          }
          if (next.size() > kMaxConvexPieces) return false;
          parts = std::move(next);
        }
      }
      out.insert(out.end(), parts.begin(), parts.end());
      return out.size() <= kMaxConvexPieces;
    }
    default: return false;
  }
}

// The solid as a union of parts: convex polytopes where it decomposes into few, else its
// surface (a leaf's mesh, or the subtree evaluated on octrees and contoured).
void parts_of(const Solid& s, const EvalOptions& o, std::vector<Part>& out) {
  if (s.kind == Solid::Kind::Empty) return;
  if (s.kind == Solid::Kind::Union) {
    for (const Solid& c : s.children) parts_of(c, o, out);
    return;
  }
  Vec3 lo{kHuge, kHuge, kHuge}, hi{-kHuge, -kHuge, -kHuge};
  size_t leaves = 0, triangles = 0;
  solid_bounds(s, lo, hi, leaves, triangles);
  std::vector<Convex> convex_parts;
  if (convex_decomposition(s, kOnPlane * norm3(sub3(hi, lo)), convex_parts)) {
    for (Convex& c : convex_parts) out.push_back({std::move(c), {}});
    return;
  }
  if (s.kind == Solid::Kind::Mesh) {
    out.push_back({{}, s.mesh});  // not convex: the decomposition took a convex leaf whole
    return;
  }
  const TriMesh m = solid_surface(s, o);
  if (!m.triangles.empty()) out.push_back(surface_part(m));
}

std::vector<Vec3> sums(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  std::vector<Vec3> out;
  out.reserve(a.size() * b.size());
  for (const Vec3& p : a)
    for (const Vec3& q : b) out.push_back(add3(p, q));
  return out;
}

// A non-convex solid N plus a convex C: every x = n + c of the sum either has x - c0 in N or,
// walking c from c0 to c inside C, x - c crosses N's surface. So N + C is N moved by any c0 of
// C together with each planar piece of N's surface plus C (a convex hull).
void add_sum(const TriMesh& n, const std::vector<Vec3>& c, std::vector<Part>& out) {
  // c0: the centroid of C's vertices, inside C, so that N + c0 shares no face with a hull
  // (flush faces of opposite sides are where a sampled union is least certain).
  Vec3 c0{0, 0, 0};
  for (const Vec3& p : c) c0 = add3(c0, scale3(p, 1.0 / double(c.size())));
  Part moved{{}, n};
  for (Vec3& p : moved.surface.positions) p = add3(p, c0);
  out.push_back(std::move(moved));
  const auto pieces = surface_pieces(n);
  if (pieces.size() > kMaxPieces)
    throw InvalidInput("a non-convex operand with " + std::to_string(pieces.size()) +
                       " planar pieces (curved faces) is not supported: at most " + std::to_string(kMaxPieces));
  for (const auto& piece : pieces) out.push_back({convex_hull(sums(piece, c)).positions, {}});
}

// A point on each connected piece of a closed surface (a soup's triangles are one piece where
// they share a position).
std::vector<Vec3> point_per_shell(const TriMesh& surface) {
  const TriMesh m = weld(surface);
  UnionFind shells(m.positions.size());
  for (const auto& t : m.triangles) shells.join(t[0], t[1]), shells.join(t[1], t[2]);
  std::vector<Vec3> out;
  std::vector<char> seen(m.positions.size(), 0);
  for (const auto& t : m.triangles)
    if (const size_t r = shells.root(t[0]); !seen[r]) {
      seen[r] = 1;
      out.push_back(m.positions[t[0]]);
    }
  return out;
}

// Two non-convex solids N and M: for x = n + m of the sum, the surface of x - M either meets
// N's surface (x is in dN + dM) or a whole shell of it lies inside N (x is in N moved by a
// point of that shell), or else a whole shell of N lies inside x - M (x is in M moved by a point
// of that shell) -- a path in N from n to N's surface would otherwise cross x - M's surface
// inside N. So N + M is N moved by a point of each shell of M, M moved by a point of each shell
// of N, and every planar piece of dN plus every planar piece of dM (convex hulls).
void add_sum(const TriMesh& n, const TriMesh& m, std::vector<Part>& out) {
  for (const auto& [from, by] : {std::pair{&n, &m}, std::pair{&m, &n}})
    for (const Vec3& c : point_per_shell(*by)) {
      Part moved{{}, *from};
      for (Vec3& p : moved.surface.positions) p = add3(p, c);
      out.push_back(std::move(moved));
    }
  const auto pn = surface_pieces(n), pm = surface_pieces(m);
  if (pn.size() * pm.size() > kMaxPieces)
    throw InvalidInput("the sum of two non-convex operands with " + std::to_string(pn.size()) + " and " +
                       std::to_string(pm.size()) + " planar pieces needs more than " + std::to_string(kMaxPieces) +
                       " convex hulls: not supported");
  for (const auto& a : pn)
    for (const auto& b : pm) out.push_back({convex_hull(sums(a, b)).positions, {}});
}

// The parts as a solid: their hulls or surfaces, unioned on the octrees.
Solid part_solid(const std::vector<Part>& parts) {
  Solid out;
  out.kind = Solid::Kind::Union;
  for (const Part& p : parts) {
    Solid leaf;
    leaf.kind = Solid::Kind::Mesh;
    leaf.mesh = p.convex() ? convex_hull(p.points) : p.surface;
    if (!leaf.mesh.triangles.empty()) out.children.push_back(std::move(leaf));
  }
  if (out.children.empty()) return {};
  if (out.children.size() == 1) return std::move(out.children[0]);
  return out;
}

}  // namespace

Solid minkowski(const std::vector<Solid>& operands, const EvalOptions& o, bool exact_only) {
  std::vector<std::vector<Part>> all;
  std::vector<const Solid*> given;
  for (const Solid& s : operands) {
    if (s.kind == Solid::Kind::Empty) continue;
    std::vector<Part> parts;
    parts_of(s, o, parts);
    // An operand with no solid in it (an intersection of parts apart) is left out, as
    // OpenSCAD leaves out an empty child: the sum of the others, not nothing.
    if (parts.empty()) continue;
    all.push_back(std::move(parts));
    given.push_back(&s);
  }
  // A solid that is not one convex part plus a faceted sphere: one distance sampling instead
  // of a hull per convex part, or per surface triangle of a non-convex one (below).
  if (!exact_only && all.size() == 2)
    for (int k = 0; k < 2; ++k) {
      const std::vector<Part>& body = all[k];
      const std::vector<Part>& other = all[1 - k];
      if (body.size() != 1 || !body[0].convex() || !is_round_body(body[0].points)) continue;
      if (other.size() == 1 && other[0].convex()) continue;  // one hull, exact
      Solid sum;
      sum.kind = Solid::Kind::RoundSum;
      if (other.size() == 1) {
        Solid leaf;
        leaf.kind = Solid::Kind::Mesh;
        leaf.mesh = other[0].surface;
        sum.children.push_back(std::move(leaf));
      } else {
        sum.children.push_back(*given[1 - k]);
      }
      sum.body = body[0].points;
      return sum;
    }
  std::vector<Part> acc;
  bool first = true, single = true;
  const Solid* only = nullptr;
  for (size_t i = 0; i < given.size(); ++i) {
    std::vector<Part> parts = std::move(all[i]);
    only = given[i];
    if (first) {
      acc = std::move(parts);
      first = false;
      continue;
    }
    single = false;
    // (A1 u A2) + (B1 u B2) = union of Ai + Bj; a convex sum is the hull of vertex sums.
    std::vector<Part> next;
    for (const Part& a : acc)
      for (const Part& b : parts) {
        if (a.convex() && b.convex()) next.push_back({convex_hull(sums(a.points, b.points)).positions, {}});
        else if (a.convex()) add_sum(b.surface, a.points, next);
        else if (b.convex()) add_sum(a.surface, b.points, next);
        else add_sum(a.surface, b.surface, next);
        if (next.size() > kMaxPieces)
          throw InvalidInput("the sum has more than " + std::to_string(kMaxPieces) + " convex parts");
      }
    acc = std::move(next);
  }
  // One operand is itself (its convex parts as hulls, as before).
  if (single && only && std::any_of(acc.begin(), acc.end(), [](const Part& p) { return !p.convex(); })) return *only;
  return part_solid(acc);
}

}  // namespace pic::detail::scad
