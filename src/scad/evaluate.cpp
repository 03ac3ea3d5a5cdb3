// Evaluating a lowered OpenSCAD model on PIC octrees: one root cube around every leaf, each
// leaf sampled into it, the Booleans run on the octrees bottom-up -- n-ary unions balanced,
// independent subtrees in parallel (TBB).
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>

#include "geometry/stopwatch.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"
#include "mesh/clean.h"
#include "pic/contour.h"
#include "pic/csg.h"
#include "pic/measure.h"
#include "pic/octree.h"
#include "pic/sample.h"
#include "pic/scad.h"
#include "pic/types.h"
#include "pic/volume.h"
#include "scad/lower.h"

namespace pic {
namespace {

using namespace detail::scad;
using detail::Clock;
using detail::since;

void append_mesh(TriMesh& to, const TriMesh& m) {
  const auto base = static_cast<uint32_t>(to.positions.size());
  to.positions.insert(to.positions.end(), m.positions.begin(), m.positions.end());
  for (const auto& t : m.triangles) to.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

// The mesh leaves of a subtree of unions only (none empty), or false when it holds anything
// else.
bool union_leaves(const Solid& s, std::vector<const TriMesh*>& out) {
  switch (s.kind) {
    case Solid::Kind::Mesh: out.push_back(&s.mesh); return true;
    case Solid::Kind::Union:
      for (const Solid& c : s.children)
        if (!union_leaves(c, out)) return false;
      return true;
    default: return false;
  }
}

/// A leaf's extent, for telling whether two leaves are apart: its box, and its own face
/// directions when it has few (a box, a prism, a bar turned obliquely). Two leaves are apart
/// when their vertices' ranges along one of these directions do not overlap: a plane
/// separates them. Axis boxes alone take turned bars for overlapping (every pair of the
/// turned Menger sponge's parallel bars).
struct LeafExtent {
  const TriMesh* mesh = nullptr;
  std::array<Vec3, 2> box;
  std::vector<Vec3> dirs;  ///< distinct face normals up to sign; none past kMaxDirs
};
constexpr size_t kMaxDirs = 16;

LeafExtent extent_of(const TriMesh& m) {
  using namespace detail;
  LeafExtent e{&m, box_of(m.positions), {}};
  for (const auto& t : m.triangles) {
    const Vec3& p = m.positions[t[0]];
    const Vec3 n = cross3(sub3(m.positions[t[1]], p), sub3(m.positions[t[2]], p));
    const double len = norm3(n);
    if (!(len > 0)) continue;
    const Vec3 u = scale3(n, 1 / len);
    const auto same = [&](const Vec3& d) { return std::abs(dot3(d, u)) > 1 - detail::kParallelCosine; };
    if (std::any_of(e.dirs.begin(), e.dirs.end(), same)) continue;
    if (e.dirs.size() == kMaxDirs) {
      e.dirs.clear();
      break;
    }
    e.dirs.push_back(u);
  }
  return e;
}

/// Whether the ranges of the two meshes' vertices along `d` are apart.
bool apart_along(const TriMesh& a, const TriMesh& b, const Vec3& d) {
  const auto range = [&](const TriMesh& m) {
    double lo = detail::kHuge, hi = -detail::kHuge;
    for (const Vec3& p : m.positions) {
      const double x = detail::dot3(p, d);
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    return std::pair{lo, hi};
  };
  const auto [alo, ahi] = range(a);
  const auto [blo, bhi] = range(b);
  return ahi < blo || bhi < alo;
}

bool leaves_apart(const LeafExtent& a, const LeafExtent& b) {
  if (boxes_apart(a.box, b.box)) return true;
  for (const Vec3& d : a.dirs)
    if (apart_along(*a.mesh, *b.mesh, d)) return true;
  for (const Vec3& d : b.dirs)
    if (apart_along(*a.mesh, *b.mesh, d)) return true;
  return false;
}

/// Reports progress at most once a second: leaves sampled and Booleans done.
class Progress {
 public:
  Progress(const EvalOptions& o, size_t leaves) : opt_(o), total_(leaves), t0_(Clock::now()), last_(t0_) {}
  std::atomic<size_t> booleans{0};
  std::atomic<size_t> thin_points{0};
  std::atomic<size_t> leaves_done{0};
  void report() {
    if (!opt_.progress) return;
    std::lock_guard lock(mu_);
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - last_).count() < 1.0) return;
    last_ = now;
    char buf[160];
    std::snprintf(buf, sizeof buf, "%zu/%zu leaves sampled, %zu Booleans, %.1f s", leaves_done.load(), total_,
                  booleans.load(), since(t0_));
    opt_.progress(buf);
  }

 private:
  const EvalOptions& opt_;
  size_t total_;
  Clock::time_point t0_, last_;
  std::mutex mu_;
};

/// The lowered model as the library's CSG tree, with the rules that belong to OpenSCAD
/// models: a leaf thinner than a finest cell is empty, leaves of a union that are apart are
/// sampled together, and a hull is the hull of its leaves' vertices (or of its subtree's
/// contour). Everything else -- balanced n-ary Booleans, halves in parallel -- is evaluate()'s.
class TreeBuilder {
 public:
  TreeBuilder(const EvalOptions& o, const Cube& cube, Progress& progress)
      : opt_(o), cube_(cube), progress_(progress) {}

