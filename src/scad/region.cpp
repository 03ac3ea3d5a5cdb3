// 2D regions through Clipper: see region.h. Each operation converts its operands to Clipper's
// integers with a power-of-two scale fitted to them (about 30 bits across the operands' extent,
// Clipper's fast 64-bit range), runs, and converts back.
#include "scad/region.h"
#include "geometry/tolerances.h"

#include <polyclipping/clipper.hpp>

#include <algorithm>
#include <cmath>
#include <map>

namespace pic::detail::scad {
namespace {

namespace cl = ClipperLib;

double fitted_scale(std::initializer_list<const Region*> regions) {
  double extent = 0;
  for (const Region* r : regions) extent = std::max(extent, region_extent(*r));
  if (!(extent > 0)) return 1;
  return std::exp2(std::floor(std::log2(double(0x3FFFFFFF) / extent)));
}

cl::Paths to_paths(const Region& r, double scale) {
  cl::Paths out;
  out.reserve(r.size());
  for (const Ring& ring : r) {
    cl::Path path;
    path.reserve(ring.size());
    for (const P2& p : ring) path.push_back({cl::cInt(std::llround(p[0] * scale)), cl::cInt(std::llround(p[1] * scale))});
    out.push_back(std::move(path));
  }
  return out;
}

Region from_paths(const cl::Paths& paths, double scale) {
  Region out;
  out.reserve(paths.size());
  for (const cl::Path& path : paths) {
    if (path.size() < 3) continue;
    // A ring narrower than two grid units on average (area below its perimeter, in grid
    // units) is rounding debris, such as a section's sliver; its extrusion would be flat.
    double perimeter = 0;
    for (size_t i = 0; i < path.size(); ++i) {
      const cl::IntPoint &a = path[i], &b = path[(i + 1) % path.size()];
      perimeter += std::hypot(double(b.X - a.X), double(b.Y - a.Y));
    }
    if (std::abs(cl::Area(path)) <= perimeter) continue;
    Ring ring;
    ring.reserve(path.size());
    for (const cl::IntPoint& p : path) ring.push_back({double(p.X) / scale, double(p.Y) / scale});
    out.push_back(std::move(ring));
  }
  return out;
}

// Runs one Clipper operation: subject paths (filled by `subject_fill`) against clip paths.
Region clip(const Region& subject, const Region& clip_region, cl::ClipType type, cl::PolyFillType subject_fill) {
  const double scale = fitted_scale({&subject, &clip_region});
  cl::Clipper c;
  c.AddPaths(to_paths(subject, scale), cl::ptSubject, true);
  c.AddPaths(to_paths(clip_region, scale), cl::ptClip, true);
  cl::Paths out;
  c.Execute(type, out, subject_fill, cl::pftNonZero);
  return from_paths(out, scale);
}

}  // namespace

double region_extent(const Region& region) {
  double extent = 0;
  for (const Ring& r : region)
    for (const P2& p : r) extent = std::max({extent, std::abs(p[0]), std::abs(p[1])});
  return extent;
}

Region region_even_odd(const std::vector<Ring>& rings) { return clip(rings, {}, cl::ctUnion, cl::pftEvenOdd); }

Region region_union(const std::vector<Region>& parts) {
  Region all;
  for (const Region& p : parts) all.insert(all.end(), p.begin(), p.end());
  return clip(all, {}, cl::ctUnion, cl::pftNonZero);
}

Region region_intersection(const std::vector<Region>& parts) {
  if (parts.empty()) return {};
  Region acc = parts[0];
  for (size_t i = 1; i < parts.size() && !acc.empty(); ++i) acc = clip(acc, parts[i], cl::ctIntersection, cl::pftNonZero);
  return acc;
}

Region region_difference(const std::vector<Region>& parts) {
  if (parts.empty()) return {};
  Region rest;
  for (size_t i = 1; i < parts.size(); ++i) rest.insert(rest.end(), parts[i].begin(), parts[i].end());
  return clip(parts[0], rest, cl::ctDifference, cl::pftNonZero);
}

Region region_offset(const Region& region, double amount, OffsetJoin join, double arc_tolerance) {
  const double scale = fitted_scale({&region}) / 2;  // room for the region to grow
  // OpenSCAD's miter limit for delta is effectively unbounded (sharp corners stay sharp).
  cl::ClipperOffset co(join == OffsetJoin::kMiter ? kUnboundedMiter : 2.0, std::max(arc_tolerance, kMinArcTolerance) * scale);
  const cl::JoinType jt = join == OffsetJoin::kRound ? cl::jtRound : join == OffsetJoin::kMiter ? cl::jtMiter : cl::jtSquare;
  co.AddPaths(to_paths(region, scale), jt, cl::etClosedPolygon);
  cl::Paths out;
  co.Execute(out, amount * scale);
  return from_paths(out, scale);
}

std::vector<Ring> rings_from_segments(const std::vector<Segment>& segs, double tol) {
  std::vector<Ring> rings;
  const auto key = [&](const P2& p) { return std::pair(std::llround(p[0] / tol), std::llround(p[1] / tol)); };
  std::multimap<std::pair<long long, long long>, size_t> ends;  // end point -> segment * 2 + which end
  for (size_t i = 0; i < segs.size(); ++i)
    for (int k = 0; k < 2; ++k) ends.emplace(key(segs[i][k]), 2 * i + size_t(k));
  std::vector<bool> used(segs.size(), false);
  // Extends the ring at its back with unused segments; true when it came back to its front.
  const auto extend = [&](Ring& ring) {
    const auto start = key(ring.front());
    for (;;) {
      const auto k = key(ring.back());
      if (k == start) {
        ring.pop_back();
        return true;
      }
      bool extended = false;
      const auto [lo, hi] = ends.equal_range(k);
      for (auto it = lo; it != hi && !extended; ++it) {
        const size_t seg = it->second / 2, end = it->second % 2;
        if (used[seg]) continue;
        used[seg] = true;
        ring.push_back(segs[seg][1 - end]);
        extended = true;
      }
      if (!extended) return false;
    }
  };
  for (size_t s = 0; s < segs.size(); ++s) {
    if (used[s]) continue;
    used[s] = true;
    Ring ring{segs[s][0], segs[s][1]};
    if (!extend(ring)) {
      std::reverse(ring.begin(), ring.end());
      extend(ring);
    }
    if (ring.size() >= 3) rings.push_back(std::move(ring));
  }
  return rings;
}

double region_area(const Region& region) {
  double a = 0;
  for (const Ring& r : region) a += signed_area(r);
  return a;
}

/// Whether a counter-clockwise ring turns left (or goes straight) at every vertex.
bool convex_ring(const Ring& r) {
  const size_t n = r.size();
  double extent = 0;
  for (const P2& p : r) extent = std::max({extent, std::abs(p[0]), std::abs(p[1])});
  const double eps = kCollinearCross * extent * extent;
  for (size_t i = 0; i < n; ++i) {
    const P2 &a = r[i], &b = r[(i + 1) % n], &c = r[(i + 2) % n];
    if ((b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]) < -eps) return false;
  }
  return true;
}

