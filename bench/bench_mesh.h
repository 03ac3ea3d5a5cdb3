// Benchmark-side mesh helpers, header-only and independent of the PIC library (the OpenVDB peer
// uses them too): a fast OBJ reader/writer, peak RSS, and the two-sided Hausdorff distance
// between two triangle meshes (exact point-to-triangle distances over a BVH, from the vertices
// plus deterministic area-weighted surface samples of each side).
#pragma once

#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace bench {

using V3 = std::array<double, 3>;
struct Mesh {
  std::vector<V3> p;
  std::vector<std::array<uint32_t, 3>> t;
};

/// Peak resident set size of this process so far, in bytes (Linux: ru_maxrss is in KiB).
inline size_t peak_rss_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<size_t>(u.ru_maxrss) * 1024;
}

/// OBJ: `v x y z` and `f a b c ...` (v/vt/vn and negative indices accepted, polygons fanned).
inline Mesh read_obj(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Mesh m;
  const char* s = text.c_str();
  const char* end = s + text.size();
  std::vector<uint32_t> poly;
  while (s < end) {
    const char* eol = static_cast<const char*>(std::memchr(s, '\n', end - s));
    if (!eol) eol = end;
    if (s[0] == 'v' && (s[1] == ' ' || s[1] == '\t')) {
      char* q = const_cast<char*>(s + 2);
      V3 v;
      for (int k = 0; k < 3; ++k) v[k] = std::strtod(q, &q);
      m.p.push_back(v);
    } else if (s[0] == 'f' && (s[1] == ' ' || s[1] == '\t')) {
      poly.clear();
      const char* q = s + 2;
      while (q < eol) {
        while (q < eol && (*q == ' ' || *q == '\t' || *q == '\r')) ++q;
        if (q >= eol) break;
        char* after = nullptr;
        const long i = std::strtol(q, &after, 10);
        if (after == q) throw std::runtime_error(path + ": bad face line");
        const long nv = static_cast<long>(m.p.size());
        const long v = i > 0 ? i - 1 : nv + i;
        if (v < 0 || v >= nv) throw std::runtime_error(path + ": face index out of range");
        poly.push_back(static_cast<uint32_t>(v));
        q = after;
        while (q < eol && *q != ' ' && *q != '\t') ++q;  // skip /vt/vn
      }
      for (size_t k = 1; k + 1 < poly.size(); ++k) m.t.push_back({poly[0], poly[k], poly[k + 1]});
    }
    s = eol + 1;
  }
  if (m.t.empty()) throw std::runtime_error(path + ": no triangles");
  return m;
}

inline void write_obj(const Mesh& m, const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot write " + path);
  std::vector<char> buf(1 << 20);
  std::setvbuf(f, buf.data(), _IOFBF, buf.size());
  for (const auto& v : m.p) std::fprintf(f, "v %.9g %.9g %.9g\n", v[0], v[1], v[2]);
  for (const auto& t : m.t) std::fprintf(f, "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
  if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + path);
}

namespace detail {
inline V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline V3 madd(const V3& a, double s, const V3& b) { return {a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]}; }

/// Squared distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
inline double point_triangle_d2(const V3& p, const V3& a, const V3& b, const V3& c) {
  const V3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  V3 q;
  if (d1 <= 0 && d2 <= 0) {
    q = a;
  } else {
    const V3 bp = sub(p, b);
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
      q = b;
    } else {
      const double vc = d1 * d4 - d3 * d2;
      if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        q = madd(a, d1 / (d1 - d3), ab);
      } else {
        const V3 cp = sub(p, c);
        const double d5 = dot(ab, cp), d6 = dot(ac, cp);
        if (d6 >= 0 && d5 <= d6) {
          q = c;
        } else {
          const double vb = d5 * d2 - d1 * d6;
          if (vb <= 0 && d2 >= 0 && d6 <= 0) {
            q = madd(a, d2 / (d2 - d6), ac);
          } else {
            const double va = d3 * d6 - d5 * d4;
            if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
              q = madd(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), sub(c, b));
            } else {
              const double denom = 1.0 / (va + vb + vc);
              const double v = vb * denom, w = vc * denom;
              q = madd(madd(a, v, ab), w, ac);
            }
          }
        }
      }
    }
  }
  const V3 d = sub(p, q);
  return dot(d, d);
}
}  // namespace detail