  CsgTree build(const Solid& s) {
    switch (s.kind) {
      case Solid::Kind::Empty: return csg_empty();
      case Solid::Kind::Mesh: return leaf(s.mesh);
      case Solid::Kind::Union: return csg_union(united(s.children, 0, s.children.size()));
      case Solid::Kind::Intersect: return csg_intersection(each(s.children, 0, s.children.size()));
      case Solid::Kind::Difference:
        return csg_difference(build(s.children[0]), united(s.children, 1, s.children.size()));
      case Solid::Kind::Hull: return hull(s.children);
      case Solid::Kind::RoundSum: return round_sum(s);
    }
    return csg_empty();
  }

  CsgChainOptions chain_options() const {
    CsgChainOptions co;
    co.sampling.depth = opt_.depth;
    co.sampling.error = opt_.error;
    co.sampling.cube = cube_;
    co.sampling.parallel = opt_.parallel;
    co.csg.error = opt_.error;
    co.csg.parallel = opt_.parallel;
    co.compact = false;  // the Booleans compact where it pays; the contour follows the node order
    co.on_leaf = [p = &progress_] { ++p->leaves_done, p->report(); };
    co.on_step = [p = &progress_](size_t, const CsgStats& s) {
      ++p->booleans;
      p->thin_points += s.thin_points;
      p->report();
    };
    return co;
  }

 private:
  const EvalOptions& opt_;
  Cube cube_;
  Progress& progress_;

