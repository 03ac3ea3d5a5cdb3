// Randomized CSG harness: random rotated and scaled primitives and the meshes in
// data/, random operations and chains of them; each PIC result is compared with CGAL's exact
// Boolean of the operands' own contours (tests/support/exact_csg.h): component counts, the two
// one-sided distances in finest cells, volumes. Prints one line per case and the worst cases
// with their seeds; every case is replayable alone from its seed. Each result is also checked
// for validity (closed, 2-manifold, no self-intersections: check_validity).
//
//   pic_csg_fuzz [--seed S] [--cases N] [--depth D] [--top K] [--out DIR]
//   pic_csg_fuzz --case SEED [--out DIR]     one case, its meshes written to DIR
//   ... --resampled                          also the exact result sampled on the same lattice
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
#include "support/csg_cases.h"
#include "support/exact_csg.h"

namespace {

using namespace pic;

std::vector<TriMesh> g_models;  // data/ meshes normalized to the unit cube around the origin

TriMesh written(const Octree& t) {
  return contour(t);
}

struct CaseResult {
  uint64_t seed = 0;
  std::string text;  // operands and operations
  int depth = 0;
  bool skipped = false;
  std::string why;
  CsgComparison cmp;
  double pic_seconds = 0, exact_seconds = 0;
  MeshValidity validity;  // of PIC's written result (exact self-intersection test)
};

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void print_components(const TriMesh& pic_mesh, const TriMesh& exact, double cell) {
  for (const auto& [name, mesh] : {std::pair<const char*, const TriMesh*>{"pic", &pic_mesh}, {"exact", &exact}})
    for (const MeshComponent& c : mesh_components(*mesh))
      std::printf("%s component: %zu triangles, %.1f cells across, at (%.4f %.4f %.4f)\n", name, c.triangles,
                  c.extent() / cell, (c.lo[0] + c.hi[0]) / 2, (c.lo[1] + c.hi[1]) / 2, (c.lo[2] + c.hi[2]) / 2);
}

/// With --out: a case's meshes as DIR/PREFIX_NAME.obj, the operands' contours under their own
/// names, PIC's result as _pic and the exact one, when CGAL gave one, as _exact.
void write_meshes(const std::string& out_dir, const std::string& prefix,
                  const std::vector<std::pair<std::string, TriMesh>>& operands, const TriMesh& pic_mesh,
                  const std::optional<TriMesh>& exact) {
  std::filesystem::create_directories(out_dir);
  const std::string base = out_dir + "/" + prefix + "_";
  for (const auto& [name, mesh] : operands) write_mesh(mesh, base + name + ".obj");
  write_mesh(pic_mesh, base + "pic.obj");
  if (exact) write_mesh(*exact, base + "exact.obj");
}

bool g_resampled = false;  // --resampled: also compare the exact result sampled by PIC

/// The exact result itself sampled on the same lattice: how close PIC can get to it at all.
/// A CSG distance about this large is the resolution limit, one much larger is an error.
void print_resampled(const TriMesh& exact, const SampleOptions& so, double cell) {
  const CsgComparison r = compare_to_exact(written(sample(exact, so)), exact, cell);
  std::printf("exact sampled: components %zu/%zu, pic->exact %.2f, exact->pic %.2f at (%.4f %.4f %.4f), thick %.2f at "
              "(%.4f %.4f %.4f)\n",
              r.pic_components, r.exact_components, r.pic_to_exact, r.exact_to_pic, r.worst_exact[0], r.worst_exact[1],
              r.worst_exact[2], r.exact_to_pic_thick, r.worst_thick[0], r.worst_thick[1], r.worst_thick[2]);
}

CaseResult run_case(uint64_t seed, int fixed_depth, const std::string& out_dir) {
  CaseResult res;
  res.seed = seed;
  const CsgCase k = make_case(seed, fixed_depth, g_models);
  res.depth = k.depth;
  res.text = k.text;
  const std::vector<TriMesh>& inputs = k.inputs;
  const std::vector<CsgOp>& ops = k.ops;
  SampleOptions so;
  so.depth = res.depth;
  so.cube = Cube{{0, 0, 0}, 1};
  // PIC: sample each operand, combine left to right. Reference: the same on the operands' own
  // contours, exactly.
  auto t0 = Clock::now();
  std::vector<Octree> trees;
  for (const TriMesh& m : inputs) trees.push_back(sample(m, so));
  Octree acc = trees[0];
  std::vector<Octree> steps;  // the result after each operation, saved with --out
  for (size_t i = 1; i < trees.size(); ++i) {
    acc = csg(acc, trees[i], ops[i - 1]);
    if (!out_dir.empty()) steps.push_back(acc);
  }
  const TriMesh pic_mesh = written(acc);
  res.pic_seconds = since(t0);
  res.validity = check_validity(pic_mesh);
  if (!out_dir.empty()) {
    std::filesystem::create_directories(out_dir);
    const std::string base = out_dir + "/case" + std::to_string(seed) + "_";
    for (size_t i = 0; i < trees.size(); ++i) save(trees[i], base + "op" + std::to_string(i) + ".pic");
    for (size_t i = 0; i < steps.size(); ++i) save(steps[i], base + "step" + std::to_string(i + 1) + ".pic");
  }
  t0 = Clock::now();
  std::optional<TriMesh> exact = written(trees[0]);
  for (size_t i = 1; i < trees.size() && exact; ++i) exact = exact_boolean(*exact, written(trees[i]), ops[i - 1]);
  res.exact_seconds = since(t0);
  if (!out_dir.empty()) {
    std::vector<std::pair<std::string, TriMesh>> operands;
    for (size_t i = 0; i < trees.size(); ++i) operands.emplace_back("op" + std::to_string(i), written(trees[i]));
    write_meshes(out_dir, "case" + std::to_string(seed), operands, pic_mesh, exact);
  }
  if (!exact) {
    res.skipped = true;
    res.why = "CGAL refused an operand (self-intersecting or not a Surface_mesh)";
    return res;
  }
  res.cmp = compare_to_exact(pic_mesh, *exact, 1.0 / double(1 << res.depth));
  if (!out_dir.empty()) print_components(pic_mesh, *exact, 1.0 / double(1 << res.depth));
  if (g_resampled) print_resampled(*exact, so, 1.0 / double(1 << res.depth));
  return res;
}

/// Two meshes (a real pair, e.g. the Thingi10K difference pair) sampled in the cube
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
  res.validity = check_validity(pic_mesh);
  t0 = Clock::now();
  const TriMesh ca = written(ta), cb = written(tb);
  std::printf("operand contours: %zu and %zu self-intersecting pairs\n", count_self_intersections(ca),
              count_self_intersections(cb));
  const std::optional<TriMesh> exact = exact_boolean(ca, cb, op, false);
  res.exact_seconds = since(t0);
  if (!out_dir.empty()) write_meshes(out_dir, "pair", {{"a", ca}, {"b", cb}}, pic_mesh, exact);
  if (!exact) {
    res.skipped = true;
    res.why = "CGAL failed";
    return res;
  }
  const double cell = so.cube->size / double(1 << res.depth);
  res.cmp = compare_to_exact(pic_mesh, *exact, cell, 200000);
  print_components(pic_mesh, *exact, cell);
  return res;
}

