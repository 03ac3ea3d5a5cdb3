// pic offset / shell / round / thicken: volumetric operations on a mesh or a .pic, written
// as a .pic or a mesh.
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli.h"
#include "pic/volume.h"

namespace pic::cli {

namespace {

struct VolumeArgs {
  std::string in, out, cube;
  int depth = 12;
  double error = 1e-8;
  double amount = 0;  // distance, thickness or radius
  bool outward = false, convex = false, concave = false, json = false, serial = false;
};

SampleOptions options_of(const VolumeArgs& a) { return sample_options(a.depth, a.error, a.serial, a.cube); }

/// The input as a mesh: a mesh file as read, a .pic through its contour.
TriMesh input_mesh(const std::string& path) {
  if (is_pic_path(path)) return contour(load(path));
  const Geometry g = read_geometry(path);
  if (g.is_point_cloud()) throw InvalidInput(path + ": a point cloud; sample it first (pic sample) and use the .pic");
  return g.mesh;
}

/// Runs `op`, writes the result (a .pic, or its mesh with the edge points on the exact
/// surface) and reports.
void finish(const VolumeArgs& a, const std::string& what,
            const std::function<Octree(SampleStats*, VolumeMesh*)>& op) {
  const auto t0 = Clock::now();
  progress(what + " " + a.in);
  SampleStats st;
  const bool to_mesh = is_mesh_path(a.out);
  VolumeMesh vm;
  const Octree tree = op(&st, to_mesh ? &vm : nullptr);
  const double seconds = since(t0) - vm.seconds;
  Json j;
  j.add("seconds", seconds)
      .add("pics", analyze(tree).pics)
      .add("capped", st.capped)
      .add("evaluations", st.evaluations)
      .raw("cube", cube_json(tree.cube));
  std::optional<WrittenMesh> written;
  if (to_mesh) {
    ContourFile f;
    f.mesh = std::move(vm.mesh);
    f.stats = vm.stats;
    write_contoured(f, a.out, vm.options);
    written = f.written;
    j.add("contour_seconds", vm.seconds)
        .add("triangles", f.mesh.triangles.size())
        .add("volume", volume(f.mesh))
        .raw("topology", topology_json(f.written.topology));
  } else {
    save(tree, a.out);
  }
  if (a.json) std::cout << j.str() << "\n";
  else std::printf("%zu PICs in %.3f s -> %s\n", analyze(tree).pics, seconds, a.out.c_str());
  if (written) require_valid(*written);
}

CLI::App* add_common(CLI::App& app, const char* name, const char* help, std::shared_ptr<VolumeArgs> a) {
  auto* c = app.add_subcommand(name, help);
  c->add_option("input", a->in, "A mesh (obj, stl, ply, off, gltf, glb) or a .pic")->required();
  c->add_option("-o,--output", a->out, "Output .pic, or a mesh (.obj, .stl, .ply, .off, .glb)")->required();
  c->add_option("--depth", a->depth, "Maximum octree level")->capture_default_str();
  c->add_option("--error", a->error, "QEF residual threshold (root-cube units squared)")->capture_default_str();
  c->add_option("--cube", a->cube, "Root cube X,Y,Z,SIZE (default: around the result)");
  c->add_flag("--json", a->json, "Print one JSON object on stdout");
  c->add_flag("--serial", a->serial, "Do not use threads");
  return c;
}

}  // namespace

void add_volume(CLI::App& app) {
  {
    auto a = std::make_shared<VolumeArgs>();
    auto* c = add_common(app, "offset", "Grow (distance > 0) or shrink (distance < 0) a solid", a);
    c->add_option("--distance", a->amount, "Offset distance in input units")->required();
    c->callback([a] { finish(*a, "offsetting", [a](SampleStats* st, VolumeMesh* m) { return offset(input_mesh(a->in), a->amount, options_of(*a), st, m); }); });
  }
  {
    auto a = std::make_shared<VolumeArgs>();
    auto* c = add_common(app, "shell", "Hollow a solid to walls of a thickness (or a skin around it)", a);
    c->add_option("--thickness", a->amount, "Wall thickness in input units")->required();
    c->add_flag("--outward", a->outward, "A skin outside the solid instead of walls inside it");
    c->callback([a] {
      finish(*a, "hollowing", [a](SampleStats* st, VolumeMesh* m) { return shell(input_mesh(a->in), a->amount, a->outward, options_of(*a), st, m); });
    });
  }
  {
    auto a = std::make_shared<VolumeArgs>();
    auto* c = add_common(app, "round", "Round a solid's convex edges (or fill its concave ones)", a);
    c->add_option("--radius", a->amount, "Rounding radius in input units")->required();
    c->add_flag("--convex", a->convex, "Round the convex edges (the default)");
    c->add_flag("--concave", a->concave, "Fill the concave edges instead (fillets)");
    c->callback([a] {
      if (a->convex && a->concave) throw InvalidInput("--convex and --concave exclude each other");
      finish(*a, "rounding", [a](SampleStats* st, VolumeMesh* m) { return round_edges(input_mesh(a->in), a->amount, !a->concave, options_of(*a), st, m); });
    });
  }
  {
    auto a = std::make_shared<VolumeArgs>();
    auto* c = add_common(app, "thicken", "Make the solid within thickness / 2 of a surface (open or closed)", a);
    c->add_option("--thickness", a->amount, "Total thickness in input units")->required();
    c->callback([a] { finish(*a, "thickening", [a](SampleStats* st, VolumeMesh* m) { return thicken(input_mesh(a->in), a->amount, options_of(*a), st, m); }); });
  }
}

}  // namespace pic::cli
