// pic sample: a mesh or an oriented point cloud -> a PIC object.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli.h"

namespace pic::cli {

namespace {
struct SampleArgs {
  std::string in, out, cube, inside = "auto";
  int depth = 12;
  double error = 1e-8;
  bool json = false, serial = false;
};

void run(const SampleArgs& a) {
  SampleOptions o = sample_options(a.depth, a.error, a.serial, a.cube);
  const auto mode = parse_inside_mode(a.inside);
  if (!mode) throw InvalidInput("--inside must be auto, parity or winding");
  o.inside = *mode;
  progress("reading " + a.in);
  const Geometry geo = read_geometry(a.in);
  SampleStats st;
  Octree tree;
  if (geo.is_point_cloud()) {
    progress("sampling " + std::to_string(geo.points.positions.size()) + " points");
    tree = sample(geo.points, o, &st);
  } else {
    progress("sampling " + std::to_string(geo.mesh.triangles.size()) + " triangles");
    tree = sample(geo.mesh, o, &st);
  }
  save(tree, a.out);
  if (a.json) {
    std::cout << Json()
                     .fields(st)
                     .add("file_bytes", static_cast<size_t>(std::filesystem::file_size(a.out)))
                     .raw("cube", cube_json(tree.cube))
                     .str()
              << "\n";
  } else {
    std::printf("%zu PICs in %.3f s -> %s\n", st.pics, st.seconds, a.out.c_str());
  }
}
}  // namespace

void add_sample(CLI::App& app) {
  auto a = std::make_shared<SampleArgs>();
  auto* c = app.add_subcommand("sample", "Sample a triangle mesh or an oriented point cloud into a PIC object");
  c->add_option("input", a->in, "Mesh file (obj, stl, ply, off, gltf, glb) or point cloud (ply with normals, xyz)")
      ->required();
  c->add_option("-o,--output", a->out, "Output .pic file")->required();
  c->add_option("--depth", a->depth, "Maximum octree level")->capture_default_str();
  c->add_option("--error", a->error, "QEF residual threshold (root-cube units squared)")->capture_default_str();
  c->add_option("--cube", a->cube, "Root cube X,Y,Z,SIZE (min corner, side) in input coordinates");
  c->add_flag("--json", a->json, "Print one JSON object on stdout");
  c->add_flag("--serial", a->serial, "Do not use threads");
  c->add_option("--inside", a->inside,
                "Inside/outside: auto (parity for clean closed meshes, else winding), parity, winding")
      ->capture_default_str();
  c->callback([a] { run(*a); });
}

}  // namespace pic::cli
