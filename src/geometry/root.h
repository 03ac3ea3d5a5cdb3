// Where a function changes sign along a segment: false position with the Illinois step (the
// end that stays put twice in a row has its value halved), the root finder every crossing of
// a function with a cell edge uses.
#pragma once

#include <algorithm>

namespace pic::detail {

/// The parameter t in [0, 1] where f changes sign, given f(0) = f0 and f(1) = f1 of opposite
/// signs (0 counts with the negative side's opposite: f(t) == 0 ends the search), to
/// `tolerance` of the unit interval within `iterations` values of f. Each step keeps a
/// thousandth of the bracket off its ends.
template <class F>
double illinois_root(F&& f, double f0, double f1, double tolerance, int iterations) {
  double lo = 0, hi = 1;
  int last = 0;
  for (int it = 0; it < iterations && hi - lo > tolerance; ++it) {
    const double t = std::clamp(lo + (hi - lo) * f0 / (f0 - f1), lo + (hi - lo) * 1e-3, hi - (hi - lo) * 1e-3);
    const double ft = f(t);
    if (ft == 0) return t;
    if ((ft < 0) == (f0 < 0)) {
      lo = t, f0 = ft;
      if (last == 1) f1 /= 2;
      last = 1;
    } else {
      hi = t, f1 = ft;
      if (last == -1) f0 /= 2;
      last = -1;
    }
  }
  return (lo + hi) / 2;
}

}  // namespace pic::detail
