// pic mesh: a PIC object -> its closed surface as a mesh file.
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli.h"

namespace pic::cli {

namespace {
struct MeshArgs {
  std::string in, out;
  bool json = false, no_split = false, no_check = false, fast = false, plain = false, fans = false;
  double simplify = 0;  // finest cells
};

void run(const MeshArgs& a) {
  const Octree tree = load(a.in);
  ContourOptions opt;
  opt.intersection_free = !a.plain;
  opt.split_sheets = !a.no_split;
  opt.fan_all = a.fans;
  opt.simplify = a.simplify;
  const ContourFile f = write_contour(tree, a.out, opt);
  const TriMesh& mesh = f.mesh;
  const MeshTopology& topo = f.written.topology;
  WrittenMesh written = f.written;
  if (a.json) {
    Json j;
    j.add("vertices", mesh.positions.size())
        .add("triangles", mesh.triangles.size())
        .add("seconds", f.seconds)
        .add("split_vertices", f.stats.split_vertices)
        .add("simplified_away", f.stats.simplified_away)
        .add("fans", f.stats.fans)
        .add("other_diagonal", f.stats.other_diagonal)
        .add("face_points", f.stats.face_points)
        .add("face_fans", f.stats.face_fans)
        .add("moved_vertices", f.stats.moved_vertices)
        .add("volume", volume(mesh))
        .raw("topology", topology_json(topo));
    const MeshValidity v = check_validity(mesh, !a.no_check);
    if (v.checked) written.self_intersections = v.self_intersections;
    std::cout << add_validity(j, v).str() << "\n";
  } else {
    std::printf("%zu vertices, %zu triangles in %.4f s (%s) -> %s\n", mesh.positions.size(), mesh.triangles.size(),
                f.seconds, topology_words(topo).c_str(), a.out.c_str());
  }
  require_valid(written);
}
}  // namespace

void add_mesh(CLI::App& app) {
  auto a = std::make_shared<MeshArgs>();
  auto* c = app.add_subcommand("mesh", "Extract the surface of a PIC object");
  c->add_option("input", a->in, "Input .pic file")->required();
  c->add_option("-o,--output", a->out, "Output mesh (.obj, .stl, .ply, .off, .glb)")->required();
  c->add_flag("--json", a->json, "Print one JSON object on stdout");
  c->add_flag("--no-split", a->no_split,
              "Write the dual contouring mesh as is (it may touch itself at a few edges or vertices)");
  c->add_flag("--no-check", a->no_check, "With --json: skip the exact self-intersection test (huge meshes)");
  c->add_flag("--fast", a->fast, "Same as the default (the intersection-free contour is as fast as the plain one)");
  c->add_flag("--plain", a->plain,
              "Dual contouring's plain split everywhere, for comparison: slivers may fold through each other");
  c->add_option("--simplify", a->simplify,
                "Merge flat regions and straight creases, staying within about TOL finest cells of the raw contour (0: the raw contour)")
      ->capture_default_str();
  c->add_flag("--fans", a->fans,
              "Every dual polygon a fan around a point of its edge, for comparison (about 2.4 times the triangles)");
  c->callback([a] { run(*a); });
}

}  // namespace pic::cli
