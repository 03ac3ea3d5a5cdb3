#include "geometry/qef.h"
#include "geometry/tolerances.h"

#include <Eigen/Dense>
#include <cmath>

namespace pic::detail {

void Qef::add_plane(const Vec3& n, double d, double w) {
  a[0] += w * n[0] * n[0];
  a[1] += w * n[0] * n[1];
  a[2] += w * n[0] * n[2];
  a[3] += w * n[1] * n[1];
  a[4] += w * n[1] * n[2];
  a[5] += w * n[2] * n[2];
  b[0] += w * n[0] * d;
  b[1] += w * n[1] * d;
  b[2] += w * n[2] * d;
  c += w * d * d;
  weight += w;
}

Qef& Qef::operator+=(const Qef& o) {
  for (int k = 0; k < 6; ++k) a[k] += o.a[k];
  for (int k = 0; k < 3; ++k) b[k] += o.b[k];
  c += o.c;
  weight += o.weight;
  return *this;
}

double Qef::error(const Vec3& x) const {
  if (weight <= 0) return 0;
  const double ax0 = a[0] * x[0] + a[1] * x[1] + a[2] * x[2];
  const double ax1 = a[1] * x[0] + a[3] * x[1] + a[4] * x[2];
  const double ax2 = a[2] * x[0] + a[4] * x[1] + a[5] * x[2];
  const double q = x[0] * ax0 + x[1] * ax1 + x[2] * ax2 - 2 * (b[0] * x[0] + b[1] * x[1] + b[2] * x[2]) + c;
  return std::max(q, 0.0) / weight;
}

namespace {

bool in_box(const Eigen::Vector3d& x, const Vec3& lo, const Vec3& hi) {
  for (int k = 0; k < 3; ++k)
    if (x[k] < lo[k] || x[k] > hi[k]) return false;
  return true;
}

}  // namespace

Qef::Solution Qef::solve(const Vec3& seed, Pinv pinv) const {
  return solve_in_box(seed, {-kHuge, -kHuge, -kHuge}, {kHuge, kHuge, kHuge}, pinv);
}

Qef::Solution Qef::solve_in_box(const Vec3& seed, const Vec3& lo, const Vec3& hi, Pinv pinv) const {
  const bool damped = pinv == Pinv::Damped;
  const double cutoff = damped ? kSharpDamping : kRelativeCutoff;
  if (weight <= 0) return {seed, 0, 0};
  Eigen::Matrix3d m;
  m << a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5];
  const Eigen::Vector3d s(seed[0], seed[1], seed[2]);
  const Eigen::Vector3d r = Eigen::Vector3d(b[0], b[1], b[2]) - m * s;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(m);
  const Eigen::Vector3d ev = eig.eigenvalues();
  const double top = std::max({std::abs(ev[0]), std::abs(ev[1]), std::abs(ev[2])});
  Eigen::Vector3d inv = Eigen::Vector3d::Zero();
  int rank = 0;
  std::array<bool, 3> fixed{};
  for (int k = 0; k < 3; ++k) {
    fixed[k] = top > 0 && std::abs(ev[k]) > cutoff * top;
    rank += fixed[k];
    if (damped && top > 0) inv[k] = ev[k] / (ev[k] * ev[k] + cutoff * top * cutoff * top);
    else if (fixed[k]) inv[k] = 1.0 / ev[k];
  }
  const Eigen::Matrix3d& u = eig.eigenvectors();
  Eigen::Vector3d x = s + u * inv.asDiagonal() * (u.transpose() * r);
  if (!in_box(x, lo, hi) && rank == 2) {
    // A crease: the minimizers form the line x + t d. Clip it to the box.
    Eigen::Vector3d d;
    for (int k = 0; k < 3; ++k)
      if (!fixed[k]) d = u.col(k);
    double t0 = -kHuge, t1 = kHuge;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(d[k]) < kTinyDivisor) {
        if (x[k] < lo[k] || x[k] > hi[k]) t0 = 1, t1 = 0;
        continue;
      }
      double a = (lo[k] - x[k]) / d[k], b = (hi[k] - x[k]) / d[k];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
    }
    if (t0 <= t1) x += 0.5 * (t0 + t1) * d;
  } else if (!in_box(x, lo, hi) && rank == 1) {
    // A plane: the centroid of its section with the box (where it crosses the box edges).
    Eigen::Vector3d n = Eigen::Vector3d::Zero();  // rank 1: one column below is taken
    for (int k = 0; k < 3; ++k)
      if (fixed[k]) n = u.col(k);
    const double off = n.dot(x);
    Eigen::Vector3d acc = Eigen::Vector3d::Zero();
    int cnt = 0;
    for (int axis = 0; axis < 3; ++axis)
      for (int c = 0; c < 4; ++c) {
        Eigen::Vector3d a;
        const int i = (axis + 1) % 3, j = (axis + 2) % 3;
        a[axis] = lo[axis];
        a[i] = (c & 1) ? hi[i] : lo[i];
        a[j] = (c & 2) ? hi[j] : lo[j];
        const double fa = n.dot(a) - off, len = hi[axis] - lo[axis];
        if (n[axis] == 0) continue;
        const double t = -fa / (n[axis] * len);
        if (t < 0 || t > 1) continue;
        a[axis] += t * len;
        acc += a;
        ++cnt;
      }
    if (cnt > 0) x = acc / cnt;
  }
  const Vec3 p{x[0], x[1], x[2]};
  return {p, error(p), rank};
}

}  // namespace pic::detail
