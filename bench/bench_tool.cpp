// Helpers for bench/run.sh.
//   pic_bench_tool subdivide IN.obj OUT.obj LEVELS   4-split every triangle LEVELS times at
//                                                    edge midpoints (shared, so the result
//                                                    stays closed and welded; same geometry)
//   pic_bench_tool distance A.obj B.obj [SAMPLES]    two-sided Hausdorff distance (JSON)
//   pic_bench_tool meshinfo A.obj                    vertices, triangles, signed volume (JSON)
#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <unordered_map>

#include "bench_mesh.h"

namespace {

bench::Mesh subdivide(const bench::Mesh& in) {
  bench::Mesh out;
  out.p = in.p;
  out.t.reserve(in.t.size() * 4);
  std::unordered_map<uint64_t, uint32_t> mid;
  mid.reserve(in.t.size() * 2);
  auto midpoint = [&](uint32_t a, uint32_t b) {
    const uint64_t key = a < b ? (uint64_t(a) << 32 | b) : (uint64_t(b) << 32 | a);
    auto [it, fresh] = mid.try_emplace(key, static_cast<uint32_t>(out.p.size()));
    if (fresh) {
      const auto& pa = out.p[a];
      const auto& pb = out.p[b];
      out.p.push_back({(pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2, (pa[2] + pb[2]) / 2});
    }
    return it->second;
  };
  for (const auto& t : in.t) {
    const uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
    out.t.push_back({t[0], ab, ca});
    out.t.push_back({ab, t[1], bc});
    out.t.push_back({ca, bc, t[2]});
    out.t.push_back({ab, bc, ca});
  }
  return out;
}

double signed_volume(const bench::Mesh& m) {
  double v = 0;
  for (const auto& t : m.t) {
    const auto &a = m.p[t[0]], &b = m.p[t[1]], &c = m.p[t[2]];
    v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return v / 6;
}

int usage() {
  std::cerr << "usage: pic_bench_tool subdivide IN.obj OUT.obj LEVELS\n"
               "       pic_bench_tool distance A.obj B.obj [SAMPLES]\n"
               "       pic_bench_tool meshinfo A.obj\n";
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return usage();
  const std::string cmd = argv[1];
  try {
    if (cmd == "subdivide" && argc == 5) {
      bench::Mesh m = bench::read_obj(argv[2]);
      const int levels = std::stoi(argv[4]);
      for (int l = 0; l < levels; ++l) m = subdivide(m);
      bench::write_obj(m, argv[3]);
      std::cout << "{\"vertices\": " << m.p.size() << ", \"triangles\": " << m.t.size() << "}\n";
    } else if (cmd == "distance" && (argc == 4 || argc == 5)) {
      const auto t0 = std::chrono::steady_clock::now();
      const bench::Mesh a = bench::read_obj(argv[2]);
      const bench::Mesh b = bench::read_obj(argv[3]);
      const size_t samples = argc == 5 ? std::stoul(argv[4]) : 200000;
      const auto h = bench::hausdorff(a, b, samples);
      std::string j = bench::hausdorff_json(h);
      j.insert(j.size() - 1, ", \"seconds\": " +
                                 bench::fmt(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
      std::cout << j << "\n";
    } else if (cmd == "meshinfo" && argc == 3) {
      const bench::Mesh m = bench::read_obj(argv[2]);
      std::cout << "{\"vertices\": " << m.p.size() << ", \"triangles\": " << m.t.size()
                << ", \"volume\": " << bench::fmt(signed_volume(m)) << "}\n";
    } else {
      return usage();
    }
  } catch (const std::exception& e) {
    std::cerr << "pic_bench_tool: error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
