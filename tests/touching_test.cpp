// Booleans of boxes that touch at a corner, along an edge or over a face, overlap or lie apart,
// axis-aligned and turned, against exact volumes by inclusion-exclusion: where two parts touch,
// the result may join them or keep them apart by at most a finest cell, never lose a part.
#include <gtest/gtest.h>

#include <random>

#include "pic/pic.h"
#include "support/mesh_checks.h"

namespace pic {
namespace {

struct Box {
  Vec3 lo, hi;
  double volume() const { return (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]); }
  double edges() const { return 4 * ((hi[0] - lo[0]) + (hi[1] - lo[1]) + (hi[2] - lo[2])); }
};

double overlap_volume(const Box& a, const Box& b) {
  double v = 1;
  for (int k = 0; k < 3; ++k) v *= std::max(0.0, std::min(a.hi[k], b.hi[k]) - std::max(a.lo[k], b.lo[k]));
  return v;
}

enum class Contact { Corner, Edge, Face, Overlap, Apart };

/// A box A and a box B placed against it, meeting at contact coordinate c along the axes they
/// touch across. `step` > 0 puts every coordinate on a lattice of that pitch (the octree's
/// planes), 0 anywhere; `coarse` puts the contact on the planes of the octree's first levels,
/// where the cells around it are big unless something splits them.
std::pair<Box, Box> arrange(std::mt19937_64& rng, Contact contact, double step, bool coarse) {
  std::uniform_real_distribution<double> u(0, 1);
  auto snap = [&](double x) { return step > 0 ? std::round(x / step) * step : x; };
  Box a, b;
  // Along the axes B touches across, A ends and B starts at c; along the others their
  // ranges overlap partly.
  const int across = contact == Contact::Corner ? 3 : contact == Contact::Edge ? 2 : contact == Contact::Face ? 1 : 0;
  for (int k = 0; k < 3; ++k) {
    const double c = coarse ? 0.625 * std::floor(2 * u(rng)) : snap(0.2 + 0.5 * u(rng));
    a.hi[k] = c;
    a.lo[k] = snap(c - 0.4 - 0.5 * u(rng));
    const double len = snap(0.3 + 0.5 * u(rng));
    if (k < across) {
      b.lo[k] = c;
    } else if (contact == Contact::Apart && k == 0) {
      b.lo[k] = snap(c + 0.2 + 0.1 * u(rng));  // a gap of 2.5 cells or more at depth 6
    } else {
      b.lo[k] = snap(a.lo[k] + (a.hi[k] - a.lo[k]) * (0.2 + 0.6 * u(rng)));
    }
    b.hi[k] = b.lo[k] + len;
  }
  return {a, b};
}

struct Outcome {
  double volume = 0;
  TriMesh mesh;
};

Outcome boolean(const Box& a, const Box& b, const std::array<double, 9>& turn, CsgOp op, int depth) {
  const TriMesh ma = transformed(make_box(a.lo, a.hi), turn, {0, 0, 0});
  const TriMesh mb = transformed(make_box(b.lo, b.hi), turn, {0, 0, 0});
  SampleOptions so;
  so.depth = depth;
  so.cube = Cube{{-2.5, -2.5, -2.5}, 5.0};  // both operands on one lattice, any turn inside
  Outcome o;
  o.mesh = unsplit_contour(csg(sample(ma, so), sample(mb, so), op));
  o.volume = volume(o.mesh);
  return o;
}

TEST(Touching, RandomBoxArrangementsKeepTheirVolume) {
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> u(0, 1);
  const Contact contacts[] = {Contact::Corner, Contact::Edge, Contact::Face, Contact::Overlap, Contact::Apart};
  const CsgOp ops[] = {CsgOp::Union, CsgOp::Subtract, CsgOp::Intersect};
  int cases = 0;
  double worst = 0;  // the largest volume error as a fraction of its tolerance
  for (int i = 0; i < 240; ++i) {
    const Contact contact = contacts[i % 5];
    const int depth = 6 + (i / 5) % 5;  // 6..10; 11 and 12 below
    const bool on_lattice = (i / 25) % 2 == 0, coarse = i % 2 == 0;
    const bool turned = (i / 50) % 2 == 1;
    const double h = 5.0 / double(1 << depth);
    const auto [a, b] = arrange(rng, contact, on_lattice ? h : 0, coarse);
    std::array<double, 9> turn{1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (turned) turn = rotation({0.48, 0.6, 0.64}, 0.3 + u(rng));
    const CsgOp op = ops[(i / 5) % 3];
    if (op == CsgOp::Intersect && contact != Contact::Overlap) continue;  // empty: nothing to mesh
    const double vi = overlap_volume(a, b);
    const double exact = op == CsgOp::Union      ? a.volume() + b.volume() - vi
                         : op == CsgOp::Subtract ? a.volume() - vi
                                                 : vi;
    const Outcome r = boolean(a, b, turn, op, depth);
    // A finest cell's cross-section along every edge the result can have (its operands' edges
    // hold the contacts too): where the lattice cannot hold a crease or a contact exactly.
    const double tol = (turned ? 1.0 : 0.05) * h * h * (a.edges() + b.edges()) + 1e-6;
    EXPECT_NEAR(r.volume, exact, tol) << "case " << i << " op " << to_string(op) << " depth " << depth
                                      << (turned ? " turned" : "") << (on_lattice ? " on the lattice" : "") << (coarse ? " coarse" : "");
    EXPECT_TRUE(test::IsClosedManifold(r.mesh)) << "case " << i;
    worst = std::max(worst, std::abs(r.volume - exact) / tol);
    ++cases;
  }
  EXPECT_GE(cases, 150);
  RecordProperty("worst_error_over_tolerance", std::to_string(worst));
  printf("worst volume error / tolerance: %.3f over %d cases\n", worst, cases);
}

TEST(Touching, DeepLevelsKeepTheirVolume) {
  // The same contacts at depths 11 and 12, axis-aligned, on the coarse planes and off the lattice.
  std::mt19937_64 rng(7);
  const Contact contacts[] = {Contact::Corner, Contact::Edge, Contact::Face};
  for (int depth : {11, 12})
    for (Contact contact : contacts)
      for (CsgOp op : {CsgOp::Union, CsgOp::Subtract, CsgOp::Union}) {
        const auto [a, b] = arrange(rng, contact, 0, op == CsgOp::Union);
        const double exact = op == CsgOp::Union ? a.volume() + b.volume() : a.volume();
        const Outcome r = boolean(a, b, {1, 0, 0, 0, 1, 0, 0, 0, 1}, op, depth);
        EXPECT_NEAR(r.volume, exact, 1e-6 + 1e-6 * exact) << to_string(op) << " depth " << depth;
        EXPECT_TRUE(test::IsClosedManifold(r.mesh));
      }
}

/// Two unit cubes, A's max corner at c and B placed against it: across all three axes (a
/// corner), two (an edge half as long as a side) or one (a face).
std::pair<Box, Box> unit_pair(const Vec3& c, Contact contact) {
  const Box a{{c[0] - 1, c[1] - 1, c[2] - 1}, c};
  Box b{c, {c[0] + 1, c[1] + 1, c[2] + 1}};
  if (contact == Contact::Edge) {
    b.lo[2] -= 0.5;
    b.hi[2] -= 0.5;
  }
  if (contact == Contact::Face) {
    b.lo = {c[0], c[1] - 1, c[2] - 1};
    b.hi = {c[0] + 1, c[1], c[2]};
  }
  return {a, b};
}

TEST(Touching, CubePairsFromMeshesKeepTheirVolume) {
  // The chain's cube is the bounding cube of both: its middle is the contact for c = (1, 1, 1),
  // where the cells around it are as big as an octant; c = (0.8, 0.8, 0.8) is off the lattice.
  for (const Vec3 c : {Vec3{1, 1, 1}, Vec3{0.8, 0.8, 0.8}})
    for (Contact contact : {Contact::Corner, Contact::Edge, Contact::Face})
      for (CsgOp op : {CsgOp::Union, CsgOp::Subtract}) {
        const auto [a, b] = unit_pair(c, contact);
        std::vector<CsgOperand> operands(2);
        operands[0].mesh = make_box(a.lo, a.hi);
        operands[1].mesh = make_box(b.lo, b.hi);
        CsgChainOptions o;
        o.sampling.depth = 10;
        const TriMesh m = unsplit_contour(csg_chain(operands, {op}, o));
        EXPECT_NEAR(volume(m), op == CsgOp::Union ? 2.0 : 1.0, 1e-6) << to_string(op) << " at " << c[0];
        EXPECT_TRUE(test::IsClosedManifold(m));
      }
}

TEST(Touching, OneMeshOfTouchingPartsKeepsItsVolume) {
  // Both cubes in one mesh: two shells meeting at a corner, an edge or a face, sampled by
  // crossing parity and by winding number.
  for (const Vec3 c : {Vec3{1, 1, 1}, Vec3{0.8, 0.8, 0.8}})
    for (Contact contact : {Contact::Corner, Contact::Edge, Contact::Face})
      for (InsideMode mode : {InsideMode::Parity, InsideMode::Winding}) {
        const auto [a, b] = unit_pair(c, contact);
        TriMesh both = make_box(a.lo, a.hi);
        const TriMesh mb = make_box(b.lo, b.hi);
        const auto base = uint32_t(both.positions.size());
        both.positions.insert(both.positions.end(), mb.positions.begin(), mb.positions.end());
        for (auto t : mb.triangles) both.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
        SampleOptions so;
        so.depth = 10;
        so.inside = mode;
        const TriMesh m = unsplit_contour(sample(both, so));
        EXPECT_NEAR(volume(m), 2.0, 1e-6) << to_string(mode) << " at " << c[0] << " contact " << int(contact);
        EXPECT_TRUE(test::IsClosedManifold(m));
      }
}

}  // namespace
}  // namespace pic
