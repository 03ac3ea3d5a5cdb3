// Flat regions of a closed, 2-manifold mesh merged without moving its surface.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pic/types.h"

namespace pic::detail {

/// Merges vertices whose star is flat onto a neighbour, keeping the mesh closed and
/// 2-manifold, every triangle's orientation and no triangle worse shaped than
/// kMinTriangleQuality (or the star's worst). Every point of the result lies within `drift`
/// of the input and every point of the input within `drift` of the result. Returns the
/// number of triangles removed; `merged_away` (optional): the input vertices that are gone.
/// `keep` (optional, per vertex): no triangle at these vertices changes.
size_t merge_flat(TriMesh& mesh, double drift, std::vector<Vec3>* merged_away = nullptr,
                  const std::vector<uint8_t>* keep = nullptr);

}  // namespace pic::detail
