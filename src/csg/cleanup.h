// The CSG clean-up (paper section 5 leaves it open): after the combine, the stamped part of
// the result may hold what no single PIC leaf can represent — islands of finer points on a
// coarse leaf's faces, finest leaves whose corners make two components, specks where the two
// operands' surfaces pass within a fraction of a cell — and operands' crack repairs that the
// passes would take for real coarse leaves. This stage makes it a valid PIC again, guided by
// the combine's sign hints. See docs/algorithms.md, "CSG", step 6.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "pic/csg.h"

namespace pic::detail {

/// Per node of a tree: the timestamp of the last operation that worked on it (paper 5.2.1).
/// A CSG operation's own bookkeeping: never part of an octree.
using Stamps = std::vector<uint32_t>;

/// A lattice point whose sign the clean-up should set to `inside` (see sign_hint in csg.cpp).
struct SignHint {
  /// Join: a finest leaf's corners made one component (sign_hint). Thin: an end of a capped
  /// edge across a feature thinner than a cell; BesideThin: an end of a capped edge crossed
  /// twice through faces turning by less, kept only next to a Thin point (thin_feature_hints).
  enum class Kind : uint8_t { Join, Thin, BesideThin };
  std::array<int64_t, 3> point;
  bool inside;
  Kind kind = Kind::Join;
};

/// Clean-up of the leaves whose `stamps` entry is `stamp` after `a op b` was combined into `a`: crack
/// repairs withdrawn and redone, sign hints applied, islands and leaves of more than one
/// component removed, and specks the Boolean made absorbed (`sign_b`: B's sign at a lattice
/// point, to tell those from B's own small components). A flip at the corner of a leaf
/// coarser than the finest level first splits that leaf (resampled with QEF threshold
/// `error`). Sets stats.repaired and stats.thin_points.
void clean_up(Octree& a, Stamps& stamps, uint32_t stamp, CsgOp op, const std::vector<SignHint>& hints,
              const std::function<bool(const std::array<int64_t, 3>&)>& sign_b, double error, CsgStats& stats);

}  // namespace pic::detail
