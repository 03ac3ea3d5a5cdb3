// Exact and filtered predicates on grid triangles (src/geometry.h).

#include <gtest/gtest.h>

#include <random>

#include "geometry/lattice.h"

namespace pic::detail {
namespace {

// A random triangle near `box`: long slivers (the case the edge axes are for) and small ones.
ITri random_triangle(std::mt19937_64& rng, const IBox& box) {
  const double size = double(box.hi[0] - box.lo[0]);
  std::uniform_real_distribution<double> u(-1.0, 2.0);
  std::uniform_real_distribution<double> v(-0.02, 0.02);
  I3 p[3];
  const bool sliver = rng() % 2;
  for (int k = 0; k < 3; ++k) {
    const double base = u(rng);
    for (int i = 0; i < 3; ++i) {
      const double x = sliver && i > 0 ? base + (k == 0 ? 3 * u(rng) : v(rng)) : u(rng);
      p[i][k] = box.lo[k] + i64(x * size);
    }
  }
  return make_itri(p[0], p[1], p[2]);
}

IBox child_box(const IBox& b, int c) {
  IBox out;
  for (int k = 0; k < 3; ++k) {
    const i64 mid = (b.lo[k] + b.hi[k]) / 2;
    out.lo[k] = (c >> k) & 1 ? mid : b.lo[k];
    out.hi[k] = (c >> k) & 1 ? b.hi[k] : mid;
  }
  return out;
}

TEST(Geometry, ChildEdgeTestKeepsEveryTriangleThatMeetsTheChild) {
  std::mt19937_64 rng(7);
  const IBox parent = cell_box(9, {300 << 11, 1000 << 11, 77 << 11});
  int met = 0, agree = 0, total = 0;
  for (int n = 0; n < 20000; ++n) {
    const ITri t = random_triangle(rng, parent);
    if (is_degenerate(t)) continue;
    const ChildEdgeTest test(t, parent);
    for (int c = 0; c < 8; ++c) {
      const IBox cb = child_box(parent, c);
      const bool meets = clipped_area(t, cb) >= 0;
      met += meets;
      // Never drops a triangle that meets the child's box (the lists stay conservative).
      if (meets) ASSERT_TRUE(test.may_touch(c)) << "triangle " << n << " child " << c;
      agree += test.may_touch(c) == edges_may_touch_box(t, cb.lo, cb.hi);
      ++total;
    }
  }
  EXPECT_GT(met, 1000);
  // Shifted projections decide like the direct test except within the rounding margin.
  EXPECT_GE(agree, total - total / 1000);
}

}  // namespace
}  // namespace pic::detail
