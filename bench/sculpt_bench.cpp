// Sculpting benchmark: N subtractions of a small sphere at random points on the current surface
// of a PIC object, each written in place with pic::csg_inplace (so a stroke costs what it
// touches, not the size of the object).
//
//   pic_sculpt INPUT.pic [--strokes 1000] [--radius 0.02] [--segments 32] [--seed 1]
//              [--repick 50] [--out OUT.pic] [--mesh OUT.obj] [--check] [--centres OUT.txt]
//
// --radius is relative to the root cube. Stroke centres are vertices of the current contour,
// re-extracted every --repick strokes (the contour time is not part of a stroke). Each stroke
// samples its tool sphere into the object's cube at the object's depth (reported separately as
// tool_sample) and then subtracts it (reported as stroke). --check contours the object after
// every stroke (untimed) and reports which strokes left it open or non-manifold, and after
// how many the contour stays non-manifold even after pic::split_nonmanifold. --centres writes
// each stroke's centre and radius in the input's units (`x y z r` a line), so a peer can make
// the same strokes (bench/manifold_peer.mjs --sculpt).
// Prints one JSON object.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "pic/pic.h"
#include "pic/primitives.h"

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = q * (v.size() - 1);
  const size_t i = static_cast<size_t>(pos);
  const double f = pos - i;
  return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

std::string summary(const std::vector<double>& v, double scale) {
  double sum = 0, mx = 0;
  for (double x : v) {
    sum += x;
    mx = std::max(mx, x);
  }
  return "{\"median\": " + num(quantile(v, 0.5) * scale) + ", \"p95\": " + num(quantile(v, 0.95) * scale) +
         ", \"mean\": " + num(v.empty() ? 0 : sum / v.size() * scale) + ", \"max\": " + num(mx * scale) +
         ", \"total\": " + num(sum * scale) + "}";
}

size_t peak_rss_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<size_t>(u.ru_maxrss) * 1024;
}

int usage() {
  std::cerr << "usage: pic_sculpt INPUT.pic [--strokes N] [--radius R] [--segments S] [--seed K] [--repick M] [--check] [--centres OUT.txt] "
               "[--out OUT.pic] [--mesh OUT.obj]\n";
  return 1;
}
}  // namespace