  /// A leaf thinner than a finest cell (a sliver ring of a 2D Boolean, extruded) holds no
  /// solid at this depth: it is empty here, where a mesh given to `pic sample` is an error.
  CsgTree leaf(const TriMesh& m) {
    if (detail::plane_spread(m) >= cube_.size / double(int64_t{1} << opt_.depth)) return csg_leaf(m);
    ++progress_.leaves_done;
    return csg_empty();
  }
  std::vector<CsgTree> each(const std::vector<Solid>& kids, size_t b, size_t e) {
    std::vector<CsgTree> out;
    for (size_t i = b; i < e; ++i) out.push_back(build(kids[i]));
    return out;
  }
  CsgTree round_sum(const Solid& s) {
    const Solid& of = s.children[0];
    const TriMesh surface = of.kind == Solid::Kind::Mesh ? of.mesh : solid_surface(of, opt_);
    if (surface.triangles.empty()) return csg_empty();
    SampleOptions so;
    so.depth = opt_.depth;
    so.error = opt_.error;
    so.cube = cube_;
    so.parallel = opt_.parallel;
    Octree sum = minkowski_round(surface, s.body, so);
    ++progress_.leaves_done;
    return csg_leaf(std::move(sum));
  }
  CsgTree hull(const std::vector<Solid>& kids) {
    std::vector<Vec3> pts;
    bool direct = true;
    for (const Solid& c : kids) direct = direct && hull_points(c, pts);
    if (!direct) {
      // A difference or intersection below the hull: take the vertices of its contour
      // (within a finest cell of the exact result).
      const Octree u = evaluate(csg_union(each(kids, 0, kids.size())), chain_options());
      pts = unsplit_contour(u).positions;
    }
    TriMesh h = detail::convex_hull(pts);
    if (h.triangles.empty()) return csg_empty();
    return leaf(h);
  }
  /// The parts whose union is kids[b, e). Where they are all mesh leaves (or unions of them),
  /// the leaves that are apart are sampled together: a soup of closed meshes that do not meet
  /// is the union's surface as it is, so one sampling pass replaces a sampling per leaf and a
  /// Boolean per pair (the holes of a die, the teeth of a gear). Leaves that meet are still
  /// combined by Booleans: sampled as one soup, the parts of their triangles inside another
  /// leaf pull the cells' vertices off the surface and refine them to the finest level (the
  /// Menger sponge's bars took 1.3x longer that way).
  std::vector<CsgTree> united(const std::vector<Solid>& kids, size_t b, size_t e) {
    std::vector<const TriMesh*> leaves;
    for (size_t i = b; i < e; ++i)
      if (!union_leaves(kids[i], leaves)) return each(kids, b, e);
    std::vector<LeafExtent> extents;
    for (const TriMesh* m : leaves) {
      if (m->triangles.empty() || !(volume(*m) > 0)) return each(kids, b, e);
      extents.push_back(extent_of(*m));
    }
    // Greedily: each leaf joins the first group whose every leaf is apart from it.
    std::vector<std::vector<size_t>> groups;
    for (size_t i = 0; i < leaves.size(); ++i) {
      const auto apart = [&](const std::vector<size_t>& g) {
        return std::all_of(g.begin(), g.end(), [&](size_t j) { return leaves_apart(extents[j], extents[i]); });
      };
      const auto g = std::find_if(groups.begin(), groups.end(), apart);
      if (g == groups.end()) groups.push_back({i});
      else g->push_back(i);
    }
    if (groups.size() == leaves.size()) return each(kids, b, e);
    std::vector<CsgTree> parts;
    for (const auto& group : groups) {
      TriMesh m;
      for (size_t i : group) append_mesh(m, *leaves[i]);
      parts.push_back(leaf(m));
    }
    // The groups count as one leaf each from here: progress counts the others as done.
    progress_.leaves_done += leaves.size() - groups.size();
    return parts;
  }
};

std::optional<Octree> evaluate_model(const Solid& model, const EvalOptions& options, const Cube& cube,
                                     size_t leaves, EvalStats* st) {
  Progress progress(options, leaves);
  TreeBuilder builder(options, cube, progress);
  const CsgTree tree = builder.build(model);
  Octree out = evaluate(tree, builder.chain_options());
  if (st) {
    st->booleans = progress.booleans.load();
    st->thin_points = progress.thin_points.load();
  }
  if (out.vertices.empty()) return std::nullopt;
  return out;
}

}  // namespace

namespace detail::scad {
void solid_bounds(const Solid& s, Vec3& lo, Vec3& hi, size_t& leaves, size_t& triangles) {
  if (s.kind == Solid::Kind::RoundSum) {
    // The child's box grown by the body's.
    Vec3 clo{kHuge, kHuge, kHuge}, chi{-kHuge, -kHuge, -kHuge};
    size_t child_leaves = 0;
    solid_bounds(s.children[0], clo, chi, child_leaves, triangles);
    const auto [blo, bhi] = box_of(s.body);
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], clo[k] + blo[k]), hi[k] = std::max(hi[k], chi[k] + bhi[k]);
    ++leaves;
    return;
  }
  if (s.kind == Solid::Kind::Mesh) {
    ++leaves;
    triangles += s.mesh.triangles.size();
    for (const Vec3& p : s.mesh.positions)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  }
  for (const Solid& c : s.children) solid_bounds(c, lo, hi, leaves, triangles);
}

TriMesh solid_surface(const Solid& s, const EvalOptions& options) {
  if (s.kind == Solid::Kind::Mesh) return s.mesh;
  // In the cube around where the subtree's result can lie, as a whole model's: a small
  // remnant of big operands keeps its own resolution (a resize then scales it up).
  Solid model = s;
  const Cube cube = root_cube(model);
  Vec3 lo{kHuge, kHuge, kHuge}, hi{-kHuge, -kHuge, -kHuge};
  size_t leaves = 0, tris = 0;
  solid_bounds(model, lo, hi, leaves, tris);
  if (leaves == 0) return {};
  EvalOptions o = options;
  o.progress = nullptr;
  const std::optional<Octree> t = evaluate_model(model, o, cube, leaves, nullptr);
  if (!t) return {};
  return contour(*t);
}
}  // namespace detail::scad

