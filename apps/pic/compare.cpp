// pic compare: the two-sided (Hausdorff) distance between two surfaces, and their volumes.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "cli.h"

namespace pic::cli {

namespace {
struct CompareArgs {
  std::string a, b;
  double unit = 0;
  size_t samples = 200000;
  std::optional<double> offset;
  bool json = false;
};

/// --offset D: how far A lies from B's surface offset by D, and the offset surface from A.
void run_offset(const TriMesh& a, const TriMesh& b, double offset, double unit, const CompareArgs& args) {
  const OffsetDistance d = offset_distance(a, b, offset, args.samples);
  Json j;
  j.add("offset", offset)
      .add("offset_worst", d.worst / unit)
      .add("offset_worst_vertex", d.worst_vertex / unit)
      .add("offset_mean", d.mean / unit)
      .raw("offset_where", vec_json(d.where))
      .add("offset_back_worst", d.back_worst / unit)
      .add("offset_back_mean", d.back_mean / unit)
      .raw("offset_back_where", vec_json(d.back_where))
      .add("offset_back_points", d.back_points)
      .add("offset_hausdorff", d.hausdorff() / unit)
      .add("unit", unit);
  if (args.json) std::cout << j.str() << "\n";
  else
    std::printf("from B's offset by %g: worst %.3g (vertices %.3g), mean %.3g; back from the offset: worst %.3g, "
                "mean %.3g; in units of %g\n",
                offset, d.worst / unit, d.worst_vertex / unit, d.mean / unit, d.back_worst / unit, d.back_mean / unit,
                unit);
}

void run(const CompareArgs& args) {
  double unit = args.unit;
  auto surface = [&](const std::string& path) {
    if (is_pic_path(path)) {
      const Octree t = load(path);
      if (unit <= 0) unit = t.cube.size;
      return unsplit_contour(t);
    }
    return read_mesh(path);
  };
  const TriMesh a = surface(args.a), b = surface(args.b);
  if (unit <= 0) unit = 1;
  if (args.offset) return run_offset(a, b, *args.offset, unit, args);
  const SurfaceDistance d = surface_distance(a, b, args.samples);
  const double va = volume(a), vb = volume(b);
  Json j;
  j.add("hausdorff", d.hausdorff / unit)
      .add("a_to_b", d.a_to_b / unit)
      .add("b_to_a", d.b_to_a / unit)
      .add("mean_a_to_b", d.mean_a_to_b / unit)
      .add("mean_b_to_a", d.mean_b_to_a / unit)
      .raw("worst_a", vec_json(d.worst_a))
      .raw("worst_b", vec_json(d.worst_b))
      .add("unit", unit)
      .add("volume_a", va)
      .add("volume_b", vb)
      .add("volume_rel_diff", vb != 0 ? (va - vb) / std::abs(vb) : 0.0)
      .raw("topology_a", topology_json(analyze_topology(a)));
  if (args.json) std::cout << j.str() << "\n";
  else
    std::printf("hausdorff %.3g (A->B %.3g, B->A %.3g) in units of %g; volume difference %.3g %%\n",
                d.hausdorff / unit, d.a_to_b / unit, d.b_to_a / unit, unit,
                vb != 0 ? 100 * (va - vb) / std::abs(vb) : 0.0);
}
}  // namespace

void add_compare(CLI::App& app) {
  auto a = std::make_shared<CompareArgs>();
  auto* c = app.add_subcommand("compare", "Two-sided (Hausdorff) distance between two surfaces");
  c->add_option("a", a->a, "A .pic file or a mesh")->required();
  c->add_option("b", a->b, "A .pic file or a mesh (the reference)")->required();
  c->add_option("--unit", a->unit, "Divide distances by this length (default: the root cube of the first .pic, else 1)");
  c->add_option("--samples", a->samples, "Area-weighted samples per side, besides all vertices")->capture_default_str();
  c->add_option("--offset", a->offset,
                 "Instead: how far A lies from B's surface offset by this distance, and back (B closed)");
  c->add_flag("--json", a->json, "Print one JSON object on stdout");
  c->callback([a] { run(*a); });
}

}  // namespace pic::cli