/// "valid", or what makes PIC's result not a valid solid.
std::string validity_text(const MeshValidity& v) {
  if (v.valid()) return "valid";
  return "NOT VALID: " + std::to_string(v.self_intersections) + " self-intersections, " +
         std::to_string(v.nonmanifold_vertices) + " non-manifold vertices, " + std::to_string(v.nonmanifold_edges) +
         " non-manifold edges, " + std::to_string(v.boundary_edges) + " boundary edges, " +
         std::to_string(v.collinear_triangles) + " zero-area triangles";
}

void print(const CaseResult& c) {
  if (c.skipped) {
    std::printf("seed %llu depth %d: %s: skipped (%s), %s\n", (unsigned long long)c.seed, c.depth, c.text.c_str(),
                c.why.c_str(), validity_text(c.validity).c_str());
    return;
  }
  const CsgComparison& m = c.cmp;
  std::printf(
      "seed %llu depth %d: %s: components %zu/%zu, pic->exact %.2f cells at (%.4f %.4f %.4f), exact->pic %.2f cells at "
      "(%.4f %.4f %.4f), volume %+.2e, %.2f s / %.2f s, thick %.2f at (%.4f %.4f %.4f), %s\n",
      (unsigned long long)c.seed, c.depth, c.text.c_str(), m.pic_components, m.exact_components, m.pic_to_exact,
      m.worst_pic[0], m.worst_pic[1], m.worst_pic[2], m.exact_to_pic, m.worst_exact[0], m.worst_exact[1],
      m.worst_exact[2], m.volume_rel, c.pic_seconds, c.exact_seconds, m.exact_to_pic_thick, m.worst_thick[0],
      m.worst_thick[1], m.worst_thick[2], validity_text(c.validity).c_str());
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
    else if (std::strcmp(argv[i], "--resampled") == 0) g_resampled = true;
    else if (std::strcmp(argv[i], "--pair") == 0 && i + 3 < argc) {
      pair = {argv[i + 1], argv[i + 2], argv[i + 3]};
      i += 3;
    }
    else {
      std::fprintf(stderr, "usage: pic_csg_fuzz [--seed S] [--cases N] [--depth D] [--top K] [--out DIR] | --case SEED [--resampled]\n");
      return 1;
    }
  }
  g_models = load_case_models(PIC_DATA_DIR);
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
  size_t skipped = 0, invalid = 0;  // invalid: also among the skipped (PIC's result is checked first)
  for (int k = 0; k < cases; ++k) {
    all.push_back(run_case(seed + uint64_t(k), depth, out_dir));
    print(all.back());
    skipped += all.back().skipped;
    invalid += !all.back().validity.valid();
  }
  std::erase_if(all, [](const CaseResult& c) { return c.skipped; });
  size_t mismatched = 0;
  for (const auto& c : all) mismatched += c.cmp.pic_components != c.cmp.exact_components;
  std::printf("\n%zu cases (seeds %llu..%llu), %zu skipped, %zu with a component count different from the exact one, "
              "%zu not a valid solid\n",
              size_t(cases), (unsigned long long)seed, (unsigned long long)(seed + cases - 1), skipped, mismatched,
              invalid);
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
  worst("exact -> PIC distance where the exact solid is thicker than a cell",
        [](const CaseResult& c) { return c.cmp.exact_to_pic_thick; });
  return 0;
}
