// Chains of Booleans over PIC objects and meshes (pic csg, Python's csg_meshes).
#include "pic/csg.h"
#include "octree/cell.h"

#include <algorithm>

namespace pic {

namespace {

/// The root cube around every mesh operand, when the options leave it open.
std::optional<Cube> shared_cube(const std::vector<CsgOperand>& operands, const SampleOptions& sampling) {
  if (sampling.cube) return sampling.cube;
  TriMesh all;
  for (const CsgOperand& x : operands)
    if (!x.tree) all.positions.insert(all.positions.end(), x.mesh.positions.begin(), x.mesh.positions.end());
  if (all.positions.empty()) return std::nullopt;
  return bounding_cube(all, sampling.margin);
}

}  // namespace

Octree csg_chain(std::vector<CsgOperand> operands, const std::vector<CsgOp>& ops, const CsgChainOptions& options) {
  if (operands.empty() || ops.size() + 1 != operands.size())
    throw InvalidInput("a chain of Booleans needs one operand more than operations");
  SampleOptions sampling = options.sampling;
  sampling.cube = shared_cube(operands, sampling);
  auto say = [&](const std::string& m) {
    if (options.progress) options.progress(m);
  };
  // Operands become octrees one at a time: a long chain never holds all of them sampled.
  auto take = [&](size_t k) {
    CsgOperand& x = operands[k];
    if (x.tree) return std::move(*x.tree);
    say("sampling " + x.name);
    Octree t = sample(x.mesh, sampling);
    x.mesh = TriMesh{};
    return t;
  };
  Octree acc = take(0);
  for (size_t k = 0; k < ops.size(); ++k) {
    const Octree b = take(k + 1);
    say(to_string(ops[k]) + " " + operands[k + 1].name);
    CsgStats st;
    csg_inplace(acc, b, ops[k], options.csg, &st);  // no copy of the result per step
    st.stamp = uint32_t(k + 1);
    if (options.on_step) options.on_step(k + 1, st);
  }
  if (acc.nodes.size() > detail::reachable_nodes(acc)) detail::compact(acc);
  return acc;
}

}  // namespace pic
