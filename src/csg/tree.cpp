// A CSG tree over octrees and meshes, evaluated bottom-up: see pic/csg.h (CsgTree, evaluate).
#include "pic/csg.h"
#include "octree/cell.h"

#include <tbb/parallel_invoke.h>

#include <mutex>
#include <optional>

namespace pic {

CsgTree csg_leaf(std::shared_ptr<const Octree> tree) {
  CsgTree t;
  t.kind = CsgTree::Kind::Octree;
  t.tree = std::move(tree);
  return t;
}
CsgTree csg_leaf(Octree tree) { return csg_leaf(std::make_shared<const Octree>(std::move(tree))); }
CsgTree csg_leaf(TriMesh mesh) {
  CsgTree t;
  t.kind = CsgTree::Kind::Mesh;
  t.mesh = std::make_shared<const TriMesh>(std::move(mesh));
  return t;
}
CsgTree csg_empty() {
  CsgTree t;
  t.kind = CsgTree::Kind::Empty;
  return t;
}
CsgTree csg_union(std::vector<CsgTree> children) {
  CsgTree t;
  t.kind = CsgTree::Kind::Union;
  t.children = std::move(children);
  return t;
}
CsgTree csg_intersection(std::vector<CsgTree> children) {
  CsgTree t;
  t.kind = CsgTree::Kind::Intersection;
  t.children = std::move(children);
  return t;
}
CsgTree csg_difference(CsgTree from, std::vector<CsgTree> take_away) {
  CsgTree t;
  t.kind = CsgTree::Kind::Difference;
  t.children.push_back(std::move(from));
  for (CsgTree& c : take_away) t.children.push_back(std::move(c));
  return t;
}

namespace {

void collect_mesh_points(const CsgTree& t, std::vector<Vec3>& out) {
  if (t.kind == CsgTree::Kind::Mesh) out.insert(out.end(), t.mesh->positions.begin(), t.mesh->positions.end());
  for (const CsgTree& c : t.children) collect_mesh_points(c, out);
}

/// The first octree leaf's cube, for a tree without meshes whose result must still have one.
const Octree* first_octree(const CsgTree& t) {
  if (t.kind == CsgTree::Kind::Octree) return t.tree.get();
  for (const CsgTree& c : t.children)
    if (const Octree* o = first_octree(c)) return o;
  return nullptr;
}

class TreeEvaluator {
 public:
  TreeEvaluator(const CsgChainOptions& options, const SampleOptions& sampling, const Octree* empty_like)
      : options_(options), sampling_(sampling), empty_like_(empty_like) {}

  /// A subtree's solid, and whether a Boolean made it (then every part of it has been through
  /// the clean-up: copies of it need no second one inside).
  struct Part {
    Octree tree;
    bool settled = false;
  };

  /// The solid of `t`, or nothing for an empty one.
  std::optional<Part> eval(const CsgTree& t) {
    switch (t.kind) {
      case CsgTree::Kind::Empty: return std::nullopt;
      case CsgTree::Kind::Octree: return Part{*t.tree};
      case CsgTree::Kind::Mesh: {
        if (!t.name.empty()) say("sampling " + t.name);
        Part p{sample(*t.mesh, sampling_)};
        if (options_.on_leaf) options_.on_leaf();
        return p;
      }
      case CsgTree::Kind::Union: return balanced(t.children, 0, t.children.size(), CsgOp::Union);
      case CsgTree::Kind::Intersection: return balanced(t.children, 0, t.children.size(), CsgOp::Intersect);
      case CsgTree::Kind::Difference: {
        if (t.children.empty()) throw InvalidInput("a difference needs the solid to take from");
        if (t.children.size() == 1) return eval(t.children[0]);
        std::optional<Part> a, b;
        both([&] { a = eval(t.children[0]); }, [&] { b = balanced(t.children, 1, t.children.size(), CsgOp::Union); });
        if (!a || !b) return a;
        boolean(*a, *b, CsgOp::Subtract, t.children.size() == 2 ? t.children[1].name : std::string());
        return a;
      }
    }
    return std::nullopt;
  }

  /// The empty solid in the tree's cube.
  Octree empty() const {
    Octree t;
    if (sampling_.cube) t.cube = *sampling_.cube;
    else if (empty_like_) t.cube = empty_like_->cube;
    t.max_depth = empty_like_ ? empty_like_->max_depth : sampling_.depth;
    return t;
  }

 private:
  const CsgChainOptions& options_;
  SampleOptions sampling_;
  const Octree* empty_like_;
  std::mutex step_mutex_;  // on_step and progress are called one at a time
  uint32_t steps_ = 0;     // Booleans finished so far (under step_mutex_)

  template <class A, class B>
  void both(const A& a, const B& b) {
    if (options_.csg.parallel) tbb::parallel_invoke(a, b);
    else a(), b();
  }
  /// kids[b, e) combined: the first floor(n/2) with the rest, each half the same way. An empty
  /// part leaves a union as the other part and makes an intersection empty.
  std::optional<Part> balanced(const std::vector<CsgTree>& kids, size_t b, size_t e, CsgOp op) {
    if (b >= e) return std::nullopt;
    if (e - b == 1) return eval(kids[b]);
    const size_t mid = b + (e - b) / 2;
    std::optional<Part> x, y;
    both([&] { x = balanced(kids, b, mid, op); }, [&] { y = balanced(kids, mid, e, op); });
    if (op == CsgOp::Intersect && (!x || !y)) return std::nullopt;
    if (!x) return y;
    if (!y) return x;
    boolean(*x, *y, op, e - mid == 1 ? kids[mid].name : std::string());
    return x;
  }
  /// x := x op y, reported (`name`: y's, when it is a named leaf).
  void boolean(Part& x, const Part& y, CsgOp op, const std::string& name) {
    if (!name.empty()) say(to_string(op) + " " + name);
    CsgStats st;
    CsgOptions csg = options_.csg;
    csg.b_settled = y.settled;
    csg_inplace(x.tree, y.tree, op, csg, &st);
    x.settled = true;
    if (!options_.on_step) return;
    const std::lock_guard lock(step_mutex_);
    st.stamp = ++steps_;
    options_.on_step(st.stamp, st);
  }
  void say(const std::string& m) {
    if (!options_.progress) return;
    const std::lock_guard lock(step_mutex_);
    options_.progress(m);
  }
};

}  // namespace

Octree evaluate(const CsgTree& tree, const CsgChainOptions& options) {
  SampleOptions sampling = options.sampling;
  if (!sampling.cube) {
    TriMesh all;
    collect_mesh_points(tree, all.positions);
    if (!all.positions.empty()) sampling.cube = bounding_cube(all, sampling.margin);
  }
  TreeEvaluator ev(options, sampling, first_octree(tree));
  std::optional<TreeEvaluator::Part> result = ev.eval(tree);
  if (!result) return ev.empty();
  Octree& r = result->tree;
  if (options.compact && r.nodes.size() > detail::reachable_nodes(r)) detail::compact(r);
  return std::move(r);
}

}  // namespace pic
