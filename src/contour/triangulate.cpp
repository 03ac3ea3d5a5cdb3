// Triangulating the dual polygons so that no two triangles cross, by construction (after Ju
// and Udeshi 2006, "Intersection-free contouring on an octree grid").
//
// The argument. Every vertex lies strictly inside its cell. Each polygon side a b crosses the
// common face of a's and b's cells at one point Q (the segment's own crossing when that is
// inside the face, else a face point: the side is then split there); all polygons with that
// side share Q. A polygon dual to minimal edge e owns, in each cell c_i around e with vertex
// v_i, the tetrahedra (v_i, Q, e) over the two faces of c_i next to e. Inside one cell these
// are cones from v_i over the triangles (Q, e) of its faces, and those triangles tile the faces
// without overlapping, so different polygons' regions meet only on their boundaries. A fan
// around a point p strictly inside e, with triangles (p, v_i, Q) and (p, Q, v_i+1), lies in
// its region. Written as a ring of points around e (the vertices, with each side's face
// point between its two), the region is the ring of tetrahedra (e, r_i, r_i+1): with no face
// point, tetrahedra (v_i, Q, e) and (v_i+1, Q, e) make up (e, v_i, v_i+1) as Q lies on the
// side. The plain split is kept when every side crosses its face and both its triangles lie
// in that ring, strictly inside except along the polygon's own sides; a polygon with face
// points becomes a fan from one of its ring's points when that fan lies in the ring; else a
// fan around p. So triangles of different polygons meet only in shared vertices and sides.
#include "contour/triangulate.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <unordered_map>

#include <tbb/parallel_for.h>

#include "geometry/root.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"

