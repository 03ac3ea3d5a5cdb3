// The speck pass: closed shells or voids a cell or two across absorbed into their
// surroundings. See consistency.h (remove_specks).
#include "signs/consistency.h"
#include "signs/leaf_walks.h"
#include "geometry/key_bits.h"

#include <Eigen/Dense>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <bit>
#include <vector>

namespace pic::detail {

using Lat = std::array<int64_t, 3>;

namespace {

/// At most this many lattice points make a speck: the Boolean's specks are 1-3 points (two
/// surfaces passing within a fraction of a cell of each other); bigger regions are features.
constexpr size_t kMaxSpeckPoints = 4;

/// How thin, in finest cells, a speck that reaches a coarser leaf must be to be removed: two
/// surfaces passing within a fraction of a cell of each other (a void a quarter cell thick)
/// are; a piece a cell thick is a feature.
constexpr double kMaxSpeckThickness = 0.5;

/// The extent of points across their flattest direction (the smallest principal axis).
double thickness(const std::vector<Vec3>& pts) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Vec3& p : pts) mean += Eigen::Vector3d(p[0], p[1], p[2]);
  mean /= double(pts.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Vec3& p : pts) {
    const Eigen::Vector3d d = Eigen::Vector3d(p[0], p[1], p[2]) - mean;
    cov += d * d.transpose();
  }
  const Eigen::Vector3d axis = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  double lo = 0, hi = 0;
  for (const Vec3& p : pts) {
    const double x = (Eigen::Vector3d(p[0], p[1], p[2]) - mean).dot(axis);
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  return hi - lo;
}

/// Corners of active gray leaves at `min_level` or finer holding the leaf's minority sign
/// (both signs when tied), with that sign: where a speck's points must be.
std::vector<std::pair<Lat, bool>> speck_candidates(const Octree& t, const std::function<bool(uint32_t)>* active,
                                                   int min_level) {
  // Sorted as (point, sign) pairs are, through one 64-bit key: 21 bits a coordinate (x
  // highest), the sign lowest.
  std::vector<uint64_t> keys;
  for_each_gray_leaf(t, active, [&](uint32_t node, const Cell& cell) {
    const uint8_t s = t.nodes[node].signs;
    if (cell.level < min_level || s == 0 || s == 0xff) return;
    const int in = std::popcount(s);
    for (int c = 0; c < 8; ++c) {
      const bool sign = (s >> c) & 1;
      if (sign != (in <= 4) && in != 4) continue;
      const Lat p = cell.corner(c);
      keys.push_back(uint64_t(p[0]) << 43 | uint64_t(p[1]) << 22 | uint64_t(p[2]) << 1 | uint64_t(sign));
    }
  });
  tbb::parallel_sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<std::pair<Lat, bool>> out(keys.size());
  constexpr uint64_t kMask = (uint64_t{1} << 21) - 1;
  for (size_t i = 0; i < keys.size(); ++i)
    out[i] = {Lat{int64_t(keys[i] >> 43), int64_t(keys[i] >> 22 & kMask), int64_t(keys[i] >> 1 & kMask)}, (keys[i] & 1) != 0};
  return out;
}

/// grow_speck's buffers, kept from one call to the next (most calls stop after a few leaves).
struct SpeckScratch {
  Speck sp;
  std::vector<Vec3> vertices;  // of the speck's leaves, its surface (with coarse_rim)
};

/// Whether the region of p's sign (`inside`) connected to p through shared leaves is a speck
/// (then it is in scratch.sp): every leaf around its points gray with the point as a corner
/// (or, with `uniform_rim`, uniform of the other sign), one of them at least touched by this
/// operation (active), and at most kMaxSpeckPoints points. `seen` gets the points visited
/// either way.
bool grow_speck(const Octree& t, const std::function<bool(uint32_t)>* active, const Lat& p, bool inside,
                bool uniform_rim, bool coarse_rim, KeyBits& seen, SpeckScratch& scratch) {
  const int64_t step = int64_t{1} << (kMaxLevel - t.max_depth);
  constexpr int64_t kLimit = int64_t{1} << kMaxLevel;
  Speck& sp = scratch.sp;
  sp.inside = inside;
  sp.rim.clear();
  sp.leaves.clear();
  std::vector<Lat>& queue = sp.points;
  queue.assign(1, p);
  seen.insert(lattice_key(p), false);
  bool ok = true, touched = false, coarse = false;
  std::vector<Vec3>& vertices = scratch.vertices;
  vertices.clear();
  for (size_t i = 0; i < queue.size() && ok; ++i) {
    const Lat q = queue[i];
    for (int o = 0; o < 8 && ok; ++o) {
      Lat c;
      for (int k = 0; k < 3; ++k) {
        c[k] = q[k] - ((o >> k) & 1) * step;
        ok = ok && c[k] >= 0 && c[k] + step <= kLimit;
      }
      if (!ok) break;
      const auto [node, cell] = leaf_at(t, c);
      const Node& n = t.nodes[node];
      if (uniform_rim && n.kind != CellKind::Gray) {
        // A uniform leaf of the other sign: all of it is rim already.
        ok = (n.kind == CellKind::Black) != sp.inside;
        continue;
      }
      // A point is on the boundary of every leaf around it; with coarse_rim it need not be
      // a corner of a leaf one level coarser (its sign then is the finer side's alone). No
      // leaf may be coarser than that: the speck's leaves become uniform, and a big leaf's
      // surface is no speck (two parts' corners meeting at the point, seen from the big
      // leaves of one of them).
      const bool corner = cell.corner_index(q) >= 0;
      ok = n.kind == CellKind::Gray && cell.level >= t.max_depth - 1 && (corner || coarse_rim);
      if (!ok) break;
      coarse = coarse || !corner;
      touched = touched || !active || (*active)(node);
      sp.leaves.push_back(node);
      if (coarse_rim) vertices.push_back(vertex_unit(cell, t.vertices[n.index]));
      for (int k = 0; k < 8; ++k) {
        const Lat r = cell.corner(k);
        const bool in = (n.signs >> k) & 1;
        if (in != sp.inside) {
          sp.rim.push_back(r);
        } else if (std::find(queue.begin(), queue.end(), r) == queue.end()) {
          // A point seen before belongs to a region that was not a speck: so is this one.
          ok = seen.insert(lattice_key(r), false) && queue.size() < kMaxSpeckPoints;
          queue.push_back(r);
        }
      }
    }
  }
  if (!ok || !touched) return false;
  // Beside a coarser leaf the region may be a small real piece (4 cells across, a component
  // of the exact result too); only a flat one is the Boolean's noise.
  if (coarse && thickness(vertices) * double(int64_t{1} << t.max_depth) >= kMaxSpeckThickness) return false;
  std::sort(sp.leaves.begin(), sp.leaves.end());
  sp.leaves.erase(std::unique(sp.leaves.begin(), sp.leaves.end()), sp.leaves.end());
  return true;
}

}  // namespace

size_t remove_specks(Octree& t, const std::function<bool(uint32_t)>* active,
                     const std::function<bool(const Speck&)>& keep, const SpeckSearch& search) {
  KeyBits seen;
  SpeckScratch scratch;
  size_t removed = 0;
  for (const auto& [p, inside] : speck_candidates(t, active, search.min_level < 0 ? t.max_depth : search.min_level)) {
    if (seen.find(lattice_key(p)) >= 0) continue;
    if (!grow_speck(t, active, p, inside, search.uniform_rim, search.coarse_rim, seen, scratch)) continue;
    const Speck& sp = scratch.sp;
    if (keep(sp)) continue;
    for (uint32_t node : sp.leaves) t.nodes[node] = Node{0, sp.inside ? CellKind::White : CellKind::Black, 0, 0, 0};
    ++removed;
  }
  return removed;
}

}  // namespace pic::detail
