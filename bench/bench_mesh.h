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

#include "pic/pic.h"

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

struct OneSided {
  double max = 0, mean = 0;
};

struct Hausdorff {
  OneSided ab, ba;  // a -> b: points of a, distances to b
  double two_sided() const { return std::max(ab.max, ba.max); }
};

inline pic::TriMesh to_pic(const Mesh& m) {
  pic::TriMesh t;
  t.positions.assign(m.p.begin(), m.p.end());
  t.triangles = m.t;
  return t;
}

/// Two-sided Hausdorff distance between a and b, in the meshes' units (the library's
/// sampled exact point-to-triangle distance: every vertex plus `samples` points per side).
inline Hausdorff hausdorff(const Mesh& a, const Mesh& b, size_t samples = 200000) {
  const pic::SurfaceDistance d = pic::surface_distance(to_pic(a), to_pic(b), samples);
  return {{d.a_to_b, d.mean_a_to_b}, {d.b_to_a, d.mean_b_to_a}};
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
         ", \"mean_ba\": " + fmt(h.ba.mean) + "}";
}

}  // namespace bench
