// PIC — Booleans computed directly on two octrees (paper section 5).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <functional>
#include <memory>
#include <vector>

#include "pic/octree.h"
#include "pic/sample.h"

namespace pic {

enum class CsgOp { Union, Intersect, Subtract };
std::string to_string(CsgOp op);
/// Parses "union", "intersect"/"intersection", "subtract"/"difference".
std::optional<CsgOp> parse_csg_op(const std::string& s);

struct CsgOptions {
  double error = 1e-8;  ///< QEF residual threshold for new vertices
  bool parallel = true; ///< combine subtrees near the root with TBB (output identical to serial)
  /// B is itself a Boolean's result, so the clean-up already saw each of its parts where it
  /// landed: a part of B copied whole into A is checked along its cell's faces only (else a part
  /// smaller than about 32K nodes is cleaned whole, for a sampled tool's own sign islands).
  bool b_settled = false;
};

struct CsgStats {
  double seconds = 0;
  double contour_a_seconds = 0;  ///< partial contour of A
  double contour_b_seconds = 0;  ///< partial contour of B
  double csg_seconds = 0;        ///< the octree recursion itself, clean-up included
  double cleanup_seconds = 0;    ///< of which: islands, one component per leaf, cracks
  size_t cells_visited = 0;      ///< cell pairs visited by the recursion
  size_t cells_stamped = 0;      ///< operand cells stamped as overlap
  size_t gray_pairs = 0;         ///< gray/gray evaluations (GraycellCSG)
  size_t forced_subdivisions = 0;
  size_t repaired = 0;           ///< uniform leaves turned gray to keep the surface closed
  /// Lattice points given the sign of a wall, blade or slot thinner than the finest cell that
  /// the Boolean made (kept about a cell thick instead of dropped)
  size_t thin_points = 0;
  uint32_t stamp = 0;            ///< this operation's number in its chain (1 for a single one)
  bool resampled_b = false;      ///< B was re-expressed in A's cube
};

/// Boolean of two PIC objects computed on the octrees (paper section 5). Operands should
/// share a root cube; if they do not, B is resampled from its contour into A's cube, or,
/// when B does not fit there, both are resampled into the cube around both cubes. Depths may
/// differ (the result takes the larger). The result is closed; see docs/algorithms.md.
/// \throws InvalidInput when an operand cannot be resampled.
Octree csg(const Octree& a, const Octree& b, CsgOp op, const CsgOptions& options = {},
           CsgStats* stats = nullptr);

/// The same Boolean written into `a` (A := A op B). Only the overlap region is rebuilt;
/// untouched subtrees stay where they are, so a sculpting stroke costs what it touches.
void csg_inplace(Octree& a, const Octree& b, CsgOp op, const CsgOptions& options = {},
                 CsgStats* stats = nullptr);

/// One operand of a chain of Booleans: a PIC object used as it is, or else a mesh that the chain
/// samples into the cube it shares with the chain's other meshes.
struct CsgOperand {
  std::optional<Octree> tree;
  TriMesh mesh;
  std::string name;  ///< for progress messages and errors
};
struct CsgChainOptions {
  SampleOptions sampling;  ///< for mesh operands; its `cube`, when unset, is the bounding
                           ///< cube of all the mesh operands together
  CsgOptions csg;
  std::function<void(const std::string&)> progress;  ///< optional: "sampling x", "union y"
  /// Optional: called after each Boolean with its operand's index and statistics.
  std::function<void(size_t, const CsgStats&)> on_step;
  /// Drop the nodes no leaf reaches from the result (smaller, and laid out as a loaded file).
  bool compact = true;
  /// Optional: called after each mesh leaf is sampled (from the thread that sampled it).
  std::function<void()> on_leaf;
};
/// operands[0] ops[0] operands[1] ops[1] operands[2] ..., left to right: evaluate() of the
/// left-deep tree ((a op b) op c) ..., each step's statistics to on_step in order. Mesh
/// operands are sampled into one cube around all of them, so the Booleans between them need
/// no resampling (a Boolean with a PIC object in another cube resamples as csg() does).
/// \throws InvalidInput when ops.size() + 1 != operands.size() or as sample() and csg().
Octree csg_chain(std::vector<CsgOperand> operands, const std::vector<CsgOp>& ops,
                 const CsgChainOptions& options = {});

/// A CSG tree over PIC objects and meshes, evaluated on demand: a leaf holds an octree (shared,
/// never copied by building the tree) or a mesh; an inner node is an n-ary union or
/// intersection, or a difference (its first child minus the union of the others). Build it
/// with csg_leaf, csg_union, csg_intersection and csg_difference.
struct CsgTree {
  enum class Kind { Empty, Octree, Mesh, Union, Intersection, Difference };
  Kind kind = Kind::Union;
  std::shared_ptr<const Octree> tree;   ///< Kind::Octree
  std::shared_ptr<const TriMesh> mesh;  ///< Kind::Mesh
  std::vector<CsgTree> children;        ///< inner nodes
  std::string name;                     ///< optional, for progress messages ("sampling x")
};
CsgTree csg_leaf(Octree tree);
CsgTree csg_leaf(std::shared_ptr<const Octree> tree);
CsgTree csg_leaf(TriMesh mesh);
CsgTree csg_empty();  ///< no solid: a union skips it, an intersection with it is empty
CsgTree csg_union(std::vector<CsgTree> children);
CsgTree csg_intersection(std::vector<CsgTree> children);
CsgTree csg_difference(CsgTree from, std::vector<CsgTree> take_away);

/// Evaluates the tree on octrees. Mesh leaves are sampled into one cube around all of them
/// (options.sampling.cube when set); octree leaves in another cube are resampled as csg()
/// does. An n-ary union or intersection combines its children in a balanced order — the first
/// half with the second, each half the same way, halves evaluated in parallel (with
/// options.csg.parallel) — and no step copies a result: each Boolean is written into its left
/// operand. Three children combine as a op (b op c). An empty union is the empty solid.
/// options.on_step gets each Boolean's statistics with its number in the order they finish
/// (the chain's order for a left-deep tree).
/// Throws InvalidInput as sample() and csg() do, or for a difference without children.
Octree evaluate(const CsgTree& tree, const CsgChainOptions& options = {});

}  // namespace pic
