// Lattice points that keep thin features: see thin_features.h.
#include "signs/thin_features.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>

#include "signs/consistency.h"

namespace pic::detail {

std::vector<AskedSign> thin_feature_signs(std::vector<AskedSign>& asked, const std::vector<AskedSign>& beside,
                                          int64_t step) {
  using Lat = std::array<int64_t, 3>;
  const auto key = [](const Lat& p, bool inside) { return lattice_key(p) * 2 + uint64_t(inside); };
  std::unordered_set<uint64_t> kept;
  for (const auto& [p, inside] : asked) kept.insert(key(p, inside));
  std::unordered_map<uint64_t, Lat> waiting;
  for (const auto& [p, inside] : beside)
    if (!kept.count(key(p, inside))) waiting.emplace(key(p, inside), p);
  std::vector<AskedSign> work(asked.begin(), asked.end());
  while (!work.empty() && !waiting.empty()) {
    const auto [p, inside] = work.back();
    work.pop_back();
    for (int a = 0; a < 3; ++a)
      for (const int64_t d : {-step, step}) {
        Lat q = p;
        q[a] += d;
        const auto it = waiting.find(key(q, inside));
        if (it == waiting.end()) continue;
        asked.push_back({q, inside});
        work.push_back({q, inside});
        waiting.erase(it);
      }
  }
  std::sort(asked.begin(), asked.end());
  asked.erase(std::unique(asked.begin(), asked.end()), asked.end());
  std::vector<AskedSign> set;
  for (size_t i = 0; i < asked.size(); ++i) {
    const bool both = (i + 1 < asked.size() && asked[i + 1].first == asked[i].first) ||
                      (i > 0 && asked[i - 1].first == asked[i].first);
    if (!both) set.push_back(asked[i]);
  }
  return set;
}

}  // namespace pic::detail
