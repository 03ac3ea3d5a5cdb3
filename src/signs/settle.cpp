// The settling loop: see settle.h.
#include "signs/settle.h"

#include <algorithm>
#include <numeric>

#include "signs/leaf_walks.h"

namespace pic::detail {

namespace {

/// Per node: whether its closed cell meets a capped leaf's (ancestors included).
std::vector<uint8_t> near_capped(const Octree& t) {
  std::vector<uint8_t> near(t.nodes.size(), 0);
  auto walk = [&](auto&& self, uint32_t node, const Cell& cell) -> void {
    const Node& n = t.nodes[node];
    if (n.kind == CellKind::Internal) {
      for (int c = 0; c < 8; ++c) self(self, n.index + c, cell.child(c));
    } else if (n.kind == CellKind::Gray && (n.flags & kFlagCapped)) {
      for_each_node_meeting(t, 0, Cell{}, cell.lat, cell.corner(7), [&](uint32_t m) { near[m] = 1; });
    }
  };
  walk(walk, 0, Cell{});
  return near;
}

}  // namespace

size_t settle(Octree& t, const SettlePlan& plan, PinnedPoints& pinned) {
  const auto* component_scope = plan.one_component_everywhere ? nullptr : plan.active;
  // Every node a flip touches, logged for the island pass's next round (which looks only near
  // them) and passed on to the plan's own record.
  IslandRounds rounds;
  const std::function<void(uint32_t)> touched = [&](uint32_t n) {
    rounds.touched.push_back(n);
    if (plan.touched) (*plan.touched)(n);
  };
  bool converged = false;  // the last round changed no sign
  bool kept_two = false;   // and left leaves with two components (capped ones)
  for (int round = 0; round < 4; ++round) {
    const size_t islands = remove_islands(t, plan.active, &touched, &pinned, &rounds);
    const ComponentFlips how{&touched, &pinned, plan.spare_coarse, plan.refine ? &plan.refine : nullptr,
                             plan.margin ? &plan.margin : nullptr};
    const TopologyFix fix = enforce_one_component(t, component_scope, how);
    converged = islands == 0 && fix.flipped == 0;
    kept_two = fix.remaining > 0;
    // Rounds repeat until one changes no sign: only then may the erosions below stay around
    // the capped leaves instead of checking every coarse boundary of the scope again.
    if (converged) break;
  }
  // The guarantee's erosions: where the rounds ran out, over the whole scope; else around the
  // capped leaves (those the passes left two components in, and, when sampling, every one).
  // Above the cap the rules hold by refinement and by the passes' own checks.
  if (!converged) {
    erode_until_valid(t, component_scope, plan.active, &touched);
  } else if (kept_two || plan.erode_after_quiet) {
    erode_around_capped(t, &touched);
  }
  const std::function<bool(const Speck&)> keep_none = [](const Speck&) { return false; };
  remove_specks(t, plan.active, plan.keep_speck ? plan.keep_speck : keep_none, plan.specks);
  return repair_cracks(t, plan.active);
}

size_t erode_around_capped(Octree& t, const std::function<void(uint32_t)>* touched) {
  std::vector<uint8_t> near = near_capped(t);
  if (std::find(near.begin(), near.end(), 1) == near.end()) return 0;
  const std::function<bool(uint32_t)> in = [&](uint32_t n) { return n < near.size() && near[n] != 0; };
  const std::function<void(uint32_t)> mark = [&](uint32_t n) {
    if (n >= near.size()) near.resize(t.nodes.size(), 0);
    near[n] = 1;
    if (touched) (*touched)(n);
  };
  return erode_until_valid(t, &in, &in, &mark);
}

size_t erode_until_valid(Octree& t, const std::function<bool(uint32_t)>* components,
                         const std::function<bool(uint32_t)>* boundaries, const std::function<void(uint32_t)>* touched) {
  // Both erosions only take points out, so together they end, and they end only where every
  // leaf has one component and every coarse leaf a simple boundary. A leaf's verdict reads only
  // the signs on its closed cell, so after the first pass only leaves meeting a point flipped in
  // the last pass or in this one so far can have changed: the passes look only there, and find
  // the same leaves, in the same order, as a pass over the whole scope.
  std::vector<uint8_t> last, now;  // per node: meets a point flipped in the last pass / this one
  bool whole = true;
  const auto near = [&](uint32_t n) { return whole || (n < last.size() && last[n]) || (n < now.size() && now[n]); };
  const std::function<bool(uint32_t)> in_components = [&](uint32_t n) { return near(n) && (!components || (*components)(n)); };
  const std::function<bool(uint32_t)> in_boundaries = [&](uint32_t n) { return near(n) && (!boundaries || (*boundaries)(n)); };
  const std::function<void(const std::array<int64_t, 3>&)> flipped_at = [&](const std::array<int64_t, 3>& p) {
    now.resize(t.nodes.size(), 0);
    for_each_node_meeting(t, 0, Cell{}, p, p, [&](uint32_t m) { now[m] = 1; });
  };
  size_t total = 0;
  for (;;) {
    const size_t flipped =
        erode_to_one_component(t, whole ? components : &in_components, touched, &flipped_at) +
        erode_to_simple_boundaries(t, whole ? boundaries : &in_boundaries, touched, &flipped_at);
    if (flipped == 0) return total;
    total += flipped;
    whole = false;
    last.swap(now);
    now.assign(t.nodes.size(), 0);
  }
}

namespace {

/// Per node: whether its cell meets one of the region's boxes (an ancestor of such a node
/// does too, as the passes in topology.h need of an `active` filter). Each node tests only
/// the boxes its parent met.
std::vector<uint8_t> nodes_in(const Octree& t, const SettleRegion& region) {
  std::vector<uint8_t> in(t.nodes.size(), 0);
  std::vector<std::vector<uint32_t>> met(kMaxLevel + 2);  // per level: the boxes the cell meets
  met[0].resize(region.boxes.size());
  std::iota(met[0].begin(), met[0].end(), 0u);
  auto walk = [&](auto&& self, uint32_t node, const Cell& cell) -> void {
    const Box box{cell.min_unit(), cell.max_unit()};
    const std::vector<uint32_t>& from = met[cell.level];
    std::vector<uint32_t>& here = met[cell.level + 1];
    here.clear();
    for (uint32_t i : from)
      if (overlap(region.boxes[i], box)) here.push_back(i);
    if (here.empty()) return;
    in[node] = 1;
    const Node& n = t.nodes[node];
    if (n.kind != CellKind::Internal) return;
    for (int c = 0; c < 8; ++c) self(self, n.index + c, cell.child(c));  // children fill the next list
  };
  walk(walk, 0, Cell{});
  return in;
}

}  // namespace

void settle_sampled(Octree& tree, const SettleRegion& region, const ResampleLeaf* resample,
                    const std::function<double(const std::array<int64_t, 3>&)>* margin) {
  std::vector<uint8_t> in;
  if (!region.everywhere) in = nodes_in(tree, region);
  const std::function<bool(uint32_t)> active = [&](uint32_t n) { return in[n] != 0; };
  const std::function<void(uint32_t)> touched = [&](uint32_t n) {
    if (n >= in.size()) in.resize(tree.nodes.size(), 0);
    in[n] = 1;
  };
  SettlePlan plan;
  plan.active = region.everywhere ? nullptr : &active;
  plan.touched = region.everywhere ? nullptr : &touched;
  plan.one_component_everywhere = true;
  plan.erode_after_quiet = true;
  // Where |w| hovers at 1/2 (an open part's end inside another part) the level set leaves
  // specks a cell across, closed shells or voids of a few triangles: resolution noise.
  plan.specks = {tree.max_depth - 1, true};
  const std::function<void(uint32_t)> ignore = [](uint32_t) {};
  if (resample)
    plan.refine = [&](const std::array<int64_t, 3>& p) { refine_around(tree, p, *resample, region.everywhere ? ignore : touched); };
  if (margin) plan.margin = *margin;
  PinnedPoints pinned;
  settle(tree, plan, pinned);
}

}  // namespace pic::detail
