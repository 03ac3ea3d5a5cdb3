// pic eval: an OpenSCAD model (.scad through openscad, or its .csg export) -> a PIC object.
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli.h"

namespace pic::cli {

namespace {
struct EvalArgs {
  std::string in, out;
  int depth = 12;
  double error = 1e-8;
  bool smooth = false, json = false, serial = false, no_split = false, raw = false;
  double simplify = kCompactSimplify;  // finest cells
};

bool is_outline_path(const std::string& p) { return extension(p) == ".svg" || extension(p) == ".dxf"; }

// A 2D model's outline to SVG or DXF, as `openscad -o out.svg` writes it.
void run_outline(const EvalArgs& a, const EvalOptions& eo) {
  EvalStats st;
  const std::optional<Outline> o = eval_outline(a.in, eo, &st);
  if (!o) throw InvalidInput(a.in + ": a 3D model: write it as .pic or as a mesh (.stl, .obj, ...)");
  write_outline(*o, a.out);
  if (a.json) {
    std::cout << Json().fields(st).add("area", area(*o)).add("rings", o->rings.size()).str() << "\n";
  } else {
    std::printf("%zu rings, area %.6g in %.3f s -> %s\n", o->rings.size(), area(*o), st.seconds, a.out.c_str());
  }
}

void run(const EvalArgs& a) {
  EvalOptions eo;
  eo.depth = a.depth;
  eo.error = a.error;
  eo.smooth = a.smooth;
  eo.parallel = !a.serial;
  eo.progress = [](const std::string& m) { std::cerr << "pic: " << m << "\n"; };
  eo.warning = [](const std::string& m) { std::cerr << "pic: warning: " << m << "\n"; };
  if (is_outline_path(a.out)) return run_outline(a, eo);
  EvalStats st;
  const Octree tree = eval_scad(a.in, eo, &st);
  Json j;
  j.fields(st)
      .add("depth", a.depth)
      .add("smooth", a.smooth)
      .add("pics", analyze(tree).pics)
      .raw("cube", cube_json(tree.cube));
  std::string summary;
  std::optional<WrittenMesh> written;
  if (is_mesh_path(a.out)) {
    ContourOptions co;
    co.split_sheets = !a.no_split;
    co.simplify = a.raw ? 0 : a.simplify;
    const ContourFile f = write_contour(tree, a.out, co);
    written = f.written;
    j.add("contour_seconds", f.seconds)
        .add("triangles", f.mesh.triangles.size())
        .add("split_vertices", f.stats.split_vertices)
        .add("simplified_away", f.stats.simplified_away)
        .add("volume", volume(f.mesh))
        .raw("topology", topology_json(f.written.topology));
    summary = std::to_string(f.mesh.triangles.size()) + " triangles (" + topology_words(f.written.topology) + ")";
  } else {
    save(tree, a.out);
    summary = std::to_string(analyze(tree).pics) + " PICs";
  }
  if (a.json) std::cout << j.str() << "\n";
  else
    std::printf("%zu leaves, %zu Booleans in %.3f s: %s -> %s\n", st.leaves, st.booleans, st.seconds, summary.c_str(),
                a.out.c_str());
  if (written) require_valid(*written);
}
}  // namespace

void add_eval(CLI::App& app) {
  auto a = std::make_shared<EvalArgs>();
  auto* c = app.add_subcommand("eval", "Evaluate an OpenSCAD model (.scad via openscad, or its .csg export)");
  c->add_option("input", a->in, "OpenSCAD .scad or .csg file")->required();
  c->add_option("-o,--output", a->out,
                 "Output .pic, or a mesh (.stl, .obj, .ply, .off, .glb); a 2D model's outline: .svg or .dxf")
      ->required();
  c->add_option("--depth", a->depth, "Maximum octree level")->capture_default_str();
  c->add_option("--error", a->error, "QEF residual threshold (root-cube units squared)")->capture_default_str();
  c->add_flag("--smooth", a->smooth,
              "Tessellate spheres, cylinders and circles to 0.05 finest cells instead of by $fn/$fa/$fs");
  c->add_flag("--json", a->json, "Print one JSON object on stdout");
  c->add_flag("--serial", a->serial, "Do not use threads");
  c->add_flag("--no-split", a->no_split, "Mesh output: write the dual contouring mesh as is");
  c->add_option("--simplify", a->simplify,
                "Mesh output: merge flat regions and straight creases, staying within about TOL finest cells of the raw contour")
      ->capture_default_str();
  c->add_flag("--raw", a->raw, "Mesh output: the contour as it is, a vertex per gray cell (no --simplify)");
  c->callback([a] { run(*a); });
}

}  // namespace pic::cli
