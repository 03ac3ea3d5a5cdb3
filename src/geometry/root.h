// Where a function changes sign along a segment: false position with the Illinois step (the
// end that stays put twice in a row has its value halved), the root finder every crossing of
// a function with a cell edge uses. As a state that is asked for its next parameter and told
// the value there, so many roots can be found in step, each step's values asked for at once.
#pragma once

#include <algorithm>
#include <cmath>

#include "geometry/tolerances.h"

namespace pic::detail {

/// The parameter t in [0, 1] where f changes sign, given f(0) = f0 and f(1) = f1 of opposite
/// signs, to `tolerance` of the unit interval within `iterations` values of f (f(t) == 0 ends
/// the search). Each step keeps a thousandth of the bracket off its ends.
class IllinoisRoot {
 public:
  IllinoisRoot(double f0, double f1, double tolerance, int iterations)
      : f0_(f0), f1_(f1), tolerance_(tolerance), iterations_(iterations) {}
  bool done() const { return exact_ || it_ >= iterations_ || !(hi_ - lo_ > tolerance_); }
  /// Where to ask f next.
  double next() const {
    return std::clamp(lo_ + (hi_ - lo_) * f0_ / (f0_ - f1_), lo_ + (hi_ - lo_) * kBracketInset, hi_ - (hi_ - lo_) * kBracketInset);
  }
  /// f's value at next().
  void take(double ft) {
    const double t = next();
    ++it_;
    if (ft == 0) {
      lo_ = hi_ = t;
      exact_ = true;
    } else if ((ft < 0) == (f0_ < 0)) {
      lo_ = t, f0_ = ft;
      if (last_ == 1) f1_ /= 2;
      last_ = 1;
    } else {
      hi_ = t, f1_ = ft;
      if (last_ == -1) f0_ /= 2;
      last_ = -1;
    }
  }
  double root() const { return (lo_ + hi_) / 2; }

 private:
  double lo_ = 0, hi_ = 1, f0_, f1_, tolerance_;
  int iterations_, it_ = 0, last_ = 0;
  bool exact_ = false;
};

/// IllinoisRoot run to the end on f.
template <class F>
double illinois_root(F&& f, double f0, double f1, double tolerance, int iterations) {
  IllinoisRoot r(f0, f1, tolerance, iterations);
  while (!r.done()) r.take(f(r.next()));
  return r.root();
}

/// A root of f along [0, 1] by Newton steps on f and its slope from one evaluation, kept
/// inside the bracket that the values shrink (bisection where a step would leave it), to
/// `tolerance`; starts at false position. Where f is smooth Newton converges quadratically:
/// after a Newton step shorter than sqrt(tolerance) the next would be shorter than tolerance
/// (times f''/f'), so that step is the last and f is not asked at its end (a bisection step
/// still has to shrink below the tolerance). The slope at the answer
/// is that of the last value (its direction within that step of the answer's).
class NewtonRoot {
 public:
  NewtonRoot(double f0, double f1, double tolerance, int iterations)
      : f0_(f0), t_(std::clamp(f0 / (f0 - f1), 0.0, 1.0)), tolerance_(tolerance), last_step_(std::sqrt(tolerance)),
        iterations_(iterations) {}
  bool done() const { return done_; }
  double next() const { return t_; }
  /// f and its slope at next().
  void take(double ft, double slope) {
    if (++it_ >= iterations_ || ft == 0) {
      done_ = true;
      return;
    }
    ((ft < 0) == (f0_ < 0) ? lo_ : hi_) = t_;
    double step = t_ - ft / slope;
    const bool newton = step > lo_ && step < hi_;
    if (!newton) step = (lo_ + hi_) / 2;
    done_ = std::abs(step - t_) < (newton ? last_step_ : tolerance_);
    t_ = step;
    if (hi_ - lo_ < tolerance_) done_ = true;
  }
  double root() const { return t_; }

 private:
  double lo_ = 0, hi_ = 1, f0_, t_, tolerance_, last_step_;
  int iterations_, it_ = 0;
  bool done_ = false;
};

}  // namespace pic::detail
