// Exact welding: equal positions become one vertex.
#pragma once

#include "pic/types.h"

namespace pic::detail {

/// Equal positions merged (exactly; -0 == +0); triangles re-indexed, in their order.
TriMesh weld(const TriMesh& mesh);

}  // namespace pic::detail
