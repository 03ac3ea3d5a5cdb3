// Exact geometric predicates on double coordinates (filtered, exact fallback).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "pic/types.h"

namespace pic::detail {

/// Sign of det[b-a, c-a, d-a] (CGAL::orientation(a, b, c, d)): +1, 0 or -1, exact.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);
/// Sign of the 2D orientation of (a, b, c) projected along axis `drop` (0, 1, 2), exact.
int orient2d(const Vec3& a, const Vec3& b, const Vec3& c, int drop);
/// An axis along which triangle abc projects to a non-degenerate triangle, or -1 when the
/// triangle is collinear (exact).
int projection_axis(const Vec3& a, const Vec3& b, const Vec3& c);
/// Whether the closed segment pq meets the closed, non-degenerate triangle abc (exact).
bool segment_meets_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c);

/// CGAL's self-intersection rule for two non-degenerate triangles of one mesh (vertex indices
/// into `x`, equal positions already merged): sharing an edge, they intersect only when
/// coplanar and folded onto the same side; sharing a vertex, when the edge opposite it in one
/// meets the other; otherwise when the closed triangles meet. Exact.
bool triangles_intersect(const std::vector<Vec3>& x, const std::array<uint32_t, 3>& ta,
                         const std::array<uint32_t, 3>& tb);

}  // namespace pic::detail