namespace pic::detail {
namespace {

using Tri = std::array<uint32_t, 3>;
using Split = std::array<std::array<int, 3>, 2>;
constexpr uint32_t kNone = ~uint32_t{0};
constexpr int kMaxRing = 8;  // a quad with all four sides split at face points

inline double cross2(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

// The common face of two cells that touch across a face: its axis, plane and extent.
struct Face {
  int axis = -1;  // -1: the cells share no face
  double plane = 0;
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};
};

Face common_face(const VertexCell& ca, const VertexCell& cb) {
  Face f;
  // The axis across the face: where the cells touch (centres half + half apart).
  int axis = 0;
  double best = -kHuge;
  for (int d = 0; d < 3; ++d) {
    const double gap = std::abs(cb.center[d] - ca.center[d]) - (ca.half + cb.half);
    if (gap > best) {
      best = gap;
      axis = d;
    }
  }
  if (std::abs(best) > kTouchingCellsGap * (ca.half + cb.half)) return f;
  for (int d = 0; d < 3; ++d) {
    if (d == axis) continue;
    f.lo[d] = std::max(ca.center[d] - ca.half, cb.center[d] - cb.half);
    f.hi[d] = std::min(ca.center[d] + ca.half, cb.center[d] + cb.half);
    if (!(f.hi[d] > f.lo[d])) return f;  // the cells touch along an edge only
  }
  f.axis = axis;
  f.plane = ca.center[axis] + (cb.center[axis] > ca.center[axis] ? ca.half : -ca.half);
  return f;
}

// Where segment xa xb meets the face's plane (q); true when that lies more than `margin` inside
// the face. The margin keeps a crossing that is on the face's border in exact arithmetic (a
// vertex clamped onto its cell's edge, in line with a neighbour's vertex) from passing for
// inside by a rounding error: such a side gets a face point instead.
bool crosses_inside(const Face& face, const Vec3& xa, const Vec3& xb, Vec3& q, double margin = 0) {
  const int axis = face.axis;
  const double den = xb[axis] - xa[axis];
  const double t = den != 0 ? std::clamp((face.plane - xa[axis]) / den, 0.0, 1.0) : 0.5;
  bool inside = true;
  for (int d = 0; d < 3; ++d) {
    q[d] = xa[d] + t * (xb[d] - xa[d]);
    if (d != axis) inside = inside && q[d] > face.lo[d] + margin && q[d] < face.hi[d] - margin;
  }
  return inside;
}

// Whether q (in the face's plane) lies on the face's border: within `inset` plus a rounding
// error of the vertices (stored to about 1e-7 of their cell) of the closed face, not inside it.
bool on_border(const Face& face, const Vec3& q, double inset) {
  bool within = true, inside = true;
  for (int d = 0; d < 3; ++d) {
    if (d == face.axis) continue;
    const double tol = inset + (face.hi[d] - face.lo[d]) * 1e-6;
    within = within && q[d] >= face.lo[d] - tol && q[d] <= face.hi[d] + tol;
    inside = inside && q[d] > face.lo[d] + tol && q[d] < face.hi[d] - tol;
  }
  return within && !inside;
}

// The point of the face (`margin` inside its border) nearest where the plain split of the
// polygons `near` (but those with vertex `skip`) crosses the face's plane; among points where
// it crosses the face itself, the one nearest q. Candidates better than (best_off, best_q)
// replace `best`.
void plain_surface_in_face(const std::vector<Vec3>& x, const std::vector<MeshPolygon>& polys,
                           const std::vector<Split>& splits, const uint32_t* near, size_t count, uint32_t skip,
                           const Face& face, double margin, const Vec3& q, Vec3& best, double& best_off,
                           double& best_q) {
  const int axis = face.axis, u = (axis + 1) % 3, w = (axis + 2) % 3;
  const double lo[2] = {face.lo[u] + margin, face.lo[w] + margin}, hi[2] = {face.hi[u] - margin, face.hi[w] - margin};
  const auto consider = [&](const double c[2], double off) {
    const double dq = (c[0] - q[u]) * (c[0] - q[u]) + (c[1] - q[w]) * (c[1] - q[w]);
    if (off < best_off || (off == best_off && dq < best_q)) {
      best_off = off;
      best_q = dq;
      best[axis] = face.plane;
      best[u] = c[0];
      best[w] = c[1];
    }
  };
  for (size_t k = 0; k < count; ++k) {
    const MeshPolygon& p = polys[near[k]];
    if (skip != kNone && std::find(p.v.begin(), p.v.begin() + p.count, skip) != p.v.begin() + p.count) continue;
    for (int i = 0; i < (p.count == 4 ? 2 : 1); ++i) {
      std::array<Vec3, 3> t;
      for (int m = 0; m < 3; ++m) t[m] = x[p.v[splits[near[k]][i][m]]];
      // The triangle's chord on the face's plane (in face coordinates): where its sides cross.
      double ends[2][2];
      int found = 0;
      for (int m = 0; m < 3 && found < 2; ++m) {
        const Vec3 &a = t[m], &b = t[(m + 1) % 3];
        const double sa = a[axis] - face.plane, sb = b[axis] - face.plane;
        if ((sa < 0 && sb < 0) || (sa > 0 && sb > 0) || sa == sb) continue;
        const double l = sa / (sa - sb);
        ends[found][0] = a[u] + l * (b[u] - a[u]);
        ends[found][1] = a[w] + l * (b[w] - a[w]);
        ++found;
      }
      if (found < 2) continue;
      const double dv[2] = {ends[1][0] - ends[0][0], ends[1][1] - ends[0][1]};
      // Clipped to the face (Liang-Barsky): if any is left, its point nearest q.
      double l0 = 0, l1 = 1;
      for (int d = 0; d < 2; ++d) {
        if (dv[d] == 0) {
          if (ends[0][d] <= lo[d] || ends[0][d] >= hi[d]) l1 = -1;
          continue;
        }
        double ta = (lo[d] - ends[0][d]) / dv[d], tb = (hi[d] - ends[0][d]) / dv[d];
        if (ta > tb) std::swap(ta, tb);
        l0 = std::max(l0, ta);
        l1 = std::min(l1, tb);
      }
      const double len = dv[0] * dv[0] + dv[1] * dv[1];
      if (l1 > l0) {
        double l = len > 0 ? ((q[u] - ends[0][0]) * dv[0] + (q[w] - ends[0][1]) * dv[1]) / len : l0;
        l = std::clamp(l, l0, l1);
        const double c[2] = {ends[0][0] + l * dv[0], ends[0][1] + l * dv[1]};
        consider(c, 0.0);
        continue;
      }
      // Apart from the face: the nearest pair is a chord end clamped into the face, or a
      // corner of the face and its nearest chord point.
      for (int e = 0; e < 2; ++e) {
        const double c[2] = {std::clamp(ends[e][0], lo[0], hi[0]), std::clamp(ends[e][1], lo[1], hi[1])};
        consider(c, (c[0] - ends[e][0]) * (c[0] - ends[e][0]) + (c[1] - ends[e][1]) * (c[1] - ends[e][1]));
      }
      for (int corner = 0; corner < 4; ++corner) {
        const double c[2] = {corner & 1 ? hi[0] : lo[0], corner & 2 ? hi[1] : lo[1]};
        double l = len > 0 ? ((c[0] - ends[0][0]) * dv[0] + (c[1] - ends[0][1]) * dv[1]) / len : 0;
        l = std::clamp(l, 0.0, 1.0);
        const double px = ends[0][0] + l * dv[0] - c[0], py = ends[0][1] + l * dv[1] - c[1];
        consider(c, px * px + py * py);
      }
    }
  }
}

int axis_of(const Vec3& e0, const Vec3& e1) {
  for (int a = 0; a < 3; ++a)
    if (e0[a] != e1[a]) return a;
  return 0;
}

// Where the line of edge (e0, e1) pierces triangle (a, b, c): the edge parameter, or NaN.
double pierce(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& e0, const Vec3& e1) {
  const int ax = axis_of(e0, e1), u = (ax + 1) % 3, w = (ax + 2) % 3;
  const double au = a[u] - e0[u], aw = a[w] - e0[w], bu = b[u] - e0[u], bw = b[w] - e0[w];
  const double cu = c[u] - e0[u], cw = c[w] - e0[w];
  const double la = cross2(bu, bw, cu, cw), lb = cross2(cu, cw, au, aw), lc = cross2(au, aw, bu, bw);
  const double sum = la + lb + lc;
  const bool in = sum > 0 ? (la >= 0 && lb >= 0 && lc >= 0) : (la <= 0 && lb <= 0 && lc <= 0);
  if (sum == 0 || !in) return std::numeric_limits<double>::quiet_NaN();
  const double h = (la * a[ax] + lb * b[ax] + lc * c[ax]) / sum;
  return (h - e0[ax]) / (e1[ax] - e0[ax]);
}

// How well edge parameter t places an edge point: first how far it falls outside the edge,
// then how far from `prefer`; smaller is better.
std::pair<double, double> edge_key(double t, double prefer) {
  return {std::max({0.0, -t, t - 1}), std::abs(t - prefer)};
}

// The edge parameter where the line of edge (e0, e1) pierces the plain split of the polygons
// `near` (their triangles): inside the edge if it can, then nearest to `prefer`; NaN when the
// line pierces none. The plain dual contouring surface crosses a sign-changing edge within its
// own error of where the sampled surface does, even where the edge's own polygon folds beside
// it.
double pierce_near(const std::vector<Vec3>& x, const std::vector<MeshPolygon>& polys, const std::vector<Split>& splits,
                   const uint32_t* near, size_t count, const Vec3& e0, const Vec3& e1, double prefer) {
  double best = std::numeric_limits<double>::quiet_NaN();
  for (size_t k = 0; k < count; ++k) {
    const MeshPolygon& p = polys[near[k]];
    const Split& sp = splits[near[k]];
    for (int i = 0; i < (p.count == 4 ? 2 : 1); ++i) {
      const double t = pierce(x[p.v[sp[i][0]]], x[p.v[sp[i][1]]], x[p.v[sp[i][2]]], e0, e1);
      if (t == t && (best != best || edge_key(t, prefer) < edge_key(best, prefer))) best = t;
    }
  }
  return best;
}

// Where the ring's mean plane (centroid, vector-area normal) crosses the edge, kept within the
// heights of the ring's vertices along the edge: the fallback edge parameter.
double mean_plane_height(const std::array<Vec3, 4>& p, int count, const Vec3& e0, const Vec3& e1) {
  const int a = axis_of(e0, e1);
  Vec3 c{0, 0, 0}, n{0, 0, 0};
  double lo = kHuge, hi = -kHuge;
  for (int k = 0; k < count; ++k) {
    for (int d = 0; d < 3; ++d) c[d] += p[k][d] / count;
    const Vec3 x = cross3(p[k], p[(k + 1) % count]);
    for (int d = 0; d < 3; ++d) n[d] += x[d];
    const double t = (p[k][a] - e0[a]) / (e1[a] - e0[a]);
    lo = std::min(lo, t);
    hi = std::max(hi, t);
  }
  const double den = dot3(n, sub3(e1, e0));
  const double t = den != 0 ? dot3(n, sub3(c, e0)) / den : 0.5 * (lo + hi);
  return std::clamp(t, lo, hi);
}

// The ring's mean height along the edge, as an edge parameter.
double ring_height(const std::array<Vec3, 4>& p, int count, const Vec3& e0, const Vec3& e1) {
  const int a = axis_of(e0, e1);
  double sum = 0;
  for (int k = 0; k < count; ++k) sum += p[k][a];
  return (sum / count - e0[a]) / (e1[a] - e0[a]);
}

// The point at parameter t of edge (e0, e1), kept `margin` off its ends.
Vec3 point_on_edge(const Vec3& e0, const Vec3& e1, double t, double margin) {
  const int a = axis_of(e0, e1);
  const double m = std::min(0.25, margin / std::abs(e1[a] - e0[a]));
  if (!(t >= m)) t = m;  // also NaN
  if (t > 1 - m) t = 1 - m;
  Vec3 x = e0;
  x[a] = e0[a] + t * (e1[a] - e0[a]);  // the other two coordinates stay exact
  return x;
}

// The plain split of every polygon, with each vertex's polygons (CSR): the surface the added
// points are placed on.
struct PlainSurface {
  const std::vector<Vec3>& x;
  const std::vector<MeshPolygon>& polys;
  const std::vector<Split>& splits;
  std::vector<uint32_t> first, around;
  const SurfaceFunction& level;  // the sampled function, when known

