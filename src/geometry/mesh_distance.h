// Distances from points to a triangle mesh: the nearest point over a BVH split by the surface
// area heuristic and collapsed to four children a node, leaves of up to 8 triangles; lower
// bounds (axis boxes, and with Pruning::Full oriented boxes and each triangle's plane and
// sides) measured in floats before the exact point-triangle distance (docs/algorithms.md,
// distance queries); and for a
// closed 2-manifold mesh the signed distance, its sign from the angle-weighted pseudonormal of
// the nearest feature (Baerentzen and Aanaes 2005: exact for such a mesh, no ray and no
// winding number).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "pic/types.h"

namespace pic::detail {

/// Where on a triangle a nearest point lies: a vertex (0-2), an edge (3 + k: from vertex k to
/// vertex k + 1), or its interior.
enum class Feature : uint8_t { V0, V1, V2, E01, E12, E20, Face };

struct Nearest {
  Vec3 point{};
  double distance = 0;
  uint32_t triangle = 0;
  Feature feature = Feature::Face;
};

/// The point of triangle abc nearest p, and which feature holds it.
Nearest nearest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Which lower bounds a MeshDistance keeps.
enum class Pruning : uint8_t {
  /// Axis and oriented boxes, planes and sides: for queries at a distance from the surface
  /// (offsets), where near-ties need more than boxes to tell apart.
  Full,
  /// Axis boxes only: a third of the memory and a fraction of the build, for queries on or
  /// next to the surface within a small radius (a simplification's `within` of its raw
  /// contour), where the small triangles' boxes already hold them closely.
  Boxes,
};

class MeshDistance {
 public:
  explicit MeshDistance(const TriMesh& mesh, Pruning pruning = Pruning::Full);
  /// Unsigned distance from p to the mesh (infinity for an empty mesh).
  double distance(const Vec3& p) const;
  /// Whether some triangle lies within r of p. `hint` (opaque, optional): where a point close
  /// by found one; the triangles of its leaf and the leaves beside it are looked at first, and
  /// the nearest of them within r is taken; else the search ends at the first one found. The
  /// hint is set to the triangle taken, `found` (optional) to its distance, at most r.
  bool within(const Vec3& p, double r, uint32_t* hint = nullptr, double* found = nullptr) const;
  /// Every triangle within r of p, with its point nearest p (`triangle`: its index in the
  /// mesh), into `out` (cleared first). Returns the place in `out` of the nearest (least
  /// distance, then least index: `nearest`'s answer, but where p lies on the mesh, which
  /// `nearest` takes as the first at distance 0 it meets), or 0 when none.
  size_t nearest_within(const Vec3& p, double r, std::vector<Nearest>& out) const;
  /// The hint that names the mesh's triangle t (for a point next to it).
  uint32_t hint_of(uint32_t t) const { return slot_of_[t]; }
  /// Whether every triangle lies farther than r from the box [lo, hi], proven (false when
  /// unsure: a triangle's bounds, its plane and its distance from the box's centre or its
  /// octants' centres each may prove it away).
  bool farther_than(const Vec3& lo, const Vec3& hi, double r) const;
  /// The mesh's point nearest p (the mesh must have a triangle). `hint`, when given, names
  /// where the answer for a point close by was found (opaque; start with 0): that triangle's
  /// distance bounds the search from the start. It is set to this answer's.
  Nearest nearest(const Vec3& p, uint32_t* hint = nullptr) const;
  /// The distance from p to the triangle a hint names (set by `nearest`): at least distance(p).
  double distance_to_hint(const Vec3& p, uint32_t hint) const;

 private:
  // Boxes in float, rounded outward: a box only prunes, and four of them side by side (a
  // node's children, half a leaf's triangles) are measured in one vector operation.
  /// Four children's boxes, axis by axis; an unused slot's box is empty (lo +inf, hi -inf).
  /// With Pruning::Full each child has a second box, oriented to its triangles: one axis along
  /// their mean normal and two across it, so that a flat or gently curved patch fills it
  /// closely (an axis box holds a tilted patch loosely, and a point above it is near the box
  /// but far from the patch).
  struct Node4 {
    alignas(16) float lo[3][4], hi[3][4];
    alignas(16) float axis[3][3][4];     // oriented box: axis k's component j
    alignas(16) float along[3][2][4];    // its extent along axis k: [0] low, [1] high
    uint32_t child[4];  // kLeafBit set: a leaf's number, else a node's
  };
  /// A leaf's triangles' boxes axis by axis, slot by slot (slots past its count empty). Its
  /// triangles are tris_[first, first + count).
  struct LeafBoxes {
    alignas(16) float lo[3][8], hi[3][8];
    uint32_t first = 0, count = 0;
  };
  /// The same triangles' planes (unit normal, offset) and, in each plane, the lines of their
  /// three sides (unit normal pointing out of the triangle, offset).
  struct LeafPlanes {
    alignas(16) float plane[4][8];
    alignas(16) float side[3][4][8];
  };
  struct LeafTriangle {
    Vec3 a, b, c;
    uint32_t id;    // index in the mesh
    uint32_t leaf;  // the leaf holding it
  };
  static constexpr uint32_t kLeafBit = 1u << 31;
  static constexpr uint32_t kNoChild = ~uint32_t{0};  // a Node4's unused slots (the last ones)
  /// Triangles per leaf at most: a leaf's eight slots.
  static constexpr uint32_t kLeafSize = 8;
  static_assert(sizeof(LeafPlanes::plane[0]) == kLeafSize * sizeof(float));

