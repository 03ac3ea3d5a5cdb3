// Features thinner than the finest cell (a wall, a blade, a slot) that a capped cell finds
// between two corners of one sign: the lattice points that keep them, for the sampler and the
// Booleans alike. Setting those signs (after splitting the coarser leaves around) is the
// caller's; the settling then makes the tree valid as after any flip.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace pic::detail {

/// A lattice point and the sign it is asked to take.
using AskedSign = std::pair<std::array<int64_t, 3>, bool>;

/// The signs to set: every point `asked` (ends of capped edges across a thin feature), and the
/// points `beside` (ends of capped edges crossed twice through faces turning by less: where two
/// thin walls meet, or along a wedge's edge) that join them through finest-lattice neighbours
/// (`step` apart) of the same sign, one after another. Each point once; a point asked both ways
/// (a thin wall beside a thin slot) is left out and keeps its own sign. `asked` ends up holding
/// every point considered (the joined ones too), sorted, each once: where to settle after.
std::vector<AskedSign> thin_feature_signs(std::vector<AskedSign>& asked, const std::vector<AskedSign>& beside,
                                          int64_t step);

}  // namespace pic::detail
