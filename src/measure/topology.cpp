#include <algorithm>
#include <array>
#include <vector>

#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include "geometry/weld.h"
#include "measure/topology.h"
#include "octree/cell.h"

namespace pic {
namespace detail {

MeshTopology analyze_topology(const TriMesh& mesh, std::vector<uint8_t>* off_fan) {
  MeshTopology r;
  if (off_fan) off_fan->assign(mesh.positions.size(), 0);
  r.vertices = mesh.positions.size();
  r.triangles = mesh.triangles.size();
  const auto degenerate = [](const std::array<uint32_t, 3>& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; };
  // Each vertex's triangles (CSR), with the corner it is at.
  const size_t nv = mesh.positions.size();
  std::vector<uint32_t> first(nv + 1, 0);
  for (const auto& t : mesh.triangles) {
    if (degenerate(t)) {
      ++r.degenerate_triangles;
      if (off_fan)
        for (uint32_t v : t) (*off_fan)[v] = 1;
      continue;
    }
    for (uint32_t v : t) ++first[v + 1];
  }
  for (size_t v = 0; v < nv; ++v) first[v + 1] += first[v];
  std::vector<uint32_t> corner(first.back());  // 3 * triangle + corner
  {
    std::vector<uint32_t> fill(first.begin(), first.end() - 1);
    for (uint32_t f = 0; f < mesh.triangles.size(); ++f)
      if (!degenerate(mesh.triangles[f]))
        for (uint32_t k = 0; k < 3; ++k) corner[fill[mesh.triangles[f][k]]++] = 3 * f + k;
  }
  // Per vertex v: its edges to higher vertices (counted once, here) and whether its triangles
  // form one fan (joined across the edges at v).
  struct Counts {
    size_t boundary = 0, nonmanifold = 0, inconsistent = 0, pinched = 0;
  };
  tbb::combinable<Counts> counts;
  // The common case, tested without sorting: every edge at v is used by exactly two of v's
  // triangles, once each way. Then "next of i is previous of j" is a permutation of the
  // triangles and its cycles are v's fans. Returns their count, or 0 if the case does not hold.
  // The previous vertices go into a small hash table (distinct, or the case does not hold);
  // each next must find one that no other next found.
  constexpr uint32_t kFastFan = 32, kSlots = 64, kEmpty = ~uint32_t{0};
  const auto closed_fan_cycles = [&](size_t v, uint32_t n) {
    std::array<uint32_t, kFastFan> next, succ;
    std::array<uint32_t, kSlots> key;
    std::array<uint8_t, kSlots> owner;
    key.fill(kEmpty);
    const auto hash = [](uint32_t x) { return (x * 0x9E3779B1u) >> 26; };
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t h = corner[first[v] + i];
      const auto& t = mesh.triangles[h / 3];
      next[i] = t[(h % 3 + 1) % 3];
      const uint32_t prev = t[(h % 3 + 2) % 3];
      uint32_t s = hash(prev);
      for (; key[s] != kEmpty; s = (s + 1) % kSlots)
        if (key[s] == prev) return 0;
      key[s] = prev;
      owner[s] = uint8_t(i);
    }
    std::array<bool, kFastFan> taken{};
    for (uint32_t i = 0; i < n; ++i) {
      uint32_t s = hash(next[i]);
      while (key[s] != kEmpty && key[s] != next[i]) s = (s + 1) % kSlots;
      if (key[s] == kEmpty || taken[owner[s]]) return 0;
      taken[owner[s]] = true;
      succ[i] = owner[s];
    }
    // Every next matched a distinct previous, so succ is a permutation.
    int cycles = 0;
    std::array<bool, kFastFan> seen{};
    for (uint32_t i = 0; i < n; ++i) {
      if (seen[i]) continue;
      ++cycles;
      for (uint32_t j = i; !seen[j]; j = succ[j]) seen[j] = true;
    }
    return cycles;
  };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 4096), [&](const tbb::blocked_range<size_t>& range) {
    Counts& c = counts.local();
    // A spoke: the edge's other vertex (high 32 bits), the triangle within the fan, and whether
    // the triangle runs v -> other along it (low bit); sorted by other vertex.
    std::vector<uint64_t> spokes;
    std::vector<uint32_t> parent;
    for (size_t v = range.begin(); v < range.end(); ++v) {
      const uint32_t n = first[v + 1] - first[v];
      if (n == 0) continue;
      if (n <= kFastFan) {
        const int cycles = closed_fan_cycles(v, n);
        if (cycles == 1) continue;
        if (off_fan) (*off_fan)[v] = 1;
        if (cycles > 1) {
          ++c.pinched;
          continue;
        }
      }
      if (off_fan) (*off_fan)[v] = 1;
      spokes.clear();
      for (uint32_t i = 0; i < n; ++i) {
        const uint32_t h = corner[first[v] + i], f = h / 3, k = h % 3;
        const auto& t = mesh.triangles[f];
        spokes.push_back(uint64_t(t[(k + 1) % 3]) << 32 | uint64_t(i) << 1 | 1);
        spokes.push_back(uint64_t(t[(k + 2) % 3]) << 32 | uint64_t(i) << 1);
      }
      std::sort(spokes.begin(), spokes.end());
      parent.resize(n);
      for (uint32_t i = 0; i < n; ++i) parent[i] = i;
      const auto root = [&](uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
      };
      const auto other = [](uint64_t s) { return uint32_t(s >> 32); };
      const auto slot = [](uint64_t s) { return uint32_t(s) >> 1; };
      for (size_t i = 0; i < spokes.size();) {
        size_t j = i;
        uint32_t out = 0;
        while (j < spokes.size() && other(spokes[j]) == other(spokes[i])) {
          out += uint32_t(spokes[j] & 1);
          parent[root(slot(spokes[j]))] = root(slot(spokes[i]));
          ++j;
        }
        if (other(spokes[i]) > v) {
          const size_t uses = j - i;
          if (uses == 1) ++c.boundary;
          if (uses > 2) ++c.nonmanifold;
          if (uses == 2 && out != 1) ++c.inconsistent;
        }
        i = j;
      }
      uint32_t roots = 0;
      for (uint32_t i = 0; i < n; ++i) roots += root(i) == i;
      c.pinched += roots > 1;
    }
  });
  counts.combine_each([&](const Counts& c) {
    r.boundary_edges += c.boundary;
    r.nonmanifold_edges += c.nonmanifold;
    r.inconsistent_edges += c.inconsistent;
    r.nonmanifold_vertices += c.pinched;
  });
  return r;
}

}  // namespace detail

MeshTopology analyze_topology(const TriMesh& mesh) { return detail::analyze_topology(mesh, nullptr); }

MeshTopology analyze_welded_topology(const TriMesh& mesh) { return analyze_topology(detail::weld(mesh)); }

double volume(const TriMesh& mesh) {
  double v = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
    v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
         a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return v / 6;
}

}  // namespace pic
