// Chains of Booleans over PIC objects and meshes (pic csg, Python's csg_meshes).
#include "pic/csg.h"

#include <algorithm>

namespace pic {

Octree csg_chain(std::vector<CsgOperand> operands, const std::vector<CsgOp>& ops, const CsgChainOptions& options) {
  if (operands.empty() || ops.size() + 1 != operands.size())
    throw InvalidInput("a chain of Booleans needs one operand more than operations");
  auto leaf = [](CsgOperand& x) {
    CsgTree t = x.tree ? csg_leaf(std::move(*x.tree)) : csg_leaf(std::move(x.mesh));
    t.name = x.name;
    return t;
  };
  CsgTree chain = leaf(operands[0]);
  for (size_t k = 0; k < ops.size(); ++k) {
    CsgTree b = leaf(operands[k + 1]);
    std::vector<CsgTree> two;
    two.push_back(std::move(chain));
    two.push_back(std::move(b));
    switch (ops[k]) {
      case CsgOp::Union: chain = csg_union(std::move(two)); break;
      case CsgOp::Intersect: chain = csg_intersection(std::move(two)); break;
      case CsgOp::Subtract: {
        std::vector<CsgTree> away;
        away.push_back(std::move(two[1]));
        chain = csg_difference(std::move(two[0]), std::move(away));
        break;
      }
    }
  }
  return evaluate(chain, options);
}

}  // namespace pic