  std::pair<const uint32_t*, size_t> near(uint32_t v) const {
    return {around.data() + first[v], size_t(first[v + 1] - first[v])};
  }
};

// Where the surface crosses polygon i's edge, as an edge parameter: where the edge pierces the
// polygon's own plain split, else that of the polygons around its vertices, else one ring
// further out (a fold can put the plain crossing a polygon away); else the ring's mean plane.
double edge_parameter(const PlainSurface& s, size_t i) {
  const MeshPolygon& p = s.polys[i];
  if (s.level) {
    // The function's own zero on the edge. Where its ends' values agree in sign (the settling
    // turned a corner), the zero between the first two of 32 samples that disagree, else the
    // sample where |f| is least.
    const auto at = [&](double t) { return add3(p.e0, scale3(sub3(p.e1, p.e0), t)); };
    const auto f = [&](double t) { return s.level(at(t)); };
    const double f0 = f(0), f1 = f(1);
    if ((f0 < 0) != (f1 < 0)) return illinois_root(f, f0, f1, kEdgeRoot, kEdgeRootSteps);
    constexpr int kSamples = 32;
    double best = 0, least = std::abs(f0), prev = f0;
    for (int k = 1; k <= kSamples; ++k) {
      const double t = double(k) / kSamples, ft = k == kSamples ? f1 : f(t);
      if ((ft < 0) != (prev < 0)) {
        const double t0 = double(k - 1) / kSamples;
        return t0 + illinois_root([&](double u) { return f(t0 + u / kSamples); }, prev, ft, kEdgeRoot * kSamples, kEdgeRootSteps) / kSamples;
      }
      if (std::abs(ft) < least) least = std::abs(ft), best = t;
      prev = ft;
    }
    return best;
  }
  std::array<Vec3, 4> q;
  for (int k = 0; k < p.count; ++k) q[k] = s.x[p.v[k]];
  const double prefer = ring_height(q, p.count, p.e0, p.e1);
  const auto look = [&](const uint32_t* list, size_t count, double& t) {
    const double h = pierce_near(s.x, s.polys, s.splits, list, count, p.e0, p.e1, prefer);
    if (h == h && (t != t || edge_key(h, prefer) < edge_key(t, prefer))) t = h;
  };
  const uint32_t self = uint32_t(i);
  double t = std::numeric_limits<double>::quiet_NaN();
  look(&self, 1, t);
  if (!(t >= 0 && t <= 1))
    for (int k = 0; k < p.count; ++k) {
      const auto [list, count] = s.near(p.v[k]);
      look(list, count, t);
    }
  if (!(t >= 0 && t <= 1)) {  // each polygon of the next ring once
    std::vector<uint32_t> further;
    for (int k = 0; k < p.count; ++k)
      for (uint32_t j = s.first[p.v[k]]; j < s.first[p.v[k] + 1]; ++j)
        for (int m = 0; m < s.polys[s.around[j]].count; ++m) {
          const auto [list, count] = s.near(s.polys[s.around[j]].v[m]);
          further.insert(further.end(), list, list + count);
        }
    std::sort(further.begin(), further.end());
    further.erase(std::unique(further.begin(), further.end()), further.end());
    look(further.data(), further.size(), t);
  }
  if (t != t) t = mean_plane_height(q, p.count, p.e0, p.e1);
  return t;
}

// Where the plain split misses a side's face, the surface still crosses the face: it enters
// through the two sign-changing edges on the face's border that the side's two polygons are
// dual to. F is then the point nearest q of the chord between those edges' crossings (the
// surface's trace on the face, to first order). False when the side has not two polygons.
bool chord_across_face(const PlainSurface& s, uint32_t a, uint32_t b, const Face& face, const Vec3& q, double inset,
                       Vec3& f) {
  std::array<Vec3, 2> end;
  int found = 0;
  const auto [list, count] = s.near(a);
  for (size_t k = 0; k < count; ++k) {
    const MeshPolygon& p = s.polys[list[k]];
    if (std::find(p.v.begin(), p.v.begin() + p.count, b) == p.v.begin() + p.count) continue;
    if (found == 2) return false;
    end[found++] = point_on_edge(p.e0, p.e1, edge_parameter(s, list[k]), inset);
  }
  if (found != 2) return false;
  const Vec3 d = sub3(end[1], end[0]);
  const double len = dot3(d, d);
  const double t = len > 0 ? std::clamp(dot3(sub3(q, end[0]), d) / len, 0.0, 1.0) : 0.5;
  for (int k = 0; k < 3; ++k) f[k] = end[0][k] + t * d[k];
  f[face.axis] = face.plane;
  for (int k = 0; k < 3; ++k)
    if (k != face.axis) f[k] = std::clamp(f[k], face.lo[k] + inset, face.hi[k] - inset);
  return true;
}

// Moves face point f, within its face, onto the zero of the solid's function: Newton steps
// along the function's gradient in the face's plane (central differences), kept `inset` inside
// the face, each taken only when it lowers |level|. A face point anywhere strictly inside its
// face keeps the construction's argument, so this moves no triangle across another.
void onto_level_in_face(const SurfaceFunction& level, const Face& face, double inset, Vec3& f) {
  double size = 0;
  for (int d = 0; d < 3; ++d)
    if (d != face.axis) size = std::max(size, face.hi[d] - face.lo[d]);
  const double h = size * kFaceStep, enough = size * kFaceStep;
  double v = level(f);
  for (int it = 0; it < 4 && std::abs(v) > enough; ++it) {
    Vec3 g{0, 0, 0};
    for (int d = 0; d < 3; ++d) {
      if (d == face.axis) continue;
      Vec3 a = f, b = f;
      a[d] -= h, b[d] += h;
      g[d] = (level(b) - level(a)) / (2 * h);
    }
    const double g2 = dot3(g, g);
    if (!(g2 > 0)) break;
    Vec3 next = sub3(f, scale3(g, v / g2));
    for (int d = 0; d < 3; ++d)
      if (d != face.axis) next[d] = std::clamp(next[d], face.lo[d] + inset, face.hi[d] - inset);
    const double w = level(next);
    if (!(std::abs(w) < std::abs(v))) break;
    f = next, v = w;
  }
  if (!(std::abs(v) > size * kFaceStall)) return;
  // Newton stalls where the zero lies along the face's border (each step across it is
  // clamped back): bisect towards the nearest of the face's corners (kept inset) where the
  // function has the other sign. The segment stays in the face, convex.
  const int u = (face.axis + 1) % 3, w = (face.axis + 2) % 3;
  Vec3 other = f;
  double other_v = 0, nearest = kHuge;
  for (int c = 0; c < 4; ++c) {
    Vec3 q = f;
    q[u] = c & 1 ? face.hi[u] - inset : face.lo[u] + inset;
    q[w] = c & 2 ? face.hi[w] - inset : face.lo[w] + inset;
    const Vec3 dq = sub3(q, f);
    const double qv = level(q), d = dot3(dq, dq);
    if ((qv < 0) != (v < 0) && d < nearest) other = q, other_v = qv, nearest = d;
  }
  if (nearest == kHuge) return;
  for (int it = 0; it < 40 && std::abs(v) > enough; ++it) {
    const Vec3 mid = scale3(add3(f, other), 0.5);
    const double m = level(mid);
    if ((m < 0) == (v < 0)) f = mid, v = m;
    else other = mid, other_v = m;
  }
  if (std::abs(other_v) < std::abs(v)) f = other;
}

// True when the triangles `tris` (index triples into ring `r`) lie in the ring of tetrahedra
// (e0, e1, r_i, r_i+1) around the edge, strictly inside except at the ring's vertices. The
// ring must wind once around the edge, each step turning the same way by less than half a
// turn. Seen along the edge, tetrahedron i then fills wedge i (between the rays through r_i
// and r_i+1), between the plane (e0, r_i, r_i+1) below and (e1, r_i, r_i+1) above. Within a
// wedge a triangle's height minus those planes is linear, so it suffices to check the corners
// of the triangle's parts in the wedges: its own vertices (ring vertices), where its sides
// cross the rays (strictly inside triangle (e0, e1, r_k) on ray k), and the edge itself, if
// the edge pierces the triangle (strictly between e0 and e1).
bool inside_ring(const Vec3* r, int n, const Vec3& e0, const Vec3& e1, const std::array<int, 3>* tris, int ntris) {
  const int ax = axis_of(e0, e1), u = (ax + 1) % 3, w = (ax + 2) % 3;
  std::array<double, kMaxRing> du{}, dw{}, h{};
  for (int i = 0; i < n; ++i) {
    du[i] = r[i][u] - e0[u];
    dw[i] = r[i][w] - e0[w];
    h[i] = r[i][ax];
  }
  double turn = 0;
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const double c = cross2(du[i], dw[i], du[j], dw[j]);
    if (c == 0 || (turn != 0 && (c > 0) != (turn > 0))) return false;
    turn = c;
  }
  const double h0 = e0[ax], h1 = e1[ax], margin = kRingHeightMargin * std::abs(h1 - h0);
  // Height z at fraction rho of the way out along ray k: strictly between the lines from e0
  // and from e1 to r_k.
  const auto between = [&](double z, double rho, int k) {
    const double a = h0 + rho * (h[k] - h0), b = h1 + rho * (h[k] - h1);
    return z > std::min(a, b) + margin && z < std::max(a, b) - margin;
  };
  for (int t = 0; t < ntris; ++t) {
    const auto [a, b, c] = tris[t];
    // Where the edge's line meets the triangle (inside or on a side).
    const double la = cross2(du[b], dw[b], du[c], dw[c]), lb = cross2(du[c], dw[c], du[a], dw[a]);
    const double lc = cross2(du[a], dw[a], du[b], dw[b]), sum = la + lb + lc;
    if (sum == 0) return false;  // seen along the edge, the triangle is a segment
    if (la * sum >= 0 && lb * sum >= 0 && lc * sum >= 0 &&
        !between((la * h[a] + lb * h[b] + lc * h[c]) / sum, 0.0, a))
      return false;
    for (const auto& [p, q] : {std::pair(a, b), std::pair(b, c), std::pair(c, a)}) {
      for (int k = 0; k < n; ++k) {
        if (k == p || k == q) continue;
        const double sp = cross2(du[k], dw[k], du[p], dw[p]), sq = cross2(du[k], dw[k], du[q], dw[q]);
        if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0)) continue;
        if (sp == sq) return false;  // the side runs along ray k's line
        const double l = sp / (sp - sq);
        const double xu = du[p] + l * (du[q] - du[p]), xw = dw[p] + l * (dw[q] - dw[p]);
        const double along = du[k] * xu + dw[k] * xw;
        if (along < 0) continue;  // the ray's opposite half
        const double rho = along / (du[k] * du[k] + dw[k] * dw[k]);
        if (!(rho < 1) || !between(h[p] + l * (h[q] - h[p]), rho, k)) return false;
      }
    }
  }
  return true;
}