/// Closest-point BVH over a triangle mesh (median split on the longest axis).
class DistanceBvh {
 public:
  explicit DistanceBvh(const Mesh& m) : m_(m) {
    const size_t n = m.t.size();
    order_.resize(n);
    cent_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      order_[i] = static_cast<uint32_t>(i);
      const auto& t = m.t[i];
      for (int k = 0; k < 3; ++k) cent_[i][k] = (m.p[t[0]][k] + m.p[t[1]][k] + m.p[t[2]][k]) / 3;
    }
    nodes_.reserve(2 * n / kLeaf + 2);
    build(0, static_cast<uint32_t>(n));
    cent_.clear();
    cent_.shrink_to_fit();
  }

  /// Squared distance from p to the mesh.
  double d2(const V3& p) const {
    double best = std::numeric_limits<double>::infinity();
    uint32_t stack[128];
    int sp = 0;
    stack[sp++] = 0;
    while (sp) {
      const Node& nd = nodes_[stack[--sp]];
      if (box_d2(nd, p) >= best) continue;
      if (nd.count) {
        for (uint32_t i = nd.first; i < nd.first + nd.count; ++i) {
          const auto& t = m_.t[order_[i]];
          best = std::min(best, detail::point_triangle_d2(p, m_.p[t[0]], m_.p[t[1]], m_.p[t[2]]));
        }
      } else {
        const uint32_t l = nd.first, r = nd.right;
        const double dl = box_d2(nodes_[l], p), dr = box_d2(nodes_[r], p);
        if (dl < dr) {
          stack[sp++] = r;
          stack[sp++] = l;
        } else {
          stack[sp++] = l;
          stack[sp++] = r;
        }
      }
    }
    return best;
  }

 private:
  static constexpr uint32_t kLeaf = 4;
  struct Node {
    float lo[3], hi[3];
    uint32_t first, count, right;
  };
  static double box_d2(const Node& nd, const V3& p) {
    double s = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = p[k] < nd.lo[k] ? nd.lo[k] - p[k] : p[k] > nd.hi[k] ? p[k] - nd.hi[k] : 0.0;
      s += d * d;
    }
    return s;
  }
  uint32_t build(uint32_t begin, uint32_t end) {
    const uint32_t id = static_cast<uint32_t>(nodes_.size());
    nodes_.push_back({});
    Node nd{};
    for (int k = 0; k < 3; ++k) {
      nd.lo[k] = std::numeric_limits<float>::max();
      nd.hi[k] = -std::numeric_limits<float>::max();
    }
    for (uint32_t i = begin; i < end; ++i)
      for (uint32_t v : m_.t[order_[i]])
        for (int k = 0; k < 3; ++k) {
          // round outward so the float box contains the double triangle
          nd.lo[k] = std::min(nd.lo[k], std::nextafter(static_cast<float>(m_.p[v][k]), -INFINITY));
          nd.hi[k] = std::max(nd.hi[k], std::nextafter(static_cast<float>(m_.p[v][k]), INFINITY));
        }
    if (end - begin <= kLeaf) {
      nd.first = begin;
      nd.count = end - begin;
      nodes_[id] = nd;
      return id;
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (nd.hi[k] - nd.lo[k] > nd.hi[axis] - nd.lo[axis]) axis = k;
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](uint32_t a, uint32_t b) { return cent_[a][axis] < cent_[b][axis]; });
    nd.count = 0;
    nodes_[id] = nd;
    const uint32_t l = build(begin, mid);
    const uint32_t r = build(mid, end);
    nodes_[id].first = l;
    nodes_[id].right = r;
    return id;
  }
  const Mesh& m_;
  std::vector<Node> nodes_;
  std::vector<uint32_t> order_;
  std::vector<V3> cent_;
};