  /// The binary tree the surface area heuristic builds, collapsed into Node4s after.
  struct BNode {
    Vec3 lo, hi;
    uint32_t first = 0;  // internal: children at first, first + 1; leaf: range in the order
    uint32_t count = 0;  // 0 = internal
  };
  struct Bounds {
    Vec3 lo, hi;
    void grow(const Vec3& l, const Vec3& h) {
      for (int k = 0; k < 3; ++k) lo[k] = l[k] < lo[k] ? l[k] : lo[k], hi[k] = h[k] > hi[k] ? h[k] : hi[k];
    }
  };
  /// Where a node's triangles split (order[first, mid) and order[mid, last)) and each run's box.
  struct Split {
    uint32_t mid = 0;
    Bounds left, right;
  };
  /// Node out[self] over order[first, last), whose triangles' boxes fill `box`; its
  /// descendants appended to `out`.
  static void build(std::vector<BNode>& out, uint32_t self, const Bounds& box, uint32_t first, uint32_t last,
                    std::vector<uint32_t>& order, const std::vector<Vec3>& lo, const std::vector<Vec3>& hi,
                    const std::vector<Vec3>& centre);
  /// Reorders order[first, last) into two runs, the split the surface area heuristic picks.
  static Split split(uint32_t first, uint32_t last, std::vector<uint32_t>& order, const std::vector<Vec3>& lo,
                     const std::vector<Vec3>& hi, const std::vector<Vec3>& centre);
  static Bounds bounds(uint32_t first, uint32_t last, const std::vector<uint32_t>& order, const std::vector<Vec3>& lo,
                    const std::vector<Vec3>& hi);
  /// Each binary node's run of the order: [first, last).
  static std::vector<std::pair<uint32_t, uint32_t>> runs_of(const std::vector<BNode>& binary);
  /// The reference (node or leaf) for binary node `b`, its Node4s and leaves appended with
  /// their axis boxes and runs; each Node4 child's oriented box is due later, listed in
  /// `oriented` (node, slot, its run of the order from `range`; none listed when `range` is
  /// empty: Pruning::Boxes).
  uint32_t collapse(const std::vector<BNode>& binary, const std::vector<std::pair<uint32_t, uint32_t>>& range,
                    uint32_t b, uint32_t depth, std::vector<std::array<uint32_t, 4>>& oriented);
  /// tris_ in the order, and every leaf's triangles' boxes (and planes and sides, for Full).
  void fill_leaves(const TriMesh& mesh, const std::vector<uint32_t>& order, const std::vector<Vec3>& lo,
                   const std::vector<Vec3>& hi);
  /// The oriented boxes listed by collapse, from tris_.
  void fill_oriented_boxes(const std::vector<std::array<uint32_t, 4>>& due);
  /// Slot i of n: the oriented box of `count` triangles (`normals`: theirs times twice their
  /// area).
  static void set_oriented_box(Node4& n, uint32_t i, const LeafTriangle* tris, const Vec3* normals, uint32_t count);
  template <class Visit>
  void search(const Vec3& p, double& best2, Visit&& visit) const;
  /// Slot i of l (which bounds nothing yet): triangle abc's plane and sides, each one its
  /// corners lie on within `tolerance`.
  static void set_planes(LeafPlanes& l, uint32_t i, const Vec3& a, const Vec3& b, const Vec3& c, double tolerance);

  const LeafPlanes* planes_of(uint32_t leaf) const { return planes_.empty() ? nullptr : &planes_[leaf]; }

  Pruning pruning_;
  uint32_t root_ = 0;
  std::vector<Node4> nodes_;
  std::vector<LeafBoxes> leaves_;
  std::vector<LeafPlanes> planes_;  // per leaf (Full), or none
  uint32_t depth_ = 0;  // Node4 levels below the root
  // The mesh's share of every query's slack: kPlaneRounding times its largest coordinate (the
  // query point adds its own).
  float rounding_ = 0;
  bool far_ = false;  // a coordinate beyond kFar: the float bounds are not used
  std::vector<LeafTriangle> tris_;  // in the tree's order: each leaf's run contiguous
  std::vector<uint32_t> slot_of_;   // per mesh triangle: its place in tris_
};

/// Signed distance to a closed 2-manifold mesh (negative inside). Keeps a reference to `mesh`.
class SignedDistance {
 public:
  explicit SignedDistance(const TriMesh& mesh);
  double operator()(const Vec3& p, uint32_t* hint = nullptr) const;
  /// The signed distance and its gradient (unit length, pointing outward; the nearest
  /// face's normal where p is on the surface). `hint`: see MeshDistance::nearest.
  /// `nearest`, when given, gets the mesh point nearest p; `feature` the whole answer (its
  /// triangle and which feature of it).
  double with_gradient(const Vec3& p, Vec3& gradient, uint32_t* hint = nullptr, Vec3* nearest = nullptr,
                       Nearest* feature = nullptr) const;
  /// The signed distance and gradient (as with_gradient) from the mesh point nearest p,
  /// found already.
  double signed_at(const Vec3& p, const Nearest& n, Vec3& gradient) const;
  const MeshDistance& mesh_distance() const { return distance_; }

 private:
  const TriMesh& mesh_;
  MeshDistance distance_;
  std::vector<Vec3> face_normal_, vertex_normal_;
  std::vector<std::array<Vec3, 3>> edge_normal_;  // per triangle, edge k: from vertex k to k + 1
  double on_surface_ = 0;                          // nearer than this: on the surface
};

}  // namespace pic::detail
