// A triangle's normal (its area twice over) and shape, as the simplifications measure them.
#pragma once

#include <cmath>

#include "geometry/vec3.h"

namespace pic::detail {

inline Vec3 triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c) { return cross3(sub3(b, a), sub3(c, a)); }

/// 1 for an equilateral triangle, 0 for a flat one: 4 sqrt(3) area / (sum of squared sides).
inline double triangle_quality(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = sub3(b, a), bc = sub3(c, b), ca = sub3(a, c);
  const double s = dot3(ab, ab) + dot3(bc, bc) + dot3(ca, ca);
  return s > 0 ? 2 * std::sqrt(3.0) * norm3(triangle_normal(a, b, c)) / s : 0;
}

}  // namespace pic::detail