Octree eval_csg(const std::string& text, const EvalOptions& options, EvalStats* stats, const std::string& source) {
  const auto t0 = Clock::now();
  if (options.depth < 1 || options.depth > kMaxLevel)
    throw InvalidInput("depth must be between 1 and " + std::to_string(kMaxLevel));
  std::vector<detail::scad::Node> top;
  try {
    top = parse(text);
  } catch (const InvalidInput& e) {
    throw InvalidInput(source + ": " + e.what());
  }
  detail::scad::Node root;
  root.name = "group";
  root.children = std::move(top);
  if (detail::scad::dimension(root) == 2)
    throw InvalidInput(source + ": a 2D model: write its outline with -o out.svg or -o out.dxf");
  auto lower = [&](double cell, size_t* nodes) {
    try {
      return detail::scad::lower(root, options, cell, nodes);
    } catch (const InvalidInput& e) {
      throw InvalidInput(source + ": " + e.what());
    }
  };
  EvalStats st;
  EvalOptions first = options;
  if (options.smooth) first.smooth = false;
  Solid model = lower(0, &st.nodes);
  const auto count_leaves = [&] {
    Vec3 lo{detail::kHuge, detail::kHuge, detail::kHuge}, hi{-detail::kHuge, -detail::kHuge, -detail::kHuge};
    st.leaves = st.triangles = 0;
    solid_bounds(model, lo, hi, st.leaves, st.triangles);
  };
  count_leaves();
  if (model.kind == Solid::Kind::Empty || st.leaves == 0) throw InvalidInput(source + ": the model is empty");
  st.cube = root_cube(model);
  if (options.smooth) {
    // Second pass: tessellate against the finest cell of the cube found above.
    model = lower(st.cube.size / double(int64_t{1} << options.depth), nullptr);
    st.cube = root_cube(model);
  }
  count_leaves();
  if (st.leaves == 0) throw InvalidInput(source + ": the model is empty");
  st.mesh_seconds = since(t0);
  if (options.progress)
    options.progress("sampling " + std::to_string(st.leaves) + " leaves (" + std::to_string(st.triangles) +
                     " triangles) at depth " + std::to_string(options.depth));
  const auto t1 = Clock::now();
  std::optional<Octree> out = evaluate_model(model, options, st.cube, st.leaves, &st);
  st.octree_seconds = since(t1);
  st.seconds = since(t0);
  if (!out) throw InvalidInput(source + ": the model is empty");
  if (stats) *stats = st;
  return std::move(*out);
}

std::optional<Outline> eval_csg_outline(const std::string& text, const EvalOptions& options, EvalStats* stats,
                                        const std::string& source) {
  const auto t0 = Clock::now();
  detail::scad::Node root;
  root.name = "group";
  try {
    root.children = parse(text);
    if (detail::scad::dimension(root) != 2) return std::nullopt;
    Outline out;
    EvalStats st;
    for (auto& ring : detail::scad::lower_2d(root, options, &st.nodes)) out.rings.push_back(std::move(ring));
    if (out.rings.empty()) throw InvalidInput("the model is empty");
    st.mesh_seconds = st.seconds = since(t0);
    if (stats) *stats = st;
    return out;
  } catch (const InvalidInput& e) {
    throw InvalidInput(source + ": " + e.what());
  }
}

double area(const Outline& outline) {
  double a = 0;
  for (const auto& r : outline.rings) a += detail::scad::signed_area(r);
  return a;
}

Octree eval_csg_file(const std::filesystem::path& path, const EvalOptions& options, EvalStats* stats) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot read " + path.string());
  std::stringstream ss;
  ss << in.rdbuf();
  EvalOptions o = options;
  if (o.base_dir.empty()) o.base_dir = path.parent_path();
  return eval_csg(ss.str(), o, stats, path.string());
}

}  // namespace pic
