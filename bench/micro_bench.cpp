// Micro-benchmarks (Google Benchmark). Run: build/bench/pic_bench [--benchmark_filter=REGEX]
//   BM_QefAccumulateSolve/N      N planes added to a QEF, then solved (one gray cell's vertex)
//   BM_SampleSphere/D            corner classification + vertex placement: a 64-segment sphere
//                                sampled at depth D (counters: PICs, cells = octree nodes)
//   BM_SampleFandisk/serial|tbb  data/fandisk.obj, depth 12, error 1e-8 (paper Table 2)
//   BM_Contour/threads:T         dual contouring of the fandisk PIC object on T threads (triangles/s)
//   BM_CsgCadStep/K              step K of the CAD tool (paper Table 3): 0 = cube ∪ cylinder z,
//                                1 = − cylinder x, 2 = − cylinder y (operands pre-sampled)
//   BM_UnionOf100Spheres/K       100 pre-sampled spheres (radius 0.05, depth 9, on a 5x5x4 grid,
//                                each overlapping its neighbours) united: 0 = left to right
//                                (csg_chain), 1 = the library's CSG tree (balanced, in parallel)
//   BM_RoundToFloat32/K          rounding a contour to floats for STL/GLB, exactly checked
//                                (0 = spot, 1 = a box minus a faceted sphere; triangles/s)
//   BM_WindingQuery/near         inside/outside by the winding number of the open bunny (69k
//                                triangles) at 4096 random grid points, as the sampler decides
//                                (integer winding of bunny + caps by a ray, caps' share near
//                                them), on all threads: 0 = anywhere in its box, 1 = within 1 %
//                                of its size from its surface (queries/s)
//   BM_DipoleTreeQuery/near      the same decisions by a dipole tree of all the triangles, one
//                                query at a time
//   BM_OffsetSpot/depth:D        spot grown by 0.05 (2.6 % of its size), the octree only
//   BM_NearestAtOffset/K         nearest-point queries one after another, each hinted by the
//                                last answer, as the offset's sampler asks them: points 2.6 % of
//                                the model's size out from each triangle's centre along its
//                                normal, in the mesh's order; 0 = spot, 1 = the Stanford bunny
//                                (69k small triangles: many near-ties at that distance)
//   BM_SelfIntersections/K       the exact self-intersection test of a mesh (as an offset runs it
//                                on its input): 0 = spot, 1 = fandisk (flat faces of many
//                                coplanar triangles), 2 = the Stanford bunny
//   BM_SampleAnyInput/K          depth 12: 0 = spot (clean, parity), 1 = spot with 6 holes
//                                punched (winding), 2 = the Stanford bunny (open base, winding),
//                                3 = the bunny with its holes closed by fans (parity): the per-PIC
//                                cost of 2 against 3 is the winding path's overhead; 4 = the car
//                                shell (2,016 triangles, open windows and floor: winding), 5 = it
//                                with its holes closed by fans (parity)
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "pic/pic.h"
#include "pic/primitives.h"
#include "geometry/qef.h"
#include "octree/cell.h"
#include "geometry/mesh_distance.h"
#include "geometry/winding.h"
#include "mesh/clean.h"
#include "sample/sources.h"
#include "../apps/common/allocator_settings.h"

