#include "mesh/clean.h"

#include <algorithm>
#include <cstring>
#include <unordered_map>

#include "geometry/tolerances.h"
#include "geometry/union_find.h"
#include "geometry/vec3.h"

namespace pic::detail {
namespace {

uint64_t edge_key(uint32_t a, uint32_t b) { return uint64_t(std::min(a, b)) << 32 | std::max(a, b); }
bool degenerate(const std::array<uint32_t, 3>& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

// The triangle rotated so its smallest index comes first (same orientation).
std::array<uint32_t, 3> canonical(const std::array<uint32_t, 3>& t) {
  const int m = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
  return {t[m], t[(m + 1) % 3], t[(m + 2) % 3]};
}
struct TriHash {
  size_t operator()(const std::array<uint32_t, 3>& t) const {
    return (uint64_t(t[0]) * 0x9e3779b97f4a7c15ull) ^ (uint64_t(t[1]) * 0xc2b2ae3d27d4eb4full) ^ t[2];
  }
};

// Each triangle's traversal of each of its edges, sorted by undirected edge (then triangle):
// the uses of one edge are a run. A sorted array, not a map of vectors: on a 69k-triangle mesh
// the map's allocations cost 60 ms per table.
struct EdgeUse {
  uint64_t key;  // edge_key of the undirected edge
  uint32_t tri;
  int32_t dir;  // +1: the triangle traverses it low -> high, -1: high -> low
  bool operator<(const EdgeUse& o) const { return key != o.key ? key < o.key : tri < o.tri; }
};
/// Items bucketed by a vertex (counting sort): `start[v]..start[v + 1]` index `order` for
/// vertex v, items in their order within a bucket.
struct Buckets {
  std::vector<uint32_t> start, order;
};
template <class Vertex>
Buckets bucket_by_vertex(size_t vertices, size_t items, Vertex&& vertex_of) {
  Buckets b;
  b.start.assign(vertices + 1, 0);
  for (size_t i = 0; i < items; ++i) ++b.start[vertex_of(i) + 1];
  for (size_t v = 0; v < vertices; ++v) b.start[v + 1] += b.start[v];
  b.order.resize(items);
  std::vector<uint32_t> fill(b.start.begin(), b.start.end() - 1);
  for (size_t i = 0; i < items; ++i) b.order[fill[vertex_of(i)]++] = uint32_t(i);
  return b;
}

std::vector<EdgeUse> edge_uses(const TriMesh& m) {
  // Bucketed by the edge's lower vertex, then each short run sorted: linear and serial (in a
  // fresh process a parallel sort's thread start-up cost more than the whole sort).
  const auto use = [&](size_t i) {
    const auto& t = m.triangles[i / 3];
    const uint32_t a = t[i % 3], b = t[(i % 3 + 1) % 3];
    return EdgeUse{edge_key(a, b), uint32_t(i / 3), a < b ? 1 : -1};
  };
  const size_t n = m.triangles.size() * 3;
  const Buckets b = bucket_by_vertex(m.positions.size(), n, [&](size_t i) { return uint32_t(use(i).key >> 32); });
  std::vector<EdgeUse> uses(n);
  for (size_t i = 0; i < n; ++i) uses[i] = use(b.order[i]);
  for (size_t v = 0; v + 1 < b.start.size(); ++v)
    if (b.start[v + 1] - b.start[v] > 1) std::sort(uses.begin() + b.start[v], uses.begin() + b.start[v + 1]);
  return uses;
}

/// Whether two non-degenerate triangles have the same three vertices (in any order).
bool has_repeats(const TriMesh& m) {
  const auto sorted = [&](size_t f) {
    auto t = m.triangles[f];
    std::sort(t.begin(), t.end());
    return t;
  };
  const Buckets b = bucket_by_vertex(m.positions.size(), m.triangles.size(), [&](size_t f) { return sorted(f)[0]; });
  std::vector<std::array<uint32_t, 3>> run;
  for (size_t v = 0; v + 1 < b.start.size(); ++v) {
    if (b.start[v + 1] - b.start[v] < 2) continue;
    run.clear();
    for (uint32_t i = b.start[v]; i < b.start[v + 1]; ++i)
      if (!degenerate(m.triangles[b.order[i]])) run.push_back(sorted(b.order[i]));
    std::sort(run.begin(), run.end());
    if (std::adjacent_find(run.begin(), run.end()) != run.end()) return true;
  }
  return false;
}

// Calls f(key, first, count, net) for each undirected edge's run of uses.
template <class F>
void for_each_edge(const std::vector<EdgeUse>& uses, F&& f) {
  for (size_t i = 0; i < uses.size();) {
    size_t j = i;
    int net = 0;
    for (; j < uses.size() && uses[j].key == uses[i].key; ++j) net += uses[j].dir;
    f(uses[i].key, &uses[i], j - i, net);
    i = j;
  }
}

double tri_area(const TriMesh& m, const std::array<uint32_t, 3>& t) {
  return norm3(cross3(sub3(m.positions[t[1]], m.positions[t[0]]), sub3(m.positions[t[2]], m.positions[t[0]])));
}

// Counts on a welded mesh without degenerate triangles (`uses`: its edge_uses); duplicates
// counted by the caller.
void count_defects(const TriMesh& m, const std::vector<EdgeUse>& uses, MeshDefects& d) {
  UnionFind shells(m.triangles.size());
  for_each_edge(uses, [&](uint64_t, const EdgeUse* u, size_t n, int net) {
    if (n == 1) ++d.boundary_edges;
    if (n > 2) ++d.nonmanifold_edges;
    if (n == 2 && net != 0) ++d.inconsistent_edges;
    for (size_t i = 1; i < n; ++i) shells.join(u[i].tri, u[0].tri);
  });
  // Bounding boxes per shell (indexed by the shell's root triangle); a sweep along x finds
  // the first overlapping pair.
  std::vector<std::array<Vec3, 2>> boxes(m.triangles.size(), {Vec3{kHuge, kHuge, kHuge}, Vec3{-kHuge, -kHuge, -kHuge}});
  std::vector<uint32_t> roots;
  for (uint32_t f = 0; f < m.triangles.size(); ++f) {
    const size_t r = shells.root(f);
    if (r == f) roots.push_back(f);
    auto& box = boxes[r];
    for (uint32_t v : m.triangles[f])
      for (int k = 0; k < 3; ++k) {
        box[0][k] = std::min(box[0][k], m.positions[v][k]);
        box[1][k] = std::max(box[1][k], m.positions[v][k]);
      }
  }
  d.shells = roots.size();
  std::vector<std::array<Vec3, 2>> list;
  for (uint32_t r : roots) list.push_back(boxes[r]);
  std::sort(list.begin(), list.end(), [](const auto& a, const auto& b) { return a[0][0] < b[0][0]; });
  for (size_t i = 0; i < list.size() && !d.overlapping_shells; ++i)
    for (size_t j = i + 1; j < list.size() && list[j][0][0] <= list[i][1][0]; ++j) {
      bool overlap = true;
      for (int k = 1; k < 3; ++k) overlap = overlap && list[j][0][k] <= list[i][1][k] && list[i][0][k] <= list[j][1][k];
      if (overlap) {
        d.overlapping_shells = true;
        break;
      }
    }
}

// Drops degenerate and duplicated triangles (keeping the first of identical copies, and
// removing opposite pairs), counting both.
TriMesh drop_repeats(const TriMesh& in, MeshDefects& d) {
  TriMesh out;
  out.positions = in.positions;
  if (!has_repeats(in)) {  // the common case, without a hash table
    out.triangles.reserve(in.triangles.size());
    for (const auto& t : in.triangles) {
      if (degenerate(t)) ++d.degenerate_faces;
      else out.triangles.push_back(t);
    }
    return out;
  }
  std::unordered_map<std::array<uint32_t, 3>, uint32_t, TriHash> seen;  // canonical -> slot
  std::vector<bool> keep;
  for (const auto& t : in.triangles) {
    if (degenerate(t)) {
      ++d.degenerate_faces;
      continue;
    }
    const auto c = canonical(t);
    if (seen.count(c)) {
      ++d.duplicated_faces;
      continue;
    }
    const auto r = canonical({t[0], t[2], t[1]});
    if (auto it = seen.find(r); it != seen.end() && keep[it->second]) {
      // The reverse is there: together they bound nothing.
      ++d.duplicated_faces;
      keep[it->second] = false;
      continue;
    }
    seen.emplace(c, static_cast<uint32_t>(out.triangles.size()));
    out.triangles.push_back(t);
    keep.push_back(true);
  }
  size_t n = 0;
  for (size_t i = 0; i < out.triangles.size(); ++i)
    if (keep[i]) out.triangles[n++] = out.triangles[i];
  out.triangles.resize(n);
  return out;
}

}  // namespace


CleanMesh clean_mesh(const TriMesh& input) {
  CleanMesh r;
  r.mesh = drop_repeats(weld(input), r.defects);
  TriMesh& m = r.mesh;
  const std::vector<EdgeUse> uses = edge_uses(m);
  count_defects(m, uses, r.defects);
  if (r.defects.inconsistent_edges == 0) return r;
  // Two classes per part linked through two-triangle edges: "as seeded" and "reversed
  // relative to the seed". Turn round whichever class has less area.
  std::vector<std::vector<std::pair<uint32_t, bool>>> links(m.triangles.size());  // (other, same way)
  for_each_edge(uses, [&](uint64_t, const EdgeUse* u, size_t n, int) {
    if (n != 2) return;
    const uint32_t f = u[0].tri, g = u[1].tri;
    const bool same = u[0].dir == u[1].dir;
    links[f].push_back({g, same});
    links[g].push_back({f, same});
  });
  std::vector<int8_t> cls(m.triangles.size(), -1);
  std::vector<uint32_t> part, stack;
  for (uint32_t seed = 0; seed < m.triangles.size(); ++seed) {
    if (cls[seed] >= 0) continue;
    part.clear();
    cls[seed] = 0;
    stack.push_back(seed);
    double area[2] = {0, 0};
    while (!stack.empty()) {
      const uint32_t f = stack.back();
      stack.pop_back();
      part.push_back(f);
      area[cls[f]] += tri_area(m, m.triangles[f]);
      for (const auto& [g, same] : links[f]) {
        if (cls[g] >= 0) continue;  // a conflict (non-orientable part) keeps the first answer
        cls[g] = int8_t(same ? 1 - cls[f] : cls[f]);
        stack.push_back(g);
      }
    }
    const int8_t turn = area[1] > area[0] ? 0 : 1;
    for (uint32_t f : part)
      if (cls[f] == turn) {
        std::swap(m.triangles[f][1], m.triangles[f][2]);
        ++r.flipped;
      }
  }
  return r;
}

std::vector<std::array<uint32_t, 2>> boundary_chain(const TriMesh& mesh) {
  std::vector<std::array<uint32_t, 2>> chain;
  for_each_edge(edge_uses(mesh), [&](uint64_t key, const EdgeUse*, size_t, int net) {
    const uint32_t lo = uint32_t(key >> 32), hi = uint32_t(key);
    for (int k = 0; k < std::abs(net); ++k) chain.push_back(net > 0 ? std::array{lo, hi} : std::array{hi, lo});
  });
  // Deterministic order (the map's order is not).
  std::sort(chain.begin(), chain.end());
  return chain;
}

std::vector<std::vector<uint32_t>> boundary_loops(const std::vector<std::array<uint32_t, 2>>& chain) {
  // Every vertex has as many edges in as out, so a walk along unused edges returns to its
  // start: peel off closed walks (Hierholzer without the splicing; any decomposition will do).
  std::unordered_map<uint32_t, std::vector<uint32_t>> out;
  for (const auto& [a, b] : chain) out[a].push_back(b);
  for (auto& [v, list] : out) std::sort(list.rbegin(), list.rend());  // deterministic
  std::vector<std::vector<uint32_t>> loops;
  for (const auto& [a0, b0] : chain) {
    auto& first = out[a0];
    if (first.empty()) continue;
    std::vector<uint32_t> loop{a0};
    uint32_t v = a0;
    while (!out[v].empty()) {
      const uint32_t next = out[v].back();
      out[v].pop_back();
      if (next == a0) break;
      loop.push_back(next);
      v = next;
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

std::vector<std::array<uint32_t, 3>> cap_loops(const std::vector<std::array<uint32_t, 2>>& chain, size_t* count) {
  // Each run of up to 8 consecutive edges v0 -> ... -> v8 is capped by a fan from v0; what is
  // left to close is the coarser loop through v0, v8, v16, ... Repeating gives triangles whose
  // size grows with the level, so the dipole tree can summarize the far ones.
  constexpr size_t kRun = 8;
  std::vector<std::array<uint32_t, 3>> tris;
  const auto loops = boundary_loops(chain);
  if (count) *count = loops.size();
  for (std::vector<uint32_t> loop : loops) {
    while (loop.size() > 2) {
      std::vector<uint32_t> coarse;
      for (size_t start = 0; start < loop.size(); start += kRun) {
        coarse.push_back(loop[start]);
        const size_t end = std::min(start + kRun, loop.size());  // the run's last vertex
        for (size_t i = start + 1; i < end; ++i) {
          const std::array<uint32_t, 3> t{loop[start], loop[(i + 1) % loop.size()], loop[i]};
          if (!degenerate(t)) tris.push_back(t);
        }
      }
      if (coarse.size() == loop.size()) break;
      loop = std::move(coarse);
    }
  }
  return tris;
}

}  // namespace pic::detail

namespace pic {
MeshDefects find_defects(const TriMesh& mesh) { return detail::clean_mesh(mesh).defects; }
double detail::plane_spread(const TriMesh& mesh) {
  Vec3 n{0, 0, 0}, origin{0, 0, 0};
  double best = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
    const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const Vec3 x{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double area2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
    if (area2 > best) best = area2, n = x, origin = a;
  }
  if (best == 0) return -1;
  const double len = std::sqrt(best);
  double lo = 0, hi = 0;
  for (const Vec3& p : mesh.positions) {
    const double d = ((p[0] - origin[0]) * n[0] + (p[1] - origin[1]) * n[1] + (p[2] - origin[2]) * n[2]) / len;
    lo = std::min(lo, d), hi = std::max(hi, d);
  }
  return hi - lo;
}

}  // namespace pic