/// Query points on mesh `m`: its vertices (every k-th one above `max_vertices`) plus `samples`
/// area-weighted random points (fixed seed, so runs are repeatable).
inline std::vector<V3> surface_points(const Mesh& m, size_t samples, size_t max_vertices, uint64_t seed) {
  std::vector<V3> pts;
  const size_t stride = m.p.size() > max_vertices ? (m.p.size() + max_vertices - 1) / max_vertices : 1;
  for (size_t i = 0; i < m.p.size(); i += stride) pts.push_back(m.p[i]);
  std::vector<double> cdf(m.t.size());
  double acc = 0;
  for (size_t i = 0; i < m.t.size(); ++i) {
    const auto& t = m.t[i];
    const V3 n = detail::cross(detail::sub(m.p[t[1]], m.p[t[0]]), detail::sub(m.p[t[2]], m.p[t[0]]));
    acc += std::sqrt(detail::dot(n, n));
    cdf[i] = acc;
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  for (size_t s = 0; s < samples && acc > 0; ++s) {
    const size_t i = std::lower_bound(cdf.begin(), cdf.end(), u(rng) * acc) - cdf.begin();
    const auto& t = m.t[std::min(i, m.t.size() - 1)];
    double a = u(rng), b = u(rng);
    if (a + b > 1) {
      a = 1 - a;
      b = 1 - b;
    }
    const V3 e1 = detail::sub(m.p[t[1]], m.p[t[0]]), e2 = detail::sub(m.p[t[2]], m.p[t[0]]);
    pts.push_back(detail::madd(detail::madd(m.p[t[0]], a, e1), b, e2));
  }
  return pts;
}

struct OneSided {
  double max = 0, mean = 0, rms = 0;
  size_t points = 0;
};

inline OneSided one_sided(const std::vector<V3>& pts, const DistanceBvh& bvh) {
  struct Acc {
    double mx = 0, sum = 0, sum2 = 0;
  };
  const Acc r = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, pts.size(), 1024), Acc{},
      [&](const tbb::blocked_range<size_t>& rg, Acc a) {
        for (size_t i = rg.begin(); i != rg.end(); ++i) {
          const double d2 = bvh.d2(pts[i]);
          const double d = std::sqrt(d2);
          a.mx = std::max(a.mx, d);
          a.sum += d;
          a.sum2 += d2;
        }
        return a;
      },
      [](Acc a, const Acc& b) {
        a.mx = std::max(a.mx, b.mx);
        a.sum += b.sum;
        a.sum2 += b.sum2;
        return a;
      });
  OneSided o;
  o.points = pts.size();
  o.max = r.mx;
  o.mean = pts.empty() ? 0 : r.sum / pts.size();
  o.rms = pts.empty() ? 0 : std::sqrt(r.sum2 / pts.size());
  return o;
}

struct Hausdorff {
  OneSided ab, ba;  // a -> b: points of a, distances to b
  double two_sided() const { return std::max(ab.max, ba.max); }
};

/// Two-sided Hausdorff distance between a and b, in the meshes' units.
inline Hausdorff hausdorff(const Mesh& a, const Mesh& b, size_t samples = 200000, size_t max_vertices = 2000000) {
  Hausdorff h;
  {
    const DistanceBvh bb(b);
    h.ab = one_sided(surface_points(a, samples, max_vertices, 1), bb);
  }
  {
    const DistanceBvh ba(a);
    h.ba = one_sided(surface_points(b, samples, max_vertices, 2), ba);
  }
  return h;
}

inline std::string fmt(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

inline std::string hausdorff_json(const Hausdorff& h) {
  return "{\"hausdorff\": " + fmt(h.two_sided()) + ", \"hausdorff_ab\": " + fmt(h.ab.max) +
         ", \"hausdorff_ba\": " + fmt(h.ba.max) + ", \"mean_ab\": " + fmt(h.ab.mean) +
         ", \"mean_ba\": " + fmt(h.ba.mean) + ", \"rms_ab\": " + fmt(h.ab.rms) + ", \"rms_ba\": " + fmt(h.ba.rms) +
         ", \"points_ab\": " + std::to_string(h.ab.points) + ", \"points_ba\": " + std::to_string(h.ba.points) + "}";
}

}  // namespace bench
