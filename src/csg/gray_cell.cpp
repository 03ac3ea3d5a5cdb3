// GraycellCSG's predicates (paper Figure 3): whether the summed QEF's vertex may stand for the
// result in a cell, or the cell must be subdivided. See gray_cell.h.
#include "csg/gray_cell.h"

#include <algorithm>

#include "geometry/tolerances.h"
#include "geometry/vec3.h"

namespace pic::detail {

namespace {

/// Corners i and j of a cell joined by a cube edge.
bool adjacent_corners(int i, int j) { return std::popcount(unsigned(i ^ j)) == 1; }

/// The result's signs between a finest cell's corners, from the two operands (their signs at
/// the finer lattice points half-way).
struct HalfwaySigns {
  CsgOp op;
  Operand& xa;
  Operand& xb;
  const Cell& cell;
  bool between(int i, int j) const {
    const Lat p = cell.corner(i), q = cell.corner(j);
    const Lat m{(p[0] + q[0]) / 2, (p[1] + q[1]) / 2, (p[2] + q[2]) / 2};
    return apply(op, xa.sign(m), xb.sign(m));
  }
};

/// Whether all the corners of sign `inside` are one component once the result's sign half-way
/// between two of them (a face or body diagonal) may join them.
bool joined_halfway(const HalfwaySigns& h, uint8_t sr, bool inside) {
  std::array<int, 8> comp;  // union-find over the corners
  for (int i = 0; i < 8; ++i) comp[i] = i;
  auto root = [&](int i) {
    while (comp[i] != i) i = comp[i];
    return i;
  };
  auto has = [&](int i) { return bool((sr >> i) & 1) == inside; };
  for (int i = 0; i < 8; ++i)
    for (int j = i + 1; j < 8; ++j)
      if (has(i) && has(j) && adjacent_corners(i, j)) comp[root(j)] = root(i);
  for (int i = 0; i < 8; ++i)
    for (int j = i + 1; j < 8; ++j)
      if (has(i) && has(j) && root(i) != root(j) && h.between(i, j) == inside) comp[root(j)] = root(i);
  int first = -1;
  for (int i = 0; i < 8; ++i)
    if (has(i)) {
      if (first < 0) first = i;
      if (root(i) != root(first)) return false;
    }
  return true;
}

/// The corner of the other sign whose flip to `inside` leaves the cell one component, with the
/// most of its edges' midpoints on the `inside` side; -1 when no flip does.
int corner_to_join(const HalfwaySigns& h, uint8_t sr, bool inside) {
  int best = -1, best_score = -1;
  for (int k = 0; k < 8; ++k) {
    if (bool((sr >> k) & 1) == inside) continue;
    const uint8_t flipped = uint8_t(sr ^ (1 << k));
    if (flipped != 0 && flipped != 0xff && !one_component(flipped)) continue;
    int score = 0;
    for (int a = 0; a < 3; ++a) score += h.between(k, k ^ (1 << a)) == inside;
    if (score > best_score) {
      best_score = score;
      best = k;
    }
  }
  return best;
}

}  // namespace

/// A finest leaf whose corner signs make more than one component (corners of one sign meeting
/// only diagonally): the clean-up must flip a corner, and its default (flip the minority sign)
/// erases a solid or a gap about a cell thick lying obliquely to the lattice, whose lattice
/// points meet only diagonally (a box face and a torus meeting at a shallow angle: a slab 1-2
/// cells thick cut to pieces). The operands know better: the
/// result's sign half-way between two such corners says whether the solid (or the gap) joins
/// them. When it joins all the corners of one sign, the hint flips a corner of the other sign
/// to it. Nothing when it joins neither (a feature thinner than a cell).
std::optional<SignHint> sign_hint(CsgOp op, Operand& xa, Operand& xb, const Cell& cell, uint8_t sr) {
  const HalfwaySigns h{op, xa, xb, cell};
  for (const bool inside : {true, false}) {
    if (!joined_halfway(h, sr, inside)) continue;
    if (const int k = corner_to_join(h, sr, inside); k >= 0) return SignHint{cell.corner(k), inside};
  }
  return std::nullopt;
}

namespace {

struct EdgeCrossing {
  bool change;
  double t;
  int count;
};
EdgeCrossing edge_crossing(const Operand& x, const Side& s, const I3& a, int axis, i64 len, int c0, int c1) {
  EdgeCrossing r{(((s.signs >> c0) ^ (s.signs >> c1)) & 1) != 0, 0.5, 0};
  for (uint32_t k : s.idx) {
    if (crosses(x.tris[k], a, axis, len)) {
      if (r.count == 0) r.t = crossing_param(x.tris[k], a, axis, len);
      ++r.count;
    }
  }
  return r;
}


}  // namespace

/// Directed distances on each edge and the 1D CSG of the two crossings (paper 5.2.3,
/// Table 1): two result crossings on one edge force a subdivision, as do two crossings of one
/// operand on an edge of a virtual cell.
EdgeVerdict edge_verdict(CsgOp op, const Operand& xa, const Side& a, const Operand& xb, const Side& b,
                         const Cell& cell) {
  EdgeVerdict v;
  const i64 len = lattice_to_grid(cell.span());
  for (int e = 0; e < 12; ++e) {
    const int c0 = kEdgeCorners[e][0], c1 = kEdgeCorners[e][1], axis = edge_axis(e);
    const I3 p = lattice_to_grid(cell.corner(c0));
    const EdgeCrossing ea = edge_crossing(xa, a, p, axis, len, c0, c1);
    const EdgeCrossing eb = edge_crossing(xb, b, p, axis, len, c0, c1);
    if ((!a.real && ea.count >= 2) || (!b.real && eb.count >= 2)) {
      v.must_split = true;
      return v;
    }
    if (!ea.change && !eb.change) continue;
    const bool a0 = (a.signs >> c0) & 1, b0 = (b.signs >> c0) & 1;
    auto in_a = [&](double t) { return ea.change ? (t < ea.t ? a0 : !a0) : a0; };
    auto in_b = [&](double t) { return eb.change ? (t < eb.t ? b0 : !b0) : b0; };
    int n_r = 0;
    if (ea.change && eb.change && ea.t == eb.t) {
      n_r = apply(op, a0, b0) != apply(op, !a0, !b0);
      v.vis_a = v.vis_b = v.vis_a || n_r;
    } else if (ea.change && eb.change && std::abs(ea.t - eb.t) * cell.size() <= kCoincident &&
               apply(op, a0, b0) == apply(op, !a0, !b0)) {
      // Nearly one crossing, and the result does not change across it: the sliver between
      // the two is no crossing at all. (When it does change, the order of the two decides
      // which operand's surface the result shows, as below.)
    } else {
      if (ea.change) {
        const bool vis = apply(op, a0, in_b(ea.t)) != apply(op, !a0, in_b(ea.t));
        n_r += vis;
        v.vis_a = v.vis_a || vis;
      }
      if (eb.change) {
        const bool vis = apply(op, in_a(eb.t), b0) != apply(op, in_a(eb.t), !b0);
        n_r += vis;
        v.vis_b = v.vis_b || vis;
      }
    }
    if (n_r >= 2) {
      v.must_split = true;
      return v;
    }
  }
  return v;
}

namespace {

/// A crossing of the result's surface along a cell edge: where (edge parameter) and which way
/// the surface faces there.
struct ShownCrossing {
  Vec3 normal;
  double t;
};

/// The crossings the result shows along the edge from corner c0 (grid point p, `axis`, length
/// `len`): every crossing of A's and B's partial contours in order, through the 1D Boolean,
/// crossings within kCoincident of each other taken as one (faces the operands share). Empty
/// when a crossing's triangle stands beside a capped leaf (PartialContour::rough): its vertex
/// fits no plane and may lie a cell off, so no gap beside it says anything.
std::vector<ShownCrossing> shown_crossings(CsgOp op, const Operand& xa, const Side& a, const Operand& xb,
                                           const Side& b, const Cell& cell, const I3& p, int axis, i64 len, int c0) {
  struct Crossing {
    double t;
    Vec3 normal;  // as the result's surface would face there
    bool of_b;
  };
  std::vector<Crossing> xs;
  for (uint32_t k : a.idx)
    if (crosses(xa.tris[k], p, axis, len)) {
      if (xa.pc.rough[k]) return {};
      xs.push_back({crossing_param(xa.tris[k], p, axis, len), xa.tris[k].unit_normal, false});
    }
  const double flip_b = op == CsgOp::Subtract ? -1 : 1;
  for (uint32_t k : b.idx)
    if (crosses(xb.tris[k], p, axis, len)) {
      if (xb.pc.rough[k]) return {};
      xs.push_back({crossing_param(xb.tris[k], p, axis, len), scale3(xb.tris[k].unit_normal, flip_b), true});
    }
  if (xs.size() < 2) return {};
  std::sort(xs.begin(), xs.end(), [](const Crossing& u, const Crossing& v) { return u.t < v.t; });
  bool in_a = (a.signs >> c0) & 1, in_b = (b.signs >> c0) & 1;
  bool r = apply(op, in_a, in_b);
  std::vector<ShownCrossing> shown;
  const double together = kCoincident / cell.size();
  for (size_t i = 0; i < xs.size();) {
    const Vec3* normal = nullptr;  // the group's first crossing that changes the result
    size_t j = i;
    for (; j < xs.size() && xs[j].t - xs[i].t <= together; ++j) {
      (xs[j].of_b ? in_b : in_a) = !(xs[j].of_b ? in_b : in_a);
      if (!normal && apply(op, in_a, in_b) != r) normal = &xs[j].normal;
    }
    if (apply(op, in_a, in_b) != r) shown.push_back({*normal, xs[i].t});
    r = apply(op, in_a, in_b);
    i = j;
  }
  return shown;
}

}  // namespace

void thin_feature_hints(CsgOp op, const Operand& xa, const Side& a, const Operand& xb, const Side& b, const Cell& cell,
                        uint8_t sr, double error, std::vector<SignHint>& out) {
  // Each operand's surface may lie up to about sqrt(error) off the solid it stands for (the
  // QEF residual is a squared distance, weighted by area per cell face): a gap narrower than
  // that between A's face and B's is how two coinciding faces show (stacked parts), not a feature.
  const double min_width = std::sqrt(error);
  const i64 len = lattice_to_grid(cell.span());
  for (int e = 0; e < 12; ++e) {
    const int c0 = kEdgeCorners[e][0], c1 = kEdgeCorners[e][1];
    const bool end_sign = (sr >> c0) & 1;
    if (end_sign != bool((sr >> c1) & 1)) continue;
    const I3 p = lattice_to_grid(cell.corner(c0));
    const std::vector<ShownCrossing> seen = shown_crossings(op, xa, a, xb, b, cell, p, edge_axis(e), len, c0);
    bool thin = false, twice = false;
    for (size_t i = 0; i < seen.size(); ++i)
      for (size_t j = i + 1; j < seen.size(); ++j) {
        if (std::abs(seen[i].t - seen[j].t) * cell.size() <= min_width) continue;
        twice = true;
        thin = thin || dot3(seen[i].normal, seen[j].normal) < -kThinFeatureTurn;
      }
    if (!twice) continue;
    const auto kind = thin ? SignHint::Kind::Thin : SignHint::Kind::BesideThin;
    out.push_back(SignHint{cell.corner(c0), !end_sign, kind});
    out.push_back(SignHint{cell.corner(c1), !end_sign, kind});
  }
}

bool same_surface(const Operand& xa, const Side& a, const Operand& xb, const Side& b) {
  if (a.idx.size() != b.idx.size()) return false;
  const auto corners = [](const Operand& x, const Side& s) {
    std::vector<std::array<I3, 3>> v;
    v.reserve(s.idx.size());
    for (uint32_t k : s.idx) v.push_back(x.tris[k].v);
    std::sort(v.begin(), v.end());
    return v;
  };
  return corners(xa, a) == corners(xb, b);
}

/// Whether the two operands' partial contours meet inside the cell.
bool surfaces_meet(const Operand& xa, const Side& a, const Operand& xb, const Side& b, const Cell& cell) {
  for (uint32_t i : a.idx)
    for (uint32_t j : b.idx)
      if (triangles_meet_in_box(xa.tris[i], xb.tris[j], cell.box())) return true;
  return false;
}

bool surfaces_coincide(const Operand& xa, const Side& a, const Operand& xb, const Side& b, const Cell& cell) {
  if (a.idx.empty() || b.idx.empty()) return false;
  // Within a millionth of the cell, or a few float steps of the unit cube (the operands' float
  // vertices on one exact plane).
  const double tol = std::max(kCoincidentRelative * cell.size(), kCoincident);
  const auto same_plane = [&](const ITri& s, const ITri& t) {
    const double c = dot3(s.unit_normal, t.unit_normal);
    if (std::abs(std::abs(c) - 1) > kParallelCosine) return false;
    return std::abs((c > 0 ? t.plane : -t.plane) - s.plane) <= tol;
  };
  // Every plane of one operand here is a plane of the other (a cutter flush with a face, or
  // with an edge or corner: two or three planes each).
  const auto covered = [&](const Operand& x, const Side& s, const Operand& y, const Side& t) {
    for (uint32_t i : s.idx) {
      bool found = false;
      for (uint32_t j : t.idx)
        if (same_plane(y.tris[j], x.tris[i])) {
          found = true;
          break;
        }
      if (!found) return false;
    }
    return true;
  };
  return covered(xa, a, xb, b) && covered(xb, b, xa, a);
}

/// The new feature (where the two surfaces meet) must also fit one point or line over the
/// cell grown by half its size on every side: dual contouring joins this vertex to its
/// neighbours' by straight edges, so a curved intersection (a hole's rim) is refined until
/// those edges follow it. Not in the paper, whose per-cell test lets big cells sit on a
/// curved rim and chords cut across it.
bool feature_is_local(const Operand& xa, const Operand& xb, const Cell& cell, const Vec3& x, double error,
                      std::vector<uint32_t>& scratch) {
  IBox g = cell.box();
  const i64 h = lattice_to_grid(cell.span()) / 2;
  for (int k = 0; k < 3; ++k) {
    g.lo[k] = std::max<i64>(0, g.lo[k] - h);
    g.hi[k] = std::min<i64>(i64{1} << kGridBits, g.hi[k] + h);
  }
  const double face = 4 * cell.size() * cell.size();
  Qef q;
  scratch.clear();
  xa.bvh.query(xa.tris, g.lo, g.hi, scratch);
  box_qef(xa.tris, scratch, g, face, q);
  scratch.clear();
  xb.bvh.query(xb.tris, g.lo, g.hi, scratch);
  box_qef(xb.tris, scratch, g, face, q);
  // A shallow crease over the grown cell is still one line (see Qef::Pinv::Damped).
  return q.solve(x).error < error || q.solve(x, Qef::Pinv::Damped).error < kSharpFit * error;
}

/// The result's signs on the cell's child grid are simple (see grid_is_simple): otherwise a
/// leaf here would meet finer neighbours showing a second sheet on its faces.
bool refinement_is_simple(CsgOp op, const SignGrid& a, const SignGrid& b) {
  std::array<bool, 27> g{};
  for (int i = 0; i < 27; ++i) g[i] = apply(op, a[i], b[i]);
  return grid_is_simple(g);
}

CellQefs cell_qefs(const Operand& xa, const Side& a, const Operand& xb, const Side& b, const Cell& cell) {
  CellQefs q;
  cell_qef(xa.tris, a.idx, cell, q.a);
  cell_qef(xb.tris, b.idx, cell, q.b);
  q.sum = q.a;
  q.sum += q.b;
  return q;
}

/// An operand's own vertex in the cell: the leaf's stored one, or the minimizer of its QEF in
/// a virtual cell.
Vec3 operand_vertex(const Operand& x, const Side& s, const Qef& q, const Cell& cell) {
  if (s.real) return vertex_unit(cell, x.t.vertices[x.t.nodes[s.node].index]);
  return cell_vertex(q, cell, s.signs, true).position;
}

}  // namespace pic::detail