int main(int argc, char** argv) {
  std::string input, out, mesh_out, centres_out;
  int strokes = 1000, segments = 32, repick = 50;
  bool check = false;
  double radius = 0.02;
  unsigned seed = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    try {
      if (a == "--strokes") strokes = std::stoi(next());
      else if (a == "--radius") radius = std::stod(next());
      else if (a == "--segments") segments = std::stoi(next());
      else if (a == "--seed") seed = static_cast<unsigned>(std::stoul(next()));
      else if (a == "--repick") repick = std::max(1, std::stoi(next()));
      else if (a == "--out") out = next();
      else if (a == "--mesh") mesh_out = next();
      else if (a == "--check") check = true;
      else if (a == "--centres") centres_out = next();
      else if (input.empty() && a[0] != '-') input = a;
      else return usage();
    } catch (const std::exception&) {
      return usage();
    }
  }
  if (input.empty() || strokes < 1 || !(radius > 0)) return usage();

  try {
    pic::Octree tree = pic::load(input);
    const size_t pics_before = pic::analyze(tree).pics;
    const double r = radius * tree.cube.size;
    std::mt19937_64 rng(seed);

    pic::SampleOptions so;
    so.cube = tree.cube;
    so.depth = tree.max_depth;
    so.parallel = false;  // a stroke-sized tool: threads only add overhead

    std::vector<double> stroke_s, tool_s, visited, stamped, tool_pics, contour_s, combine_s, cleanup_s;
    stroke_s.reserve(strokes);
    std::vector<pic::Vec3> candidates, centres;
    double pick_s = 0;
    int first_open = -1, first_nonmanifold = -1, open_count = 0, nonmanifold_count = 0, unsplittable_count = 0;
    size_t skipped = 0;
    const auto t_all = Clock::now();
    for (int s = 0; s < strokes; ++s) {
      if (s % repick == 0 || candidates.empty()) {
        const auto t0 = Clock::now();
        candidates = pic::unsplit_contour(tree).positions;
        pick_s += since(t0);
        if (candidates.empty()) throw std::runtime_error("the object vanished");
      }
      const pic::Vec3 c = candidates[std::uniform_int_distribution<size_t>(0, candidates.size() - 1)(rng)];
      // The tool must fit strictly inside the cube.
      bool inside = true;
      for (int k = 0; k < 3; ++k)
        if (c[k] - r <= tree.cube.origin[k] || c[k] + r >= tree.cube.origin[k] + tree.cube.size) inside = false;
      if (!inside) {
        ++skipped;
        --s;
        if (skipped > 100000) throw std::runtime_error("no stroke centre fits in the cube");
        continue;
      }
      centres.push_back(c);
      const auto t0 = Clock::now();
      pic::SampleStats sst;
      const pic::Octree tool = pic::sample(pic::make_sphere(c, r, segments), so, &sst);
      const auto t1 = Clock::now();
      pic::CsgStats st;
      pic::csg_inplace(tree, tool, pic::CsgOp::Subtract, {}, &st);
      const auto t2 = Clock::now();
      tool_s.push_back(std::chrono::duration<double>(t1 - t0).count());
      stroke_s.push_back(std::chrono::duration<double>(t2 - t1).count());
      visited.push_back(static_cast<double>(st.cells_visited));
      stamped.push_back(static_cast<double>(st.cells_stamped));
      tool_pics.push_back(static_cast<double>(sst.pics));
      contour_s.push_back(st.contour_a_seconds + st.contour_b_seconds);
      combine_s.push_back(st.csg_seconds - st.cleanup_seconds);
      cleanup_s.push_back(st.cleanup_seconds);
      if (check) {
        pic::TriMesh m = pic::unsplit_contour(tree);
        const auto topo = pic::analyze_topology(m);
        if (!topo.manifold()) {
          pic::split_nonmanifold(m);
          if (!pic::analyze_topology(m).manifold()) ++unsplittable_count;
        }
        if (!topo.closed()) {
          ++open_count;
          if (first_open < 0) first_open = s + 1;
        }
        if (!topo.manifold()) {
          ++nonmanifold_count;
          if (first_nonmanifold < 0) first_nonmanifold = s + 1;
        }
      }
    }
    const double total_s = since(t_all);
    const auto stats = pic::analyze(tree);
    std::string extra;
    {
      pic::TriMesh m = pic::unsplit_contour(tree);
      const auto topo = pic::analyze_topology(m);
      const size_t split = pic::split_nonmanifold(m);
      if (check)
        extra += ", \"check\": {\"open_strokes\": " + std::to_string(open_count) +
                 ", \"first_open\": " + std::to_string(first_open) +
                 ", \"nonmanifold_strokes\": " + std::to_string(nonmanifold_count) +
                 ", \"first_nonmanifold\": " + std::to_string(first_nonmanifold) +
                 ", \"nonmanifold_after_split_strokes\": " + std::to_string(unsplittable_count) + "}";
      extra += ", \"triangles_after\": " + std::to_string(m.triangles.size()) +
               ", \"closed_after\": " + (topo.closed() ? "true" : "false") +
               ", \"manifold_after\": " + (topo.manifold() ? "true" : "false") +
               ", \"split_vertices_after\": " + std::to_string(split) +
               ", \"manifold_after_split\": " + (pic::analyze_topology(m).manifold() ? "true" : "false");
      if (!mesh_out.empty()) pic::write_mesh(m, mesh_out);
    }
    if (!out.empty()) pic::save(tree, out);
    if (!centres_out.empty()) {
      std::ofstream f(centres_out);
      f.precision(17);
      for (const pic::Vec3& c : centres) f << c[0] << ' ' << c[1] << ' ' << c[2] << ' ' << r << '\n';
      if (!f) throw std::runtime_error("cannot write " + centres_out);
    }
    std::cout << "{\"strokes\": " << strokes << ", \"radius\": " << num(radius) << ", \"depth\": " << tree.max_depth
              << ", \"segments\": " << segments << ", \"seed\": " << seed << ", \"repick\": " << repick
              << ", \"stroke_ms\": " << summary(stroke_s, 1e3) << ", \"tool_sample_ms\": " << summary(tool_s, 1e3)
              << ", \"partial_contours_ms\": " << summary(contour_s, 1e3)
              << ", \"combine_ms\": " << summary(combine_s, 1e3) << ", \"cleanup_ms\": " << summary(cleanup_s, 1e3)
              << ", \"cells_visited\": " << summary(visited, 1) << ", \"cells_stamped\": " << summary(stamped, 1)
              << ", \"tool_pics\": " << summary(tool_pics, 1) << ", \"pick_seconds\": " << num(pick_s)
              << ", \"total_seconds\": " << num(total_s) << ", \"pics_before\": " << pics_before
              << ", \"pics_after\": " << stats.pics << ", \"nodes_after\": " << stats.nodes
              << ", \"memory_bytes_after\": " << stats.memory_bytes << extra
              << ", \"peak_rss_bytes\": " << peak_rss_bytes() << "}\n";
  } catch (const std::exception& e) {
    std::cerr << "pic_sculpt: error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
