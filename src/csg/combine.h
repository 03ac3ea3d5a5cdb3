// The combine step of a Boolean: the paired recursion over A's and B's stamped cells (paper
// section 5.2): trivial cases, GraycellCSG where both are gray, forced subdivision by
// resampling a leaf's partial contour; in parallel tasks where the work fans out.
#pragma once

#include <vector>

#include "csg/operand.h"

namespace pic::detail {

/// Combines the stamped cells into A (nodes `sa` marks as stamped). Every task reads A as it
/// was; the new nodes land after A's, and A's own slots are written only once all tasks are
/// done. Where the result has contacts (finest cells whose signs make two components, which
/// the clean-up settles by changing a sign) beside coarser leaves, A is restored,
/// `prepare_focus` is given the contacts' corners (to stamp the cells holding them and rebuild
/// the partial contours), and the combine runs again with every cell holding such a corner
/// split down to the finest level. Returns the sign hints for the clean-up; fills stats'
/// recursion counts.
std::vector<SignHint> combine_stamped(Octree& a, Stamps& sa, const Octree& b, const Stamps& sb, const PartialContour& pa,
                                      const PartialContour& pb, CsgOp op, const CsgOptions& options, int depth,
                                      uint32_t stamp, CsgStats& stats,
                                      const std::function<void(const std::vector<Lat>&)>& prepare_focus);

}  // namespace pic::detail