// Both triangles of a quad split facing the quad's way (not folded back onto each other).
bool faces_forward(const std::array<Vec3, 4>& p, const std::array<std::array<int, 3>, 2>& split) {
  const Vec3 n = cross3(sub3(p[2], p[0]), sub3(p[3], p[1]));
  for (const auto& t : split)
    if (!(dot3(cross3(sub3(p[t[1]], p[t[0]]), sub3(p[t[2]], p[t[0]])), n) > 0)) return false;
  return true;
}

// The plain split of a polygon that stays in its region, or 0 triangles when none does.
int plain_split_in_region(const std::array<Vec3, 4>& q, int count, const Vec3& e0, const Vec3& e1,
                          std::array<std::array<int, 3>, 2>& split, bool& other) {
  other = false;
  if (count == 3) return inside_ring(q.data(), 3, e0, e1, split.data(), 1) ? 1 : 0;
  if (faces_forward(q, split) && inside_ring(q.data(), 4, e0, e1, split.data(), 2)) return 2;
  const std::array<std::array<int, 3>, 2> alt =
      split[0][2] == 2 ? std::array<std::array<int, 3>, 2>{{{0, 1, 3}, {1, 2, 3}}}
                       : std::array<std::array<int, 3>, 2>{{{0, 1, 2}, {0, 2, 3}}};
  if (faces_forward(q, alt) && inside_ring(q.data(), 4, e0, e1, alt.data(), 2)) {
    split = alt;
    other = true;
    return 2;
  }
  return 0;
}

