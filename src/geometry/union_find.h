// Disjoint sets over 0..n-1 with path halving.
#pragma once

#include <cstddef>
#include <numeric>
#include <vector>

namespace pic::detail {

struct UnionFind {
  std::vector<size_t> parent;
  explicit UnionFind(size_t n) { reset(n); }
  void reset(size_t n) {
    parent.resize(n);
    std::iota(parent.begin(), parent.end(), size_t{0});
  }
  size_t root(size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(size_t a, size_t b) { parent[root(a)] = root(b); }
};

}  // namespace pic::detail