namespace {

const std::string kData = PIC_BENCH_DATA_DIR;

void BM_QefAccumulateSolve(benchmark::State& state) {
  const int planes = static_cast<int>(state.range(0));
  std::mt19937 rng(42);
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> u(0, 1);
  // Planes through points of a small cell around a corner (a realistic feature cell).
  std::vector<std::pair<pic::Vec3, double>> pl;
  for (int i = 0; i < planes; ++i) {
    pic::Vec3 n{g(rng), g(rng), g(rng)};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (auto& x : n) x /= len;
    const pic::Vec3 p{0.5 + 0.01 * u(rng), 0.5 + 0.01 * u(rng), 0.5 + 0.01 * u(rng)};
    pl.push_back({n, n[0] * p[0] + n[1] * p[1] + n[2] * p[2]});
  }
  const pic::Vec3 seed{0.5, 0.5, 0.5};
  for (auto _ : state) {
    pic::detail::Qef q;
    for (const auto& [n, d] : pl) q.add_plane(n, d, 1.0);
    auto s = q.solve(seed);
    benchmark::DoNotOptimize(s);
  }
  state.counters["solves/s"] = benchmark::Counter(1, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_QefAccumulateSolve)->Arg(1)->Arg(3)->Arg(8)->Arg(32);

const pic::TriMesh& fandisk() {
  static const pic::TriMesh m = pic::read_mesh(kData + "/fandisk.obj");
  return m;
}

void BM_SampleSphere(benchmark::State& state) {
  const pic::TriMesh sphere = pic::make_sphere({0.5, 0.5, 0.5}, 0.3, 64);
  pic::SampleOptions o;
  o.depth = static_cast<int>(state.range(0));
  o.cube = pic::Cube{{0, 0, 0}, 1};
  o.parallel = false;
  pic::SampleStats st;
  size_t nodes = 0;
  for (auto _ : state) {
    auto t = pic::sample(sphere, o, &st);
    nodes = t.nodes.size();
    benchmark::DoNotOptimize(t);
  }
  state.counters["PICs"] = static_cast<double>(st.pics);
  state.counters["cells"] = static_cast<double>(nodes);
  state.counters["cells/s"] = benchmark::Counter(static_cast<double>(nodes), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_SampleSphere)->DenseRange(6, 12, 2)->Unit(benchmark::kMillisecond);

void BM_SampleFandisk(benchmark::State& state) {
  const pic::TriMesh& m = fandisk();
  pic::SampleOptions o;
  o.depth = 12;
  o.error = 1e-8;
  o.parallel = state.range(0) != 0;
  pic::SampleStats st;
  for (auto _ : state) {
    auto t = pic::sample(m, o, &st);
    benchmark::DoNotOptimize(t);
  }
  state.SetLabel(o.parallel ? "tbb" : "serial");
  state.counters["PICs"] = static_cast<double>(st.pics);
  state.counters["triangles_in"] = static_cast<double>(st.triangles_in);
}
BENCHMARK(BM_SampleFandisk)->ArgName("parallel")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// The whole contour as `pic mesh` computes it (sheets split), of the default tree of a bundled
// model: args threads, and 0 = dual contouring's plain split, 1 = the intersection-free
// construction (the issue asks for the construction within 1.3x of the plain split).
void contour_bench(benchmark::State& state, const pic::Octree& t, const char* name) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(state.range(0)));
  pic::ContourOptions o;
  o.intersection_free = state.range(1) != 0;
  size_t tris = 0;
  for (auto _ : state) {
    auto m = pic::contour(t, o);
    tris = m.triangles.size();
    benchmark::DoNotOptimize(m);
  }
  state.SetLabel(std::string(name) + (o.intersection_free ? " construction" : " plain"));
  state.counters["triangles"] = static_cast<double>(tris);
  state.counters["triangles/s"] = benchmark::Counter(static_cast<double>(tris), benchmark::Counter::kIsIterationInvariantRate);
}
void BM_Contour(benchmark::State& state) {
  static const pic::Octree t = pic::sample(fandisk(), pic::SampleOptions{});
  contour_bench(state, t, "fandisk");
}
BENCHMARK(BM_Contour)->ArgNames({"threads", "construct"})->ArgsProduct({{1, 2}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();
void BM_ContourSpot(benchmark::State& state) {
  static const pic::Octree t = pic::sample(pic::read_mesh(kData + "/spot.obj"), pic::SampleOptions{});
  contour_bench(state, t, "spot");
}
BENCHMARK(BM_ContourSpot)->ArgNames({"threads", "construct"})->ArgsProduct({{2}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();

struct CadScene {
  std::array<pic::Octree, 4> operands;  // cube, cylinder z, cylinder x, cylinder y
  std::array<pic::Octree, 3> before;    // the accumulated object before step k
  CadScene() {
    pic::SampleOptions o;
    o.cube = pic::Cube{{0, 0, 0}, 1};
    const pic::Vec3 c{0.5, 0.5, 0.5};
    operands[0] = pic::sample(pic::make_box({0.25, 0.25, 0.25}, {0.75, 0.75, 0.75}), o);
    operands[1] = pic::sample(pic::make_cylinder(c, 0.15, 0.8, 2, 128), o);
    operands[2] = pic::sample(pic::make_cylinder(c, 0.1, 0.8, 0, 128), o);
    operands[3] = pic::sample(pic::make_cylinder(c, 0.07, 0.8, 1, 128), o);
    before[0] = operands[0];
    before[1] = pic::csg(before[0], operands[1], pic::CsgOp::Union);
    before[2] = pic::csg(before[1], operands[2], pic::CsgOp::Subtract);
  }
};

void BM_CsgCadStep(benchmark::State& state) {
  static const CadScene scene;
  const int k = static_cast<int>(state.range(0));
  const pic::CsgOp op = k == 0 ? pic::CsgOp::Union : pic::CsgOp::Subtract;
  pic::CsgStats st;
  for (auto _ : state) {
    auto r = pic::csg(scene.before[k], scene.operands[k + 1], op, {}, &st);
    benchmark::DoNotOptimize(r);
  }
  state.SetLabel(k == 0 ? "cube+cyl_z" : k == 1 ? "-cyl_x" : "-cyl_y");
  state.counters["cells_visited"] = static_cast<double>(st.cells_visited);
  state.counters["contour_a_ms"] = st.contour_a_seconds * 1e3;
  state.counters["contour_b_ms"] = st.contour_b_seconds * 1e3;
  state.counters["csg_ms"] = st.csg_seconds * 1e3;
  state.counters["cleanup_ms"] = st.cleanup_seconds * 1e3;
}
BENCHMARK(BM_CsgCadStep)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

// Writing STL or GLB: the contour rounded to floats, with the exact search for triangle pairs
// the rounding made cross. 0 = spot's contour (curved), 1 = a box minus a 48-segment sphere
// (OpenSCAD's example004: flat faces and facets, many coplanar neighbours).
void BM_UnionOf100Spheres(benchmark::State& state) {
  static const std::vector<pic::Octree> balls = [] {
    pic::SampleOptions o;
    o.depth = 9;
    o.cube = pic::Cube{{0, 0, 0}, 1};
    std::vector<pic::Octree> out;
    for (int i = 0; i < 100; ++i)
      out.push_back(pic::sample(pic::make_sphere({0.2 + 0.08 * (i % 5), 0.2 + 0.08 * (i / 5 % 5), 0.3 + 0.08 * (i / 25)},
                                                 0.05, 32),
                                o));
    return out;
  }();
  size_t pics = 0;
  for (auto _ : state) {
    pic::Octree r;
    if (state.range(0) == 0) {
      std::vector<pic::CsgOperand> ops(balls.size());
      for (size_t i = 0; i < balls.size(); ++i) ops[i].tree = balls[i];
      r = pic::csg_chain(std::move(ops), std::vector<pic::CsgOp>(balls.size() - 1, pic::CsgOp::Union));
    } else {
      std::vector<pic::CsgTree> leaves;
      for (const pic::Octree& b : balls) leaves.push_back(pic::csg_leaf(std::make_shared<const pic::Octree>(b)));
      r = pic::evaluate(pic::csg_union(std::move(leaves)));
    }
    pics = r.vertices.size();
    benchmark::DoNotOptimize(r);
  }
  state.counters["PICs"] = double(pics);
}
BENCHMARK(BM_UnionOf100Spheres)->DenseRange(0, 1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RoundToFloat32(benchmark::State& state) {
  static const std::array<pic::TriMesh, 2> meshes = [] {
    const pic::Octree spot = pic::sample(pic::read_mesh(kData + "/spot.obj"), pic::SampleOptions{});
    pic::SampleOptions o;
    o.cube = pic::Cube{{-1.25, -1.25, -1.25}, 2.5};
    const pic::Octree box = pic::sample(pic::make_box({-0.75, -0.75, -0.75}, {0.75, 0.75, 0.75}), o);
    const pic::Octree ball = pic::sample(pic::make_sphere({0, 0, 0}, 1, 48), o);
    return std::array<pic::TriMesh, 2>{pic::contour(spot), pic::contour(pic::csg(box, ball, pic::CsgOp::Subtract))};
  }();
  const pic::TriMesh& m = meshes[size_t(state.range(0))];
  for (auto _ : state) {
    auto r = pic::round_to_float32(m);
    benchmark::DoNotOptimize(r);
  }
  state.SetLabel(state.range(0) == 0 ? "spot" : "box-sphere");
  state.counters["triangles/s"] =
      benchmark::Counter(static_cast<double>(m.triangles.size()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_RoundToFloat32)->DenseRange(0, 1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

const pic::TriMesh& mesh_of(const char* name) {
  static std::map<std::string, pic::TriMesh> meshes;
  auto it = meshes.find(name);
  if (it == meshes.end()) it = meshes.emplace(name, pic::read_mesh(kData + "/" + name)).first;
  return it->second;
}

/// Spot with 6 holes: the triangles within 3 % of its size of 6 of its vertices removed.
pic::TriMesh spot_with_holes() {
  pic::TriMesh m = mesh_of("spot.obj");
  const pic::Cube c = pic::bounding_cube(m);
  std::vector<pic::Vec3> centres;
  for (size_t k = 0; k < 6; ++k) centres.push_back(m.positions[(k * 7919) % m.positions.size()]);
  std::erase_if(m.triangles, [&](const auto& t) {
    for (const auto& x : centres) {
      const pic::Vec3& p = m.positions[t[0]];
      const double d = std::hypot(p[0] - x[0], p[1] - x[1], p[2] - x[2]);
      if (d < 0.03 * c.size) return true;
    }
    return false;
  });
  return m;
}

/// 4096 grid points in the bunny's bounding cube: anywhere in it, or within 1 % of the cube's
/// size from a vertex of the bunny.
std::vector<pic::detail::I3> query_points(bool near) {
  const pic::TriMesh& m = mesh_of("stanford-bunny.obj");
  const pic::Cube c = pic::bounding_cube(m);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1), off(-0.01, 0.01);
  std::vector<pic::detail::I3> pts(4096);
  for (auto& g : pts) {
    pic::Vec3 p{u(rng), u(rng), u(rng)};
    if (near) {
      p = pic::detail::world_to_unit(c, m.positions[rng() % m.positions.size()]);
      for (double& x : p) x = std::clamp(x + off(rng), 1e-6, 1 - 1e-6);
    }
    g = pic::detail::to_grid(p);
  }
  return pts;
}

// Inside/outside of the open bunny by its generalized winding number, as the sampler decides
// it: the integer winding number of bunny + caps by a ray, minus the caps' share near them.
void BM_WindingQuery(benchmark::State& state) {
  static const auto input = [] {
    const pic::detail::CleanMesh c = pic::detail::clean_mesh(mesh_of("stanford-bunny.obj"));
    const pic::Cube cube = pic::bounding_cube(c.mesh);
    std::vector<pic::detail::I3> grid;
    for (const auto& p : c.mesh.positions) grid.push_back(pic::detail::to_grid(pic::detail::world_to_unit(cube, p)));
    return pic::detail::winding_input(c.mesh, grid, 1.0 / 4096, nullptr);
  }();
  const std::vector<pic::detail::I3> pts = query_points(state.range(0) != 0);
  size_t inside = 0;
  for (auto _ : state) {
    inside = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, pts.size()), size_t{0},
        [&](const tbb::blocked_range<size_t>& r, size_t n) {
          for (size_t i = r.begin(); i < r.end(); ++i) n += input.source->inside(pts[i]);
          return n;
        },
        std::plus<>());
  }
  benchmark::DoNotOptimize(inside);
  state.SetLabel(state.range(0) ? "bunny, near the surface" : "bunny, anywhere in its box");
  state.counters["queries/s"] =
      benchmark::Counter(static_cast<double>(pts.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["inside"] = static_cast<double>(inside) / static_cast<double>(pts.size());
}
BENCHMARK(BM_WindingQuery)->ArgName("near")->Arg(0)->Arg(1)->UseRealTime();

// The same decisions by a dipole tree over all of the bunny's triangles (the general fast
// winding number, one query at a time): the yardstick the construction above is measured by.
void BM_DipoleTreeQuery(benchmark::State& state) {
  const pic::TriMesh& m = mesh_of("stanford-bunny.obj");
  const pic::Cube c = pic::bounding_cube(m);
  static pic::detail::DipoleTree tree;
  if (tree.empty()) {
    std::vector<pic::detail::ITri> tris;
    for (const auto& t : m.triangles) {
      pic::detail::I3 g[3];
      for (int k = 0; k < 3; ++k) g[k] = pic::detail::to_grid(pic::detail::world_to_unit(c, m.positions[t[k]]));
      tris.push_back(pic::detail::make_itri(g[0], g[1], g[2]));
    }
    tree.build_triangles(std::move(tris));
  }
  const std::vector<pic::detail::I3> pts = query_points(state.range(0) != 0);
  size_t inside = 0, i = 0;
  for (auto _ : state) {
    const pic::detail::I3& g = pts[i++ % pts.size()];
    inside += tree.inside(pic::detail::to_unit(g), &g, 0, 0.05);
  }
  benchmark::DoNotOptimize(inside);
  state.SetLabel(state.range(0) ? "bunny, near the surface" : "bunny, anywhere in its box");
  state.counters["queries/s"] = benchmark::Counter(1, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_DipoleTreeQuery)->ArgName("near")->Arg(0)->Arg(1);

/// A bundled mesh with each boundary loop closed by fans on its own vertices: the same surface
/// away from the holes, and closed, so it takes the parity path.
pic::TriMesh fan_closed(const char* name) {
  pic::detail::CleanMesh c = pic::detail::clean_mesh(mesh_of(name));
  for (const auto& t : pic::detail::cap_loops(pic::detail::boundary_chain(c.mesh))) c.mesh.triangles.push_back(t);
  return c.mesh;
}

void BM_SampleAnyInput(benchmark::State& state) {
  static const pic::TriMesh holes = spot_with_holes(), closed = fan_closed("stanford-bunny.obj"),
                            car_closed = fan_closed("car_shell.obj");
  const int k = static_cast<int>(state.range(0));
  const pic::TriMesh& m = k == 0   ? mesh_of("spot.obj")
                          : k == 1 ? holes
                          : k == 2 ? mesh_of("stanford-bunny.obj")
                          : k == 3 ? closed
                          : k == 4 ? mesh_of("car_shell.obj")
                                   : car_closed;
  pic::SampleStats st;
  double seconds = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    auto t = pic::sample(m, pic::SampleOptions{}, &st);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    benchmark::DoNotOptimize(t);
  }
  static const char* const kLabels[] = {"spot", "spot with holes", "stanford bunny", "bunny, holes fanned",
                                        "car shell", "car shell, holes fanned"};
  state.SetLabel(kLabels[k]);
  state.counters["PICs"] = static_cast<double>(st.pics);
  state.counters["ns_per_PIC"] = seconds * 1e9 / static_cast<double>(state.iterations()) / static_cast<double>(st.pics);
  state.counters["boundary_edges"] = static_cast<double>(st.defects.boundary_edges);
}
BENCHMARK(BM_SampleAnyInput)->DenseRange(0, 5)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_OffsetSpot(benchmark::State& state) {
  const pic::TriMesh& m = mesh_of("spot.obj");
  pic::SampleOptions o;
  o.depth = static_cast<int>(state.range(0));
  pic::SampleStats st;
  for (auto _ : state) {
    auto t = pic::offset(m, 0.05, o, &st);
    benchmark::DoNotOptimize(t);
  }
  state.counters["PICs"] = static_cast<double>(st.pics);
  state.counters["queries"] = static_cast<double>(st.evaluations);
}
BENCHMARK(BM_OffsetSpot)->ArgName("depth")->Arg(10)->Arg(12)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_NearestAtOffset(benchmark::State& state) {
  const pic::TriMesh& m = mesh_of(state.range(0) == 0 ? "spot.obj" : "stanford-bunny.obj");
  const double d = state.range(0) == 0 ? 0.05 : 0.004;
  const pic::detail::MeshDistance md(m);
  std::vector<pic::Vec3> at;
  for (const auto& t : m.triangles) {
    const pic::Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
    pic::Vec3 n{(b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]),
                (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]),
                (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0)) continue;
    pic::Vec3 p;
    for (int k = 0; k < 3; ++k) p[k] = (a[k] + b[k] + c[k]) / 3 + d * n[k] / len;
    at.push_back(p);
  }
  for (auto _ : state) {
    uint32_t hint = 0;
    double sum = 0;
    for (const pic::Vec3& p : at) sum += md.nearest(p, &hint).distance;
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(at.size()));
}
BENCHMARK(BM_NearestAtOffset)->DenseRange(0, 1)->Unit(benchmark::kMillisecond);

void BM_SelfIntersections(benchmark::State& state) {
  const char* names[] = {"spot.obj", "fandisk.obj", "stanford-bunny.obj"};
  const pic::TriMesh& m = mesh_of(names[state.range(0)]);
  for (auto _ : state) benchmark::DoNotOptimize(pic::self_intersecting_pairs(m).size());
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(m.triangles.size()));
}
BENCHMARK(BM_SelfIntersections)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The allocator settings of the command-line tool, so both measure the same thing.
int main(int argc, char** argv) {
  pic::app::restart_with_allocator_settings(argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