// Whether the fan from ring point `apex` over the ring (a polygon with its face points) lies in
// the polygon's region. Seen along the edge the ring is star-shaped around it (inside_ring
// checks that); a fan whose triangles all turn the same way there tiles it, so they cannot
// cross each other either.
bool fan_in_region(const std::array<Vec3, kMaxRing>& r, int m, const Vec3& e0, const Vec3& e1, int apex) {
  const int ax = axis_of(e0, e1), u = (ax + 1) % 3, w = (ax + 2) % 3;
  std::array<std::array<int, 3>, kMaxRing - 2> tris;
  double turn = 0;
  for (int j = 1; j + 1 < m; ++j) {
    const int b = (apex + j) % m, c = (apex + j + 1) % m;
    tris[j - 1] = {apex, b, c};
    const Vec3 &o = r[apex], &x = r[b], &y = r[c];
    const double t = cross2(x[u] - o[u], x[w] - o[w], y[u] - o[u], y[w] - o[w]);
    if (t == 0 || (turn != 0 && (t > 0) != (turn > 0))) return false;
    turn = t;
  }
  return inside_ring(r.data(), m, e0, e1, tris.data(), m - 2);
}

}  // namespace

std::array<std::array<int, 3>, 2> split_quad(const std::array<Vec3, 4>& p) {
  // Unnormalized triangle normals: their signs against the quad's normal need no square root.
  const Vec3 a0 = cross3(sub3(p[1], p[0]), sub3(p[2], p[0])), a1 = cross3(sub3(p[2], p[0]), sub3(p[3], p[0]));
  const Vec3 b0 = cross3(sub3(p[1], p[0]), sub3(p[3], p[0])), b1 = cross3(sub3(p[2], p[1]), sub3(p[3], p[1]));
  // The quad's own orientation: cross product of its diagonals (twice its vector area).
  const Vec3 n = cross3(sub3(p[2], p[0]), sub3(p[3], p[1]));
  const double da0 = dot3(a0, n), da1 = dot3(a1, n), db0 = dot3(b0, n), db1 = dot3(b1, n);
  // A split whose triangle faces against the quad folds it back on itself (a non-convex
  // quad split along its outer diagonal): never take it when the other split is clean.
  const bool a_ok = da0 > 0 && da1 > 0, b_ok = db0 > 0 && db1 > 0;
  auto len = [](const Vec3& x) {
    const double l = std::sqrt(dot3(x, x));
    return l > 0 ? l : 1.0;
  };
  bool use_a;
  if (a_ok != b_ok) {
    use_a = a_ok;
  } else if (!a_ok) {
    use_a = std::min(da0 / len(a0), da1 / len(a1)) >= std::min(db0 / len(b0), db1 / len(b1));
  } else {
    // Both clean: fold along the diagonal that bends most (smaller cosine between its two
    // triangles), which keeps a crease whose two vertices lie on it.
    // cos_a <= cos_b with cos = dot / sqrt(norms), compared by squares (signs first).
    const double da = dot3(a0, a1), na = dot3(a0, a0) * dot3(a1, a1);
    const double db = dot3(b0, b1), nb = dot3(b0, b0) * dot3(b1, b1);
    if ((da < 0) != (db < 0)) use_a = da < 0;
    else if (da >= 0) use_a = da * da * nb <= db * db * na;
    else use_a = da * da * nb >= db * db * na;
  }
  if (use_a) return {{{0, 1, 2}, {0, 2, 3}}};
  return {{{0, 1, 3}, {1, 2, 3}}};
}

