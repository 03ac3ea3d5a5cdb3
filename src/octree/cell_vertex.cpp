// The representative vertex of a gray cell (paper section 4, Figure 2).
#include "octree/cell_vertex.h"
#include "geometry/tolerances.h"

#include <bit>

namespace pic::detail {

bool inside_cell(const Vec3& x, const Cell& cell) {
  const Vec3 m = cell.min_unit();
  const double s = cell.size();
  const double slack = kInsideCellSlack * s;
  for (int k = 0; k < 3; ++k)
    if (x[k] < m[k] - slack || x[k] > m[k] + s + slack) return false;
  return true;
}

Qef::Solution cell_vertex(const Qef& q, const Cell& cell, uint8_t signs, bool tip_at_corner, Qef::Pinv pinv) {
  const Vec3 m = cell.min_unit();
  const double s = cell.size();
  if (q.empty()) {
    // No surface to fit: a sub-cell whose corner signs disagree with the contour by less than
    // the contour's own error. Put the vertex on the sign-changing edges right next to the
    // minority corners, so the patch this makes is tiny instead of spanning the cell.
    const bool minority_inside = __builtin_popcount(signs) <= 4;
    Vec3 acc{0, 0, 0};
    int n = 0;
    for (const auto& [c0, c1] : kEdgeCorners) {
      if (!(((signs >> c0) ^ (signs >> c1)) & 1)) continue;
      const bool c0_minority = (((signs >> c0) & 1) != 0) == minority_inside;
      const double t = c0_minority ? 0.02 : 0.98;
      for (int k = 0; k < 3; ++k) acc[k] += m[k] + s * ((1 - t) * ((c0 >> k) & 1) + t * ((c1 >> k) & 1));
      ++n;
    }
    if (n == 0) return {{m[0] + s / 2, m[1] + s / 2, m[2] + s / 2}, 0, 0};
    return {{acc[0] / n, acc[1] / n, acc[2] / n}, 0, 0};
  }
  const Vec3 hi{m[0] + s, m[1] + s, m[2] + s};
  Qef::Solution sol = q.solve_in_box({m[0] + s / 2, m[1] + s / 2, m[2] + s / 2}, m, hi, pinv);
  if (const int in = std::popcount(signs); tip_at_corner && sol.rank < 3 && (in == 1 || in == 7)) {
    // A tip: one corner apart from the other seven. Where the planes leave the vertex free
    // (a face or a crease) and pass through that corner, the surface meets there (two parts
    // touching at a lattice point): the vertex belongs at the corner, not at the point of the
    // feature nearest the cell's centre, which may be half a cell away from any surface.
    const int c = std::countr_zero(unsigned(in == 1 ? signs : uint8_t(~signs)));
    const Vec3 p{m[0] + (c & 1) * s, m[1] + ((c >> 1) & 1) * s, m[2] + ((c >> 2) & 1) * s};
    if (const double e = q.error(p); e <= sol.error + kTipTolerance * s * s) return {p, e, sol.rank};
  }
  if (inside_cell(sol.position, cell)) return sol;
  // Reseed from the corner closest to the surface (smallest QEF value).
  int best = 0;
  double best_err = kHuge;
  for (int c = 0; c < 8; ++c) {
    const Vec3 p{m[0] + (c & 1) * s, m[1] + ((c >> 1) & 1) * s, m[2] + ((c >> 2) & 1) * s};
    const double e = q.error(p);
    if (e < best_err) {
      best_err = e;
      best = c;
    }
  }
  const Vec3 p{m[0] + (best & 1) * s, m[1] + ((best >> 1) & 1) * s, m[2] + ((best >> 2) & 1) * s};
  Qef::Solution again = q.solve_in_box(p, m, hi, pinv);
  return inside_cell(again.position, cell) ? again : sol;
}

Qef::Solution sharpen(const Qef& q, const Cell& cell, uint8_t signs, const Qef::Solution& sol, const Vec3& seed,
                      bool tip_at_corner, double error) {
  if (sol.error < error) return sol;
  const Vec3 lo = cell.min_unit(), hi{lo[0] + cell.size(), lo[1] + cell.size(), lo[2] + cell.size()};
  Qef::Solution sharp = q.solve_in_box(seed, lo, hi, Qef::Pinv::Damped);
  if (!inside_cell(sharp.position, cell)) sharp = cell_vertex(q, cell, signs, tip_at_corner, Qef::Pinv::Damped);
  return sharp.error < kSharpFit * error && inside_cell(sharp.position, cell) ? sharp : sol;
}

Qef::Solution cell_vertex_sharp(const Qef& q, const Cell& cell, uint8_t signs, bool tip_at_corner, double error) {
  const Vec3 lo = cell.min_unit();
  const double h = cell.size() / 2;
  return sharpen(q, cell, signs, cell_vertex(q, cell, signs, tip_at_corner), {lo[0] + h, lo[1] + h, lo[2] + h},
                 tip_at_corner, error);
}

}  // namespace pic::detail
