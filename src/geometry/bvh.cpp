#include "geometry/bvh.h"

#include <algorithm>

namespace pic::detail {

void TriangleBvh::build(const std::vector<ITri>& tris) {
  nodes_.clear();
  order_.resize(tris.size());
  for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  if (!tris.empty()) build_range(tris, 0, static_cast<uint32_t>(tris.size()));
}

uint32_t TriangleBvh::build_range(const std::vector<ITri>& tris, uint32_t begin, uint32_t end) {
  const auto id = static_cast<uint32_t>(nodes_.size());
  nodes_.push_back({});
  I3 lo = tris[order_[begin]].lo, hi = tris[order_[begin]].hi;
  for (uint32_t i = begin; i < end; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], tris[order_[i]].lo[k]);
      hi[k] = std::max(hi[k], tris[order_[i]].hi[k]);
    }
  constexpr uint32_t kLeafSize = 8;
  if (end - begin <= kLeafSize) {
    nodes_[id] = {lo, hi, begin, end - begin, 0};
    return id;
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
  const uint32_t mid = (begin + end) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end, [&](uint32_t a, uint32_t b) {
    return tris[a].lo[axis] + tris[a].hi[axis] < tris[b].lo[axis] + tris[b].hi[axis];
  });
  const uint32_t left = build_range(tris, begin, mid);
  const uint32_t right = build_range(tris, mid, end);
  nodes_[id] = {lo, hi, left, 0, right};
  return id;
}

void TriangleBvh::query(const std::vector<ITri>& tris, const I3& lo, const I3& hi, std::vector<uint32_t>& out) const {
  if (nodes_.empty()) return;
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BNode& n = nodes_[stack[--top]];
    bool hit = true;
    for (int k = 0; k < 3 && hit; ++k) hit = n.hi[k] >= lo[k] && n.lo[k] <= hi[k];
    if (!hit) continue;
    if (n.count > 0) {
      for (uint32_t i = n.first; i < n.first + n.count; ++i)
        if (overlaps_box(tris[order_[i]], lo, hi)) out.push_back(order_[i]);
    } else {
      stack[top++] = n.first;
      stack[top++] = n.right;
    }
  }
}

}  // namespace pic::detail
