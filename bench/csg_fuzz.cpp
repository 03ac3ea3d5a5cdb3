// Randomized CSG harness (issue 10): random rotated and scaled primitives and the meshes in
// data/, random operations and chains of them; each PIC result is compared with CGAL's exact
// Boolean of the operands' own contours (tests/support/exact_csg.h): component counts, the two
// one-sided distances in finest cells, volumes. Prints one line per case and the worst cases
// with their seeds; every case is replayable alone from its seed.
//
//   pic_csg_fuzz [--seed S] [--cases N] [--depth D] [--top K] [--out DIR]
//   pic_csg_fuzz --case SEED [--out DIR]     one case, its meshes written to DIR
//   pic_csg_fuzz --pair A.obj OP B.obj [--depth D] [--out DIR]
//                                            two meshes sampled in the cube around both
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "pic/pic.h"
#include "pic/primitives.h"
#include "support/exact_csg.h"

namespace {

using namespace pic;

constexpr const char* kModels[] = {"cad_part", "fandisk", "spot", "suzanne", "teapot"};

/// A small deterministic generator (the same numbers on every standard library).
struct Rng {
  uint64_t s;
  uint64_t next() {
    s += 0x9E3779B97F4A7C15ull;
    uint64_t z = s;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * double(next() >> 11) * 0x1.0p-53; }
  int below(int n) { return int(next() % uint64_t(n)); }
};

std::vector<TriMesh> g_models;  // data/ meshes normalized to the unit cube around the origin

TriMesh normalized(TriMesh m) {
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const auto& p : m.positions)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  const double ext = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  for (auto& p : m.positions)
    for (int k = 0; k < 3; ++k) p[k] = (p[k] - (lo[k] + hi[k]) / 2) / ext;
  return m;
}

/// One random operand, inside [0.1, 0.9]^3: a primitive or a data mesh, scaled (not
/// uniformly), rotated about a random axis, moved.
TriMesh random_operand(Rng& r, std::string& what) {
  const int kind = r.below(6);
  TriMesh m;
  const Vec3 o{0, 0, 0};
  switch (kind) {
    case 0: m = make_box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}); what = "box"; break;
    case 1: m = make_sphere(o, 0.5, 48); what = "sphere"; break;
    case 2: m = make_cylinder(o, 0.5, 1, 2, 48); what = "cylinder"; break;
    case 3: m = make_torus(o, 0.35, 0.15, 2, 48, 24); what = "torus"; break;
    case 4: m = make_cone(o, 0.5, 1, 2, 48); what = "cone"; break;
    default: {
      const int k = r.below(int(g_models.size()));
      m = g_models[k];
      what = kModels[k];
    }
  }
  const double size = r.uniform(0.3, 0.6);
  const Vec3 scale{size * r.uniform(0.5, 1), size * r.uniform(0.5, 1), size * r.uniform(0.5, 1)};
  for (auto& p : m.positions)
    for (int k = 0; k < 3; ++k) p[k] *= scale[k];
  Vec3 axis{r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(-1, 1)};
  const double n = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]) + 1e-12;
  for (double& x : axis) x /= n;
  const Vec3 at{r.uniform(0.35, 0.65), r.uniform(0.35, 0.65), r.uniform(0.35, 0.65)};
  return transformed(std::move(m), rotation(axis, r.uniform(0, 2 * std::numbers::pi)), at);
}

TriMesh written(const Octree& t) {
  TriMesh m = contour(t);
  split_nonmanifold(m);
  return m;
}

struct CaseResult {
  uint64_t seed = 0;
  std::string text;  // operands and operations
  int depth = 0;
  bool skipped = false;
  std::string why;
  CsgComparison cmp;
  double pic_seconds = 0, exact_seconds = 0;
};

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