/// The rings without vertices within `tol` of the line through their neighbours (a contour
/// puts many along one straight edge; each would start a trapezoid strip).
Region without_straight_vertices(Region region, double tol) {
  for (Ring& r : region) {
    Ring kept;
    for (size_t i = 0; i < r.size(); ++i) {
      const P2& a = kept.empty() ? r.back() : kept.back();
      const P2 &b = r[i], &c = r[(i + 1) % r.size()];
      const double dx = c[0] - a[0], dy = c[1] - a[1], len = std::hypot(dx, dy);
      const double off = std::abs((b[0] - a[0]) * dy - (b[1] - a[1]) * dx);
      const bool between = (b[0] - a[0]) * dx + (b[1] - a[1]) * dy > 0 && (c[0] - b[0]) * dx + (c[1] - b[1]) * dy > 0;
      if (!(len > 0) || off > tol * len || !between) kept.push_back(b);
    }
    r = std::move(kept);
  }
  std::erase_if(region, [](const Ring& r) { return r.size() < 3; });
  return region;
}

/// The region cut into convex pieces: trapezoids between consecutive heights of its vertices
/// (in each strip the rings' edges across it, left to right, bound the filled, non-zero
/// winding intervals), each stacked on the one below while their union stays convex.
std::vector<Ring> convex_pieces(const Region& region) {
  std::vector<double> ys;
  for (const Ring& r : region)
    for (const P2& p : r) ys.push_back(p[1]);
  std::sort(ys.begin(), ys.end());
  ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
  struct Cross {
    double mid, lo, hi;  // x at the strip's middle, bottom and top
    int dir;
  };
  struct Piece {
    std::vector<P2> left, right;  // bottom to top
    Ring ring() const {
      Ring out(right.begin(), right.end());
      out.insert(out.end(), left.rbegin(), left.rend());
      return out;
    }
  };
  std::vector<Ring> out;
  std::vector<Piece> open, next;
  std::vector<Cross> cross;
  for (size_t i = 0; i + 1 < ys.size(); ++i) {
    const double y0 = ys[i], y1 = ys[i + 1];
    cross.clear();
    for (const Ring& r : region)
      for (size_t k = 0; k < r.size(); ++k) {
        const P2 &a = r[k], &b = r[(k + 1) % r.size()];
        if (std::min(a[1], b[1]) > y0 || std::max(a[1], b[1]) < y1 || a[1] == b[1]) continue;
        const auto x = [&](double y) { return a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]); };
        cross.push_back({x((y0 + y1) / 2), x(y0), x(y1), b[1] > a[1] ? 1 : -1});
      }
    std::sort(cross.begin(), cross.end(), [](const Cross& a, const Cross& b) { return a.mid < b.mid; });
    next.clear();
    int w = 0;
    for (size_t k = 0; k + 1 < cross.size(); ++k) {
      w += cross[k].dir;
      if (w == 0) continue;
      const P2 bl{cross[k].lo, y0}, br{cross[k + 1].lo, y0}, tl{cross[k].hi, y1}, tr{cross[k + 1].hi, y1};
      bool stacked = false;
      for (Piece& p : open) {
        if (p.left.empty() || p.left.back() != bl || p.right.back() != br) continue;
        Piece q = p;
        q.left.push_back(tl);
        q.right.push_back(tr);
        if (convex_ring(q.ring())) {
          next.push_back(std::move(q));
          p.left.clear();  // continued
          stacked = true;
        }
        break;
      }
      if (!stacked) next.push_back({{bl, tl}, {br, tr}});
    }
    for (const Piece& p : open)
      if (!p.left.empty()) out.push_back(p.ring());
    std::swap(open, next);
  }
  for (const Piece& p : open)
    if (!p.left.empty()) out.push_back(p.ring());
  // Rings that touch along an edge (Clipper's union of a fan can end so) cross each strip
  // there at one place, give or take Clipper's grid (about 1e-9 of the extent), bounding a
  // strip of no width: a segment, nothing in the region but a solid once summed with a body.
  const double scale = region_extent(region);
  std::erase_if(out, [&](const Ring& r) {
    double diameter = 0;
    for (const P2& a : r)
      for (const P2& b : r) diameter = std::max(diameter, std::hypot(a[0] - b[0], a[1] - b[1]));
    return std::abs(signed_area(r)) <= 1e-8 * scale * diameter;
  });
  return out;
}

}  // namespace pic::detail::scad
