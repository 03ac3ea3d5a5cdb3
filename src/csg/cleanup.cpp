// The CSG clean-up: see cleanup.h.
#include "csg/cleanup.h"

#include "csg/refine.h"
#include "signs/refine.h"
#include "signs/settle.h"
#include "signs/thin_features.h"

namespace pic::detail {
namespace {

using Lat = std::array<int64_t, 3>;

/// Turns the stamped gray leaves without a sign change back into uniform leaves. Such a leaf
/// is a crack repair (repair_cracks): a uniform leaf given a vertex so that the contour closes
/// over the sign changes its finer neighbours show on its faces. The island and face passes
/// take every gray leaf for a cell whose faces must look like one cell's, so they "fixed" those
/// neighbours' signs to the repair's uniform ones: where an operand's repair leaf was copied
/// into the result, that carved a slit as deep as the leaf into a flat face of the operand.
/// repair_cracks after the passes gives the leaves back their
/// vertices where they still border a sign change.
void withdraw_crack_repairs(Octree& t, uint32_t node, const std::function<bool(uint32_t)>& active) {
  if (!active(node)) return;
  Node& n = t.nodes[node];
  if (n.kind == CellKind::Internal) {
    for (int c = 0; c < 8; ++c) withdraw_crack_repairs(t, n.index + c, active);
  } else if (n.kind == CellKind::Gray && (n.signs == 0 || n.signs == 0xff)) {
    n = Node{0, n.signs != 0 ? CellKind::Black : CellKind::White, 0, 0, 0};
  }
}

/// Whether one operand alone shows the speck, so that it is that operand's own small
/// component (which the exact Boolean keeps), not one the Boolean made: B's signs (as the
/// operation sees them) give the result's pattern, or B is neutral over the whole speck (the
/// result there is A, which then has the speck itself).
bool speck_is_inherited(const Speck& sp, CsgOp op, const std::function<bool(const Lat&)>& sign_b) {
  const bool neutral = op == CsgOp::Intersect;  // B's sign that leaves A's unchanged
  bool all_neutral = true, b_shows = true;
  auto check = [&](const Lat& p, bool result) {
    const bool sb = sign_b(p);
    all_neutral = all_neutral && sb == neutral;
    b_shows = b_shows && (op == CsgOp::Subtract ? !sb : sb) == result;
  };
  for (const Lat& p : sp.points) check(p, sp.inside);
  for (const Lat& p : sp.rim) check(p, !sp.inside);
  return all_neutral || b_shows;
}

/// What setting a hinted sign would do: how many of the leaves around the point (each has it
/// as a corner) hold more than one component before and after.
struct HintedFlip {
  int before = 0, after = 0;
  bool possible = false;  // every leaf around is a stamped leaf with the point as a corner
  bool needed = false;    // the point's sign differs from the hint's
};

/// Whether setting corner k of a coarser leaf to `inside` would strand a finer point on one of
/// its edges or faces through that corner: a point of the other sign on an edge or face whose
/// corners all have this sign is an island, which the island pass then flips too, carrying
/// the hint along the whole edge or face (3 points along a 4-cell leaf's edge, the surface
/// 1.41 cells out). Faces wider than kMaxCheckedFace finest cells are not searched.
bool strands_finer_points(const Octree& t, const LeafRef& big, int k, bool inside) {
  constexpr int64_t kMaxCheckedFace = 32;
  const int64_t step = int64_t{1} << (kMaxLevel - t.max_depth);
  const int64_t n = big.cell.span() / step;
  const uint8_t s = uint8_t(signs_of(t.nodes[big.node]) & ~(1 << k)) | uint8_t(inside << k);
  const Lat lo = big.cell.lat;
  auto stranded = [&](const Lat& q) {
    const std::optional<bool> sq = point_sign(t, q);
    return sq && *sq != inside;
  };
  for (int a = 0; a < 3; ++a) {
    // The edge along axis a through corner k.
    if (bool((s >> (k ^ (1 << a))) & 1) != inside) continue;
    Lat q = big.cell.corner(k);
    for (int64_t i = 1; i < n; ++i) {
      q[a] = lo[a] + i * step;
      if (stranded(q)) return true;
    }
  }
  if (n > kMaxCheckedFace) return false;
  for (int a = 0; a < 3; ++a) {
    // The face across axis a through corner k: its corners share bit a with k.
    bool uniform = true;
    for (int c = 0; c < 8; ++c)
      if (((c ^ k) >> a & 1) == 0) uniform = uniform && bool((s >> c) & 1) == inside;
    if (!uniform) continue;
    const int u = (a + 1) % 3, w = (a + 2) % 3;
    Lat q = big.cell.corner(k);
    for (int64_t i = 1; i < n; ++i)
      for (int64_t j = 1; j < n; ++j) {
        q[u] = lo[u] + i * step;
        q[w] = lo[w] + j * step;
        if (stranded(q)) return true;
      }
  }
  return false;
}

HintedFlip examine_hint(const Octree& t, const SignHint& h, const std::function<bool(uint32_t)>& stamped) {
  HintedFlip f;
  for (int o = 0; o < 8; ++o) {
    const Lat q{h.point[0] - (o & 1), h.point[1] - ((o >> 1) & 1), h.point[2] - ((o >> 2) & 1)};
    const LeafRef r = leaf_at(t, q);
    const int k = r.cell.corner_index(h.point);
    if (k < 0 || !stamped(r.node) || t.nodes[r.node].kind == CellKind::Internal) return f;
    if (r.cell.level < t.max_depth && strands_finer_points(t, r, k, h.inside)) return f;
    const uint8_t s = signs_of(t.nodes[r.node]);
    const uint8_t set = with_corner(s, k, h.inside);
    f.needed = f.needed || set != s;
    f.before += multi_component(s);
    f.after += multi_component(set);
  }
  f.possible = true;
  return f;
}

/// Sets the hinted signs (sign_hint) where every leaf around the point is stamped and has it
/// as a corner and the flip leaves fewer leaves of more than one component around it. Some
/// flips leave one for the one-component pass (the next point along an oblique slab; asking
/// for none leaves such slabs cut). The points set are pinned: enforce_one_component then
/// undoes them only when nothing else will do.
void apply_sign_hints(Octree& t, const std::vector<SignHint>& hints, const std::function<bool(uint32_t)>& stamped,
                      PinnedPoints& pinned, const std::function<void(const Lat&)>& refine) {
  for (const SignHint& h : hints) {
    if (h.kind != SignHint::Kind::Join) continue;
    const HintedFlip f = examine_hint(t, h, stamped);
    if (!f.possible || !f.needed || f.after >= f.before) continue;
    refine(h.point);
    set_point_sign(t, h.point, h.inside, nullptr);
    pinned.insert(lattice_key(h.point));
  }
}

/// Gives the lattice points that capped cells found across a thin feature (thin_feature_hints,
/// joined by thin_feature_signs) the feature's sign, the coarser leaves around them split
/// first. The leaves that change are flagged capped: their vertices stand for a feature
/// thinner than the cell, not for its exact surface. The points are pinned, as the other
/// hints' are. Returns how many points it set.
size_t keep_thin_features(Octree& t, const std::vector<SignHint>& hints, PinnedPoints& pinned,
                          const std::function<void(const Lat&)>& refine, const std::function<void(uint32_t)>& touched) {
  std::vector<AskedSign> asked, beside;
  for (const SignHint& h : hints) {
    if (h.kind == SignHint::Kind::Thin) asked.push_back({h.point, h.inside});
    if (h.kind == SignHint::Kind::BesideThin) beside.push_back({h.point, h.inside});
  }
  if (asked.empty()) return 0;
  const std::vector<AskedSign> set = thin_feature_signs(asked, beside, int64_t{1} << (kMaxLevel - t.max_depth));
  for (const auto& [p, inside] : set) {
    refine(p);
    set_point_sign(t, p, inside, &touched);
    for (const auto& l : leaves_around(t, p))
      if (t.nodes[l.node].kind == CellKind::Gray) t.nodes[l.node].flags |= kFlagCapped;
    pinned.insert(lattice_key(p));
  }
  return set.size();
}

}  // namespace

void clean_up(Octree& a, Stamps& stamps, uint32_t stamp, CsgOp op, const std::vector<SignHint>& hints,
              const std::function<bool(const Lat&)>& sign_b, double error, CsgStats& stats) {
  std::function<bool(uint32_t)> stamped = [&](uint32_t n) { return stamps[n] == stamp; };
  std::function<void(uint32_t)> stamp_it = [&](uint32_t n) {
    if (n >= stamps.size()) stamps.resize(a.nodes.size(), 0);
    stamps[n] = stamp;
  };
  // A flip at a coarse leaf's corner would move all of that leaf's surface: split it first.
  const ResampleLeaf from_contour = [&](const LeafRef& l, const Lat& q) { return resample_from_contour(a, l, q, error); };
  const std::function<void(const Lat&)> refine = [&](const Lat& p) { refine_around(a, p, from_contour, stamp_it); };
  // Crack repairs of the operands are redone on the result: as gray leaves they would pass
  // for coarse neighbours that finer sign changes contradict (a slit in a flat face).
  withdraw_crack_repairs(a, 0, stamped);
  // Islands sit where new geometry meets finer old cells; a flip that makes a leaf hold one
  // component can leave a new island, so the two alternate until both are quiet.
  PinnedPoints pinned;
  stats.thin_points = keep_thin_features(a, hints, pinned, refine, stamp_it);
  apply_sign_hints(a, hints, stamped, pinned, refine);
  SettlePlan plan;
  plan.active = &stamped;
  plan.touched = &stamp_it;
  plan.spare_coarse = true;
  plan.refine = refine;
  // Specks the Boolean made (where the two operands' surfaces pass within a fraction of a
  // cell of each other); one operand's own small components stay.
  plan.keep_speck = [&](const Speck& sp) { return speck_is_inherited(sp, op, sign_b); };
  plan.specks.coarse_rim = true;
  stats.repaired = settle(a, plan, pinned);
}

}  // namespace pic::detail
