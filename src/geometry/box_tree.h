// A static bounding-box hierarchy for "which boxes overlap this one" (pairs of triangles that
// may intersect; dual polygons near a polygon).
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <numeric>
#include <vector>

#include <tbb/parallel_invoke.h>

#include "pic/types.h"

namespace pic::detail {

struct Box {
  Vec3 lo, hi;
};
inline bool overlap(const Box& a, const Box& b) {
  for (int k = 0; k < 3; ++k)
    if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
  return true;
}

/// A bounding-box hierarchy: median splits on the longest axis, leaves of up to 4 triangles.
class BoxTree {
 public:
  explicit BoxTree(const std::vector<Box>& boxes) : boxes_(boxes) {
    order_.resize(boxes.size());
    std::iota(order_.begin(), order_.end(), 0u);
    if (boxes.empty()) return;
    Counts counts;
    nodes_.resize(node_count(uint32_t(boxes.size()), counts));
    build(0, uint32_t(boxes.size()), 0, counts);
  }
  /// Replaces the boxes (same count) and refits every node's box to them, keeping the
  /// hierarchy: much cheaper than building anew when few boxes changed or all grew alike.
  void refit(const std::vector<Box>& boxes) {
    boxes_ = boxes;
    // Children come after their parent in nodes_: refit from the back.
    for (size_t id = nodes_.size(); id-- > 0;) {
      N& n = nodes_[id];
      if (n.count) {
        n.box = span_of(n.first, n.first + n.count);
      } else {
        n.box = nodes_[n.first].box;
        grow(n.box, nodes_[n.right].box);
      }
    }
  }
  /// Calls f(i, j), i < j, for every pair of overlapping boxes, in any order and from several
  /// threads at once. One walk of the tree against itself: a pair of nodes whose boxes are
  /// apart is dropped whole, where a query per box would walk down from the root each time.
  template <class F>
  void for_each_pair(F&& f) const {
    if (!nodes_.empty()) pairs_within(0, f, 0);
  }
  /// Calls f(j) for every box j overlapping q (closed boxes).
  template <class F>
  void query(const Box& q, F&& f) const {
    if (nodes_.empty()) return;
    uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top) {
      const N& n = nodes_[stack[--top]];
      if (!overlap(n.box, q)) continue;
      if (n.count) {
        for (uint32_t k = n.first; k < n.first + n.count; ++k)
          if (overlap(boxes_[order_[k]], q)) f(order_[k]);
      } else {
        stack[top++] = n.first;
        stack[top++] = n.right;
      }
    }
  }

 private:
  static void grow(Box& b, const Box& c) {
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = std::min(b.lo[a], c.lo[a]);
      b.hi[a] = std::max(b.hi[a], c.hi[a]);
    }
  }
  /// Pairs inside node a's subtree. Levels near the root run their three parts in parallel.
  template <class F>
  void pairs_within(uint32_t a, F& f, int level) const {
    const N& n = nodes_[a];
    if (n.count) {
      for (uint32_t x = n.first; x < n.first + n.count; ++x)
        for (uint32_t y = x + 1; y < n.first + n.count; ++y)
          if (overlap(boxes_[order_[x]], boxes_[order_[y]])) report(order_[x], order_[y], f);
      return;
    }
    const auto left = [&] { pairs_within(n.first, f, level + 1); };
    const auto right = [&] { pairs_within(n.right, f, level + 1); };
    const auto across = [&] { pairs_across(n.first, n.right, f, level + 1); };
    if (level < kParallelLevels) tbb::parallel_invoke(left, right, across);
    else left(), right(), across();
  }
  /// Pairs with one box under node a and the other under node b (disjoint subtrees).
  template <class F>
  void pairs_across(uint32_t a, uint32_t b, F& f, int level) const {
    const N &na = nodes_[a], &nb = nodes_[b];
    if (!overlap(na.box, nb.box)) return;
    if (na.count && nb.count) {
      for (uint32_t x = na.first; x < na.first + na.count; ++x)
        for (uint32_t y = nb.first; y < nb.first + nb.count; ++y)
          if (overlap(boxes_[order_[x]], boxes_[order_[y]])) report(order_[x], order_[y], f);
      return;
    }
    // Split the node with the larger box (a leaf cannot split).
    const bool split_a = nb.count || (!na.count && extent(na.box) >= extent(nb.box));
    const N& s = split_a ? na : nb;
    const uint32_t other = split_a ? b : a;
    const auto one = [&] { pairs_across(s.first, other, f, level + 1); };
    const auto two = [&] { pairs_across(s.right, other, f, level + 1); };
    if (level < kParallelLevels) tbb::parallel_invoke(one, two);
    else one(), two();
  }
  template <class F>
  void report(uint32_t x, uint32_t y, F& f) const {
    if (x < y) f(x, y);
    else f(y, x);
  }
  static double extent(const Box& b) { return (b.hi[0] - b.lo[0]) + (b.hi[1] - b.lo[1]) + (b.hi[2] - b.lo[2]); }
  static constexpr int kParallelLevels = 10;
  struct N {
    Box box;
    uint32_t first, count, right;
  };
  /// The union of the boxes order_[begin, end).
  Box span_of(uint32_t begin, uint32_t end) const {
    Box b = boxes_[order_[begin]];
    for (uint32_t k = begin + 1; k < end; ++k) grow(b, boxes_[order_[k]]);
    return b;
  }
  using Counts = std::map<uint32_t, uint32_t>;  // nodes over a range, by its size (above 4)
  /// Nodes of the tree over n boxes (median splits down to leaves of up to 4), filling `counts`
  /// for every size below: the layout is fixed by n alone, so both halves can be built at once
  /// into their own slots.
  static uint32_t node_count(uint32_t n, Counts& counts) {
    if (n <= 4) return 1;
    if (const auto it = counts.find(n); it != counts.end()) return it->second;
    return counts[n] = 1 + node_count(n / 2, counts) + node_count(n - n / 2, counts);
  }
  /// Node `id` over order_[begin, end), its subtree in pre-order after it (children after
  /// their parent, as refit needs). `counts` is complete here: only read.
  void build(uint32_t begin, uint32_t end, uint32_t id, const Counts& counts) {
    const Box b = span_of(begin, end);
    if (end - begin <= 4) {
      nodes_[id] = {b, begin, end - begin, 0};
      return;
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (b.hi[a] - b.lo[a] > b.hi[axis] - b.lo[axis]) axis = a;
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end, [&](uint32_t x, uint32_t y) {
      return boxes_[x].lo[axis] + boxes_[x].hi[axis] < boxes_[y].lo[axis] + boxes_[y].hi[axis];
    });
    const uint32_t left = id + 1, right = left + (mid - begin <= 4 ? 1 : counts.at(mid - begin));
    const auto build_left = [&] { build(begin, mid, left, counts); };
    const auto build_right = [&] { build(mid, end, right, counts); };
    if (end - begin > 16384) tbb::parallel_invoke(build_left, build_right);
    else build_left(), build_right();
    nodes_[id] = {b, left, 0, right};
  }
  std::vector<Box> boxes_;
  std::vector<uint32_t> order_;
  std::vector<N> nodes_;
};

}  // namespace pic::detail