std::vector<Tri> triangulate(std::vector<Vec3>& x, const std::vector<VertexCell>& cells,
                             const std::vector<MeshPolygon>& polys, Triangulation how, double inset,
                             const SurfaceFunction& level, TriangulationStats* stats) {
  const size_t n = polys.size();
  const auto ring_of = [&](size_t i) {
    std::array<Vec3, 4> q;
    for (int k = 0; k < polys[i].count; ++k) q[k] = x[polys[i].v[k]];
    return q;
  };
  const auto side = [&](size_t i, int k) {
    const MeshPolygon& p = polys[i];
    const uint32_t a = p.v[k], b = p.v[(k + 1) % p.count];
    return std::pair(std::min(a, b), std::max(a, b));  // one order, so both polygons agree
  };
  // Dual contouring's split of every polygon; then, unless plain, whether each side crosses
  // its cells' common face inside it (bit k: side k does not), and whether the plain split
  // provably stays in the polygon's region (`plain`: its triangle count, + 4 when it took the
  // other diagonal; 0: fanned).
  std::vector<Split> splits(n, Split{{{0, 1, 2}, {0, 2, 3}}});
  std::vector<uint8_t> off_face(n, 0), plain(n, 0);
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    const MeshPolygon& p = polys[i];
    const std::array<Vec3, 4> q = ring_of(i);
    if (p.count == 4) splits[i] = split_quad(q);
    if (how == Triangulation::kPlain) {
      plain[i] = uint8_t(p.count == 4 ? 2 : 1);
      return;
    }
    for (int k = 0; k < p.count; ++k) {
      const auto [a, b] = side(i, k);
      const Face f = common_face(cells[a], cells[b]);
      Vec3 c;
      if (f.axis >= 0 && !crosses_inside(f, x[a], x[b], c, inset * 0x1p-12)) off_face[i] |= uint8_t(1 << k);
    }
    bool other = false;
    if (how == Triangulation::kConstruct && !off_face[i])
      if (const int tris = plain_split_in_region(q, p.count, p.e0, p.e1, splits[i], other))
        plain[i] = uint8_t(tris + (other ? 4 : 0));
  });
  // Each vertex's polygons (CSR): the plain surface around a polygon.
  PlainSurface surface{x, polys, splits, std::vector<uint32_t>(x.size() + 1, 0), {}, level};
  std::vector<uint32_t>&first = surface.first, &around = surface.around;
  for (const MeshPolygon& p : polys)
    for (int k = 0; k < p.count; ++k) ++first[p.v[k] + 1];
  for (size_t v = 1; v < first.size(); ++v) first[v] += first[v - 1];
  around.resize(first.back());
  {
    std::vector<uint32_t> fill(first.begin(), first.end() - 1);
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < polys[i].count; ++k) around[fill[polys[i].v[k]]++] = uint32_t(i);
  }
  // Face points: one per side off its face, numbered in polygon order where first met.
  TriangulationStats st;
  const auto nv = static_cast<uint32_t>(x.size());
  std::vector<std::array<uint32_t, 4>> face_id;  // per polygon with sides off their faces
  std::vector<uint32_t> face_slot(n, kNone);     // index into face_id
  std::vector<std::pair<uint32_t, int>> face_owner;  // the polygon and side that number each face point
  std::unordered_map<uint64_t, uint32_t> face_of_side;
  for (size_t i = 0; i < n; ++i) {
    if (!off_face[i]) continue;
    face_slot[i] = static_cast<uint32_t>(face_id.size());
    face_id.push_back({kNone, kNone, kNone, kNone});
    for (int k = 0; k < polys[i].count; ++k) {
      if (!(off_face[i] >> k & 1)) continue;
      const auto [a, b] = side(i, k);
      const auto [it, fresh] = face_of_side.try_emplace(uint64_t(a) << 32 | b, uint32_t(face_owner.size()));
      if (fresh) face_owner.push_back({uint32_t(i), k});
      face_id.back()[k] = it->second;
    }
  }
  st.face_points = face_owner.size();
  // Each face point: where the plain surface around its side crosses the face; where it misses
  // the face (it may pass through a third cell beside a crease), on the chord between the face's
  // two edge crossings; else the face's point nearest the plain surface, or nearest where the
  // side meets the face's plane.
  std::vector<Vec3> face_x(face_owner.size());
  tbb::parallel_for(size_t{0}, face_owner.size(), [&](size_t j) {
    const auto [i, k] = face_owner[j];
    const auto [a, b] = side(i, k);
    const Face face = common_face(cells[a], cells[b]);
    Vec3 q;
    crosses_inside(face, x[a], x[b], q);
    Vec3 f = q;
    if (on_border(face, q, inset)) {
      // The side itself passes through the face's border (a crease through a lattice point
      // or along a lattice line, both its vertices on it): its own crossing, just inside,
      // keeps the polygons on the crease, where the plain surface would cut across it.
      for (int d = 0; d < 3; ++d)
        if (d != face.axis) f[d] = std::clamp(q[d], face.lo[d] + inset, face.hi[d] - inset);
      if (level) onto_level_in_face(level, face, inset, f);
      face_x[j] = f;
      return;
    }
    double off = std::numeric_limits<double>::infinity(), dq = off;
    for (const uint32_t v : {a, b}) {  // polygons around a, then those around b only
      const auto [list, count] = surface.near(v);
      plain_surface_in_face(x, polys, splits, list, count, v == b ? a : kNone, face, inset, q, f, off, dq);
    }
    const bool missed = off > 0;  // no plain triangle around the side crosses the face itself
    if (missed && !chord_across_face(surface, a, b, face, q, inset, f) && std::isinf(off)) {
      f = q;
      for (int d = 0; d < 3; ++d)
        if (d != face.axis) f[d] = std::clamp(q[d], face.lo[d] + inset, face.hi[d] - inset);
    }
    if (level) onto_level_in_face(level, face, inset, f);
    face_x[j] = f;
  });
  // A polygon with face points: its ring (the sides split there) as a fan from one of its
  // points when that stays in its region (`apex`: the ring index). Vertices are tried first:
  // a fan from a face point reaches across the polygon, and cut a thin wedge of a CSG result
  // a third of a cell shorter.
  constexpr uint8_t kNoApex = 0xff;
  const auto ring_with_face_points = [&](size_t i, std::array<uint32_t, kMaxRing>& ids) {
    const MeshPolygon& p = polys[i];
    int m = 0;
    for (int k = 0; k < p.count; ++k) {
      ids[m++] = p.v[k];
      if (off_face[i] >> k & 1) ids[m++] = nv + face_id[face_slot[i]][k];  // face point j as nv + j, for now
    }
    return m;
  };
  std::vector<uint8_t> apex(n, kNoApex);
  if (how == Triangulation::kConstruct) {
    tbb::parallel_for(size_t{0}, n, [&](size_t i) {
      if (!off_face[i]) return;
      std::array<uint32_t, kMaxRing> ids;
      std::array<Vec3, kMaxRing> r;
      const int m = ring_with_face_points(i, ids);
      for (int k = 0; k < m; ++k) r[k] = ids[k] < nv ? x[ids[k]] : face_x[ids[k] - nv];
      for (const bool face : {false, true})
        for (int k = 0; k < m; ++k)
          if ((ids[k] >= nv) == face && fan_in_region(r, m, polys[i].e0, polys[i].e1, k)) {
            apex[i] = uint8_t(k);
            return;
          }
    });
  }
  // Numbering, in polygon order: the fans' edge points (after the vertices), then the face
  // points; the triangles each polygon writes.
  std::vector<uint32_t> edge_id(n, kNone), tri_at(n + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    const MeshPolygon& p = polys[i];
    const uint32_t ring = uint32_t(p.count + std::popcount(unsigned(off_face[i])));
    if (plain[i]) {
      tri_at[i + 1] = plain[i] & 3;
      st.other_diagonal += plain[i] >> 2;
    } else if (apex[i] != kNoApex) {
      tri_at[i + 1] = ring - 2;
      ++st.face_fans;
    } else {
      edge_id[i] = static_cast<uint32_t>(st.fans++);
      tri_at[i + 1] = ring;
    }
  }
  for (size_t i = 0; i < n; ++i) tri_at[i + 1] += tri_at[i];
  const uint32_t face_base = nv + uint32_t(st.fans);
  x.resize(face_base + face_owner.size());
  std::copy(face_x.begin(), face_x.end(), x.begin() + face_base);
  // Each fan's edge point: where its edge crosses the plain surface of the polygons around it.
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    if (edge_id[i] == kNone) return;
    x[nv + edge_id[i]] = point_on_edge(polys[i].e0, polys[i].e1, edge_parameter(surface, i), inset);
  });
  // The triangles.
  std::vector<Tri> out(tri_at[n]);
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    const MeshPolygon& p = polys[i];
    Tri* o = out.data() + tri_at[i];
    if (plain[i]) {
      for (int k = 0; k < (plain[i] & 3); ++k) *o++ = {p.v[splits[i][k][0]], p.v[splits[i][k][1]], p.v[splits[i][k][2]]};
      return;
    }
    std::array<uint32_t, kMaxRing> ids;
    const int m = ring_with_face_points(i, ids);
    for (int k = 0; k < m; ++k)
      if (ids[k] >= nv) ids[k] += face_base - nv;
    if (apex[i] != kNoApex) {
      const int a = apex[i];
      for (int j = 1; j + 1 < m; ++j) *o++ = {ids[a], ids[(a + j) % m], ids[(a + j + 1) % m]};
      return;
    }
    const uint32_t e = nv + edge_id[i];
    for (int k = 0; k < m; ++k) *o++ = {e, ids[k], ids[(k + 1) % m]};
  });
  if (stats) *stats = st;
  return out;
}

}  // namespace pic::detail
