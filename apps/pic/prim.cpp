// pic prim: a primitive solid (box, sphere, cylinder, cone, torus) sampled into a PIC object.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <numbers>

#include "cli.h"

namespace pic::cli {

namespace {
struct PrimArgs {
  std::string kind, out, center = "0,0,0", size = "1,1,1", axis = "z", cube, rotate, mesh;
  double radius = 0.5, height = 1, minor = 0.1, error = 1e-8;
  int segments = 128, depth = 12;
  bool json = false;
};

int axis_of(const std::string& a) {
  if (a == "x") return 0;
  if (a == "y") return 1;
  if (a == "z") return 2;
  throw InvalidInput("--axis must be x, y or z");
}

TriMesh primitive(const PrimArgs& a, const Vec3& center) {
  const int axis = axis_of(a.axis);
  if (a.kind == "box") {
    const auto s = parse_numbers(a.size, 3, "--size");
    return make_box({center[0] - s[0] / 2, center[1] - s[1] / 2, center[2] - s[2] / 2},
                    {center[0] + s[0] / 2, center[1] + s[1] / 2, center[2] + s[2] / 2});
  }
  if (a.kind == "sphere") return make_sphere(center, a.radius, a.segments);
  if (a.kind == "cylinder") return make_cylinder(center, a.radius, a.height, axis, a.segments);
  if (a.kind == "cone") return make_cone(center, a.radius, a.height, axis, a.segments);
  if (a.kind == "torus") return make_torus(center, a.radius, a.minor, axis, a.segments, std::max(8, a.segments / 2));
  throw InvalidInput("unknown primitive '" + a.kind + "' (box, sphere, cylinder, cone, torus)");
}

void run(const PrimArgs& a) {
  const auto c = parse_numbers(a.center, 3, "--center");
  const Vec3 center{c[0], c[1], c[2]};
  TriMesh mesh = primitive(a, center);
  if (!a.rotate.empty()) {
    const auto r = parse_numbers(a.rotate, 4, "--rotate AX,AY,AZ,DEGREES");
    const auto rot = rotation({r[0], r[1], r[2]}, r[3] * std::numbers::pi / 180);
    mesh = transformed(transformed(mesh, {1, 0, 0, 0, 1, 0, 0, 0, 1}, {-center[0], -center[1], -center[2]}), rot, center);
  }
  if (!a.mesh.empty()) write_mesh(mesh, a.mesh);
  SampleOptions o;
  o.depth = a.depth;
  o.error = a.error;
  if (!a.cube.empty()) o.cube = parse_cube(a.cube);
  SampleStats st;
  const Octree tree = sample(mesh, o, &st);
  save(tree, a.out);
  if (a.json)
    std::cout << Json().add("pics", st.pics).add("seconds", st.seconds).add("triangles_in", st.triangles_in).str()
              << "\n";
  else
    std::printf("%s: %zu PICs in %.3f s -> %s\n", a.kind.c_str(), st.pics, st.seconds, a.out.c_str());
}
}  // namespace

void add_prim(CLI::App& app) {
  auto a = std::make_shared<PrimArgs>();
  auto* c = app.add_subcommand("prim", "Sample a primitive solid: box|sphere|cylinder|cone|torus");
  c->add_option("kind", a->kind, "box, sphere, cylinder, cone or torus")->required();
  c->add_option("-o,--output", a->out, "Output .pic file")->required();
  c->add_option("--center", a->center, "Centre X,Y,Z")->capture_default_str();
  c->add_option("--size", a->size, "Box side lengths SX,SY,SZ")->capture_default_str();
  c->add_option("--radius", a->radius, "Radius (torus: ring radius)")->capture_default_str();
  c->add_option("--minor", a->minor, "Torus tube radius")->capture_default_str();
  c->add_option("--height", a->height, "Height of cylinder or cone")->capture_default_str();
  c->add_option("--axis", a->axis, "Axis x|y|z")->capture_default_str();
  c->add_option("--rotate", a->rotate, "Rotation AX,AY,AZ,DEGREES about the centre");
  c->add_option("--segments", a->segments, "Tessellation segments around")->capture_default_str();
  c->add_option("--depth", a->depth, "Maximum octree level")->capture_default_str();
  c->add_option("--error", a->error, "QEF residual threshold")->capture_default_str();
  c->add_option("--cube", a->cube, "Root cube X,Y,Z,SIZE (share it between CSG operands)");
  c->add_flag("--json", a->json, "Print one JSON object on stdout");
  c->add_option("--mesh", a->mesh, "Also write the tessellated input mesh (same input for other tools)");
  c->callback([a] { run(*a); });
}

}  // namespace pic::cli