CaseResult run_case(uint64_t seed, int fixed_depth, const std::string& out_dir) {
  Rng r{seed * 0x2545F4914F6CDD1Dull + 1};
  CaseResult res;
  res.seed = seed;
  res.depth = fixed_depth > 0 ? fixed_depth : 7 + r.below(3);
  const int operands = 2 + (r.below(3) == 0 ? 1 + r.below(2) : 0);  // a third of the cases chain 2-3 ops
  SampleOptions so;
  so.depth = res.depth;
  so.cube = Cube{{0, 0, 0}, 1};
  std::vector<TriMesh> inputs;
  std::vector<CsgOp> ops;
  for (int i = 0; i < operands; ++i) {
    std::string what;
    inputs.push_back(random_operand(r, what));
    if (i > 0) {
      ops.push_back(CsgOp(r.below(3)));
      res.text += " " + to_string(ops.back()) + " ";
    }
    res.text += what;
  }
  // PIC: sample each operand, combine left to right. Reference: the same on the operands' own
  // contours, exactly.
  auto t0 = Clock::now();
  std::vector<Octree> trees;
  for (const TriMesh& m : inputs) trees.push_back(sample(m, so));
  Octree acc = trees[0];
  for (size_t i = 1; i < trees.size(); ++i) acc = csg(acc, trees[i], ops[i - 1]);
  const TriMesh pic_mesh = written(acc);
  res.pic_seconds = since(t0);
  t0 = Clock::now();
  std::optional<TriMesh> exact = written(trees[0]);
  for (size_t i = 1; i < trees.size() && exact; ++i) exact = exact_boolean(*exact, written(trees[i]), ops[i - 1]);
  res.exact_seconds = since(t0);
  if (!out_dir.empty()) {
    std::filesystem::create_directories(out_dir);
    const std::string base = out_dir + "/case" + std::to_string(seed);
    for (size_t i = 0; i < trees.size(); ++i) write_mesh(written(trees[i]), base + "_op" + std::to_string(i) + ".obj");
    write_mesh(pic_mesh, base + "_pic.obj");
    if (exact) write_mesh(*exact, base + "_exact.obj");
  }
  if (!exact) {
    res.skipped = true;
    res.why = "CGAL refused an operand (self-intersecting or not a Surface_mesh)";
    return res;
  }
  res.cmp = compare_to_exact(pic_mesh, *exact, 1.0 / double(1 << res.depth));
  return res;
}

/// Two meshes (a real pair, e.g. the Thingi10K difference of issue 10) sampled in the cube
/// around both. The exact reference does not check its inputs for self-intersections here:
/// CGAL then corefines what it can, and the distances far from a crossing still hold.
CaseResult run_pair(const std::string& pa, CsgOp op, const std::string& pb, int depth, const std::string& out_dir) {
  CaseResult res;
  res.depth = depth > 0 ? depth : 12;
  res.text = pa + " " + to_string(op) + " " + pb;
  const TriMesh a = read_mesh(pa), b = read_mesh(pb);
  TriMesh both = a;
  both.positions.insert(both.positions.end(), b.positions.begin(), b.positions.end());
  SampleOptions so;
  so.depth = res.depth;
  so.cube = bounding_cube(both);
  auto t0 = Clock::now();
  const Octree ta = sample(a, so), tb = sample(b, so);
  const TriMesh pic_mesh = written(csg(ta, tb, op));
  res.pic_seconds = since(t0);
  t0 = Clock::now();
  const TriMesh ca = written(ta), cb = written(tb);
  std::printf("operand contours: %zu and %zu self-intersecting pairs\n", count_self_intersections(ca),
              count_self_intersections(cb));
  const std::optional<TriMesh> exact = exact_boolean(ca, cb, op, false);
  res.exact_seconds = since(t0);
  if (!out_dir.empty()) {
    std::filesystem::create_directories(out_dir);
    write_mesh(pic_mesh, out_dir + "/pair_pic.obj");
    write_mesh(ca, out_dir + "/pair_a.obj");
    write_mesh(cb, out_dir + "/pair_b.obj");
    if (exact) write_mesh(*exact, out_dir + "/pair_exact.obj");
  }
  if (!exact) {
    res.skipped = true;
    res.why = "CGAL failed";
    return res;
  }
  res.cmp = compare_to_exact(pic_mesh, *exact, so.cube->size / double(1 << res.depth), 200000);
  return res;
}

void print(const CaseResult& c) {
  if (c.skipped) {
    std::printf("seed %llu depth %d: %s: skipped (%s)\n", (unsigned long long)c.seed, c.depth, c.text.c_str(),
                c.why.c_str());
    return;
  }
  const CsgComparison& m = c.cmp;
  std::printf(
      "seed %llu depth %d: %s: components %zu/%zu, pic->exact %.2f cells at (%.4f %.4f %.4f), exact->pic %.2f cells at "
      "(%.4f %.4f %.4f), volume %+.2e, %.2f s / %.2f s\n",
      (unsigned long long)c.seed, c.depth, c.text.c_str(), m.pic_components, m.exact_components, m.pic_to_exact,
      m.worst_pic[0], m.worst_pic[1], m.worst_pic[2], m.exact_to_pic, m.worst_exact[0], m.worst_exact[1],
      m.worst_exact[2], m.volume_rel, c.pic_seconds, c.exact_seconds);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  uint64_t seed = 1, single = 0;
  int cases = 50, depth = 0, top = 10;
  bool one = false;
  std::string out_dir;
  std::vector<std::string> pair;
  for (int i = 1; i < argc; ++i) {
    auto arg = [&](const char* name) { return std::strcmp(argv[i], name) == 0 && i + 1 < argc; };
    if (arg("--seed")) seed = std::stoull(argv[++i]);
    else if (arg("--cases")) cases = std::stoi(argv[++i]);
    else if (arg("--depth")) depth = std::stoi(argv[++i]);
    else if (arg("--top")) top = std::stoi(argv[++i]);
    else if (arg("--out")) out_dir = argv[++i];
    else if (arg("--case")) single = std::stoull(argv[++i]), one = true;
    else if (std::strcmp(argv[i], "--pair") == 0 && i + 3 < argc) {
      pair = {argv[i + 1], argv[i + 2], argv[i + 3]};
      i += 3;
    }
    else {
      std::fprintf(stderr, "usage: pic_csg_fuzz [--seed S] [--cases N] [--depth D] [--top K] [--out DIR] | --case SEED\n");
      return 1;
    }
  }
  for (const char* name : kModels) g_models.push_back(normalized(read_mesh(std::string(PIC_DATA_DIR) + "/" + name + ".obj")));
  if (!pair.empty()) {
    const std::optional<CsgOp> op = parse_csg_op(pair[1]);
    if (!op) return 1;
    print(run_pair(pair[0], *op, pair[2], depth, out_dir));
    return 0;
  }
  if (one) {
    print(run_case(single, depth, out_dir));
    return 0;
  }
  std::vector<CaseResult> all;
  size_t skipped = 0;
  for (int k = 0; k < cases; ++k) {
    all.push_back(run_case(seed + uint64_t(k), depth, out_dir));
    print(all.back());
    skipped += all.back().skipped;
  }
  std::erase_if(all, [](const CaseResult& c) { return c.skipped; });
  size_t mismatched = 0;
  for (const auto& c : all) mismatched += c.cmp.pic_components != c.cmp.exact_components;
  std::printf("\n%zu cases (seeds %llu..%llu), %zu skipped, %zu with a component count different from the exact one\n",
              size_t(cases), (unsigned long long)seed, (unsigned long long)(seed + cases - 1), skipped, mismatched);
  auto worst = [&](const char* title, auto key) {
    std::sort(all.begin(), all.end(), [&](const CaseResult& a, const CaseResult& b) { return key(a) > key(b); });
    std::printf("\nworst by %s:\n", title);
    for (int i = 0; i < top && i < int(all.size()); ++i) print(all[i]);
  };
  worst("component difference", [](const CaseResult& c) {
    return std::abs(double(c.cmp.pic_components) - double(c.cmp.exact_components)) * 1e6 + c.cmp.hausdorff;
  });
  worst("PIC -> exact distance (slits, specks)", [](const CaseResult& c) { return c.cmp.pic_to_exact; });
  worst("exact -> PIC distance (cut-off wedges)", [](const CaseResult& c) { return c.cmp.exact_to_pic; });
  return 0;
}
