// `pic`: the command-line tool, thin over the library. Every failure becomes one line on
// stderr and a non-zero exit: 1 usage, 2 bad input or I/O, 3 internal error.
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <optional>
#include <vector>

#include "pic/pic.h"
#include "pic/primitives.h"
#include "pic/scad.h"
#ifdef PIC_HAS_RENDER
#include "pic/render.h"
#endif
#ifdef PIC_HAS_VIEWER
#include "pic/viewer.h"
#endif

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

bool stderr_is_tty() { return ::isatty(2) != 0; }
void progress(const std::string& msg) {
  if (stderr_is_tty()) std::cerr << "pic: " << msg << "\n";
}

std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// Minimal JSON object writer: keys in insertion order.
class Json {
 public:
  Json& add(const std::string& k, double v) { return raw(k, num(v)); }
  Json& add(const std::string& k, size_t v) { return raw(k, std::to_string(v)); }
  Json& add(const std::string& k, int v) { return raw(k, std::to_string(v)); }
  Json& add(const std::string& k, bool v) { return raw(k, v ? "true" : "false"); }
  Json& add(const std::string& k, const std::string& v) { return raw(k, quote(v)); }
  Json& add(const std::string& k, const char* v) { return raw(k, quote(v)); }
  Json& raw(const std::string& k, const std::string& v) {
    s_ += (s_.empty() ? "" : ", ") + quote(k) + ": " + v;
    return *this;
  }
  std::string str() const { return "{" + s_ + "}"; }
  static std::string quote(const std::string& v) {
    std::string o = "\"";
    for (char c : v) {
      if (c == '"' || c == '\\') o += '\\';
      if (c == '\n') {
        o += "\\n";
        continue;
      }
      o += c;
    }
    return o + "\"";
  }

 private:
  std::string s_;
};

std::string vec_json(const pic::Vec3& v) { return "[" + num(v[0]) + ", " + num(v[1]) + ", " + num(v[2]) + "]"; }

std::vector<double> parse_numbers(const std::string& s, size_t n, const std::string& what) {
  std::vector<double> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (...) {
      throw pic::InvalidInput(what + ": '" + item + "' is not a number");
    }
  }
  if (out.size() != n) throw pic::InvalidInput(what + " needs " + std::to_string(n) + " comma-separated numbers");
  for (double x : out)
    if (!std::isfinite(x)) throw pic::InvalidInput(what + " must be finite");
  return out;
}

pic::Cube parse_cube(const std::string& s) {
  const auto v = parse_numbers(s, 4, "--cube X,Y,Z,SIZE");
  if (!(v[3] > 0)) throw pic::InvalidInput("--cube SIZE must be positive");
  return pic::Cube{{v[0], v[1], v[2]}, v[3]};
}

std::string topology_json(const pic::MeshTopology& t) {
  return Json()
      .add("closed", t.closed())
      .add("manifold", t.manifold())
      .add("boundary_edges", t.boundary_edges)
      .add("nonmanifold_edges", t.nonmanifold_edges)
      .add("nonmanifold_vertices", t.nonmanifold_vertices)
      .str();
}

// Validity of a written mesh (issue 10): exact self-intersections (null with --no-check),
// non-manifold vertices and edges, components; equal positions merged as a reader sees them.
Json& add_validity(Json& j, const pic::MeshValidity& v) {
  if (v.checked) j.add("self_intersections", v.self_intersections);
  else j.raw("self_intersections", "null");
  return j.add("nonmanifold_vertices", v.nonmanifold_vertices)
      .add("nonmanifold_edges", v.nonmanifold_edges)
      .add("components", v.components);
}

std::string info_json(const pic::Octree& tree, size_t file_bytes) {
  const auto s = pic::analyze(tree);
  std::string levels = "[";
  for (size_t l = 0; l < s.levels.size(); ++l) {
    const auto& v = s.levels[l];
    levels += (l ? ", " : "") + Json()
                                    .add("level", l)
                                    .add("white", v.white)
                                    .add("black", v.black)
                                    .add("gray", v.gray)
                                    .add("internal", v.internal)
                                    .str();
  }
  levels += "]";
  Json j;
  j.add("pics", s.pics).add("nodes", s.nodes).add("depth", tree.max_depth).add("capped", s.capped);
  if (file_bytes) j.add("file_bytes", file_bytes).add("bytes_per_pic", s.pics ? double(file_bytes) / s.pics : 0.0);
  j.add("memory_bytes", s.memory_bytes)
      .raw("cube", Json().raw("origin", vec_json(tree.cube.origin)).add("size", tree.cube.size).str())
      .raw("bbox", Json().raw("min", vec_json(s.bbox_min)).raw("max", vec_json(s.bbox_max)).str())
      .raw("levels", levels);
  return j.str();
}

void print_info_table(const pic::Octree& tree, size_t file_bytes) {
  const auto s = pic::analyze(tree);
  std::printf("level     white     black      gray  internal\n");
  for (size_t l = 0; l < s.levels.size(); ++l) {
    const auto& v = s.levels[l];
    if (v.white + v.black + v.gray + v.internal == 0) continue;
    std::printf("%5zu %9zu %9zu %9zu %9zu\n", l, v.white, v.black, v.gray, v.internal);
  }
  std::printf("PICs: %zu   nodes: %zu   depth cap: %d   cells stopped by the cap: %zu\n", s.pics, s.nodes,
              tree.max_depth, s.capped);
  if (file_bytes)
    std::printf("file: %zu bytes, %.2f bytes per PIC\n", file_bytes, s.pics ? double(file_bytes) / s.pics : 0.0);
  std::printf("memory: %zu bytes (%.2f per PIC)\n", s.memory_bytes, s.pics ? double(s.memory_bytes) / s.pics : 0.0);
  std::printf("cube: origin (%g, %g, %g) size %g\n", tree.cube.origin[0], tree.cube.origin[1], tree.cube.origin[2],
              tree.cube.size);
  std::printf("bbox of vertices: (%g, %g, %g) - (%g, %g, %g)\n", s.bbox_min[0], s.bbox_min[1], s.bbox_min[2],
              s.bbox_max[0], s.bbox_max[1], s.bbox_max[2]);
}

int axis_of(const std::string& a) {
  if (a == "x") return 0;
  if (a == "y") return 1;
  if (a == "z") return 2;
  throw pic::InvalidInput("--axis must be x, y or z");
}

// Loads a .pic, or samples a mesh file with default options (so `render`/`view` take both);
// `contour_out` gets the PIC object's surface either way.
pic::Octree load_any(const std::string& path, int depth, pic::TriMesh* contour_out) {
  const auto dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".pic") {
    auto t = pic::load(path);
    if (contour_out) *contour_out = pic::contour(t);
    return t;
  }
  pic::SampleOptions o;
  o.depth = depth;
  const pic::Geometry geo = pic::read_geometry(path);
  auto t = geo.is_point_cloud() ? pic::sample(geo.points, o) : pic::sample(geo.mesh, o);
  if (contour_out) *contour_out = pic::contour(t);
  return t;
}

// True when `path` names a mesh format (written by contouring) rather than a .pic file.
bool is_mesh_path(const std::string& path) {
  const auto dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".obj" || ext == ".stl" || ext == ".ply" || ext == ".off" || ext == ".glb" || ext == ".gltf";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pic: solid modeling with points with implicit connectivity (PIC)"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Help for every subcommand");

  // sample
  auto* cmd_sample = app.add_subcommand("sample", "Sample a triangle mesh or an oriented point cloud into a PIC object");
  std::string s_in, s_out, s_cube, s_inside = "auto";
  int s_depth = 12;
  double s_error = 1e-8;
  bool s_json = false, s_serial = false;
  cmd_sample->add_option("input", s_in, "Mesh file (obj, stl, ply, off, gltf, glb) or point cloud (ply with normals, xyz)")->required();
  cmd_sample->add_option("-o,--output", s_out, "Output .pic file")->required();
  cmd_sample->add_option("--depth", s_depth, "Maximum octree level")->capture_default_str();
  cmd_sample->add_option("--error", s_error, "QEF residual threshold (root-cube units squared)")->capture_default_str();
  cmd_sample->add_option("--cube", s_cube, "Root cube X,Y,Z,SIZE (min corner, side) in input coordinates");
  cmd_sample->add_flag("--json", s_json, "Print one JSON object on stdout");
  cmd_sample->add_flag("--serial", s_serial, "Do not use threads");
  cmd_sample->add_option("--inside", s_inside,
                         "Inside/outside: auto (parity for clean closed meshes, else winding), parity, winding")
      ->capture_default_str();

  // mesh
  auto* cmd_mesh = app.add_subcommand("mesh", "Extract the surface of a PIC object");
  std::string m_in, m_out;
  bool m_json = false, m_no_split = false, m_no_check = false, m_fast = false;
  cmd_mesh->add_option("input", m_in, "Input .pic file")->required();
  cmd_mesh->add_option("-o,--output", m_out, "Output mesh (.obj, .stl, .ply, .off, .glb)")->required();
  cmd_mesh->add_flag("--json", m_json, "Print one JSON object on stdout");
  cmd_mesh->add_flag("--no-split", m_no_split,
                     "Write the dual contouring mesh as is (it may touch itself at a few edges or vertices)");
  cmd_mesh->add_flag("--no-check", m_no_check, "With --json: skip the exact self-intersection test (huge meshes)");
  cmd_mesh->add_flag("--fast", m_fast,
                     "Plain dual contouring split: no exact re-triangulation, so a few triangles may cross "
                     "(slivers folded over a neighbour, long triangles at sharp creases)");

  // info
  auto* cmd_info = app.add_subcommand("info", "Cells per level, PIC count, bytes, bounding box");
  std::string i_in;
  bool i_json = false, i_no_check = false;
  cmd_info->add_option("input", i_in, "Input .pic file")->required();
  cmd_info->add_flag("--json", i_json, "Print one JSON object on stdout");
  cmd_info->add_flag("--no-check", i_no_check, "Skip the exact self-intersection test of the contour (huge meshes)");

  // csg
  auto* cmd_csg = app.add_subcommand("csg", "Booleans on PIC objects, left to right: A union|intersect|subtract B ...");
  std::vector<std::string> c_args;
  std::string c_out, c_mesh;
  bool c_json = false, c_no_split = false, c_no_check = false;
  double c_error = 1e-8;
  int c_depth = 12;
  cmd_csg->add_option("args", c_args, "A OP B [OP C ...]; operands are .pic files or meshes")->required();
  cmd_csg->add_option("-o,--output", c_out, "Output .pic file, or a mesh (.obj, .stl, .ply, .off, .glb)")->required();
  cmd_csg->add_option("--depth", c_depth, "Sampling depth for mesh operands (one shared cube around them)")
      ->capture_default_str();
  cmd_csg->add_option("--mesh", c_mesh, "Also contour the result to this mesh file");
  cmd_csg->add_flag("--no-split", c_no_split,
                    "With --mesh: write the dual contouring mesh as is (it may touch itself at a few edges or vertices)");
  cmd_csg->add_option("--error", c_error, "QEF residual threshold for new vertices")->capture_default_str();
  cmd_csg->add_flag("--json", c_json, "Print one JSON object on stdout");
  cmd_csg->add_flag("--no-check", c_no_check, "With --mesh --json: skip the exact self-intersection test (huge meshes)");

  // eval
  auto* cmd_eval = app.add_subcommand("eval", "Evaluate an OpenSCAD model (.scad via openscad, or its .csg export)");
  std::string e_in, e_out;
  int e_depth = 12;
  double e_error = 1e-8;
  bool e_smooth = false, e_json = false, e_serial = false, e_no_split = false;
  cmd_eval->add_option("input", e_in, "OpenSCAD .scad or .csg file")->required();
  cmd_eval->add_option("-o,--output", e_out, "Output .pic, or a mesh (.stl, .obj, .ply, .off, .glb)")->required();
  cmd_eval->add_option("--depth", e_depth, "Maximum octree level")->capture_default_str();
  cmd_eval->add_option("--error", e_error, "QEF residual threshold (root-cube units squared)")->capture_default_str();
  cmd_eval->add_flag("--smooth", e_smooth,
                     "Tessellate spheres, cylinders and circles to 0.05 finest cells instead of by $fn/$fa/$fs");
  cmd_eval->add_flag("--json", e_json, "Print one JSON object on stdout");
  cmd_eval->add_flag("--serial", e_serial, "Do not use threads");
  cmd_eval->add_flag("--no-split", e_no_split, "Mesh output: write the dual contouring mesh as is");

  // prim
  auto* cmd_prim = app.add_subcommand("prim", "Sample a primitive solid: box|sphere|cylinder|cone|torus");
  std::string p_kind, p_out, p_center = "0,0,0", p_size = "1,1,1", p_axis = "z", p_cube, p_rotate;
  double p_radius = 0.5, p_height = 1, p_minor = 0.1;
  int p_segments = 128, p_depth = 12;
  double p_error = 1e-8;
  bool p_json = false;
  cmd_prim->add_option("kind", p_kind, "box, sphere, cylinder, cone or torus")->required();
  cmd_prim->add_option("-o,--output", p_out, "Output .pic file")->required();
  cmd_prim->add_option("--center", p_center, "Centre X,Y,Z")->capture_default_str();
  cmd_prim->add_option("--size", p_size, "Box side lengths SX,SY,SZ")->capture_default_str();
  cmd_prim->add_option("--radius", p_radius, "Radius (torus: ring radius)")->capture_default_str();
  cmd_prim->add_option("--minor", p_minor, "Torus tube radius")->capture_default_str();
  cmd_prim->add_option("--height", p_height, "Height of cylinder or cone")->capture_default_str();
  cmd_prim->add_option("--axis", p_axis, "Axis x|y|z")->capture_default_str();
  cmd_prim->add_option("--rotate", p_rotate, "Rotation AX,AY,AZ,DEGREES about the centre");
  cmd_prim->add_option("--segments", p_segments, "Tessellation segments around")->capture_default_str();
  cmd_prim->add_option("--depth", p_depth, "Maximum octree level")->capture_default_str();
  cmd_prim->add_option("--error", p_error, "QEF residual threshold")->capture_default_str();
  cmd_prim->add_option("--cube", p_cube, "Root cube X,Y,Z,SIZE (share it between CSG operands)");
  cmd_prim->add_flag("--json", p_json, "Print one JSON object on stdout");
  std::string p_mesh;
  cmd_prim->add_option("--mesh", p_mesh, "Also write the tessellated input mesh (same input for other tools)");

  // render
  auto* cmd_render = app.add_subcommand("render", "Render a PIC object or a mesh to PNG");
  std::string r_in, r_out, r_size = "1024,1024", r_view = "iso", r_camera;
  bool r_octree = false, r_points = false;
  int r_depth = 12;
  cmd_render->add_option("input", r_in, "A .pic file or a mesh")->required();
  cmd_render->add_option("-o,--output", r_out, "Output PNG")->required();
  cmd_render->add_flag("--octree", r_octree, "Draw the cells of gray leaves");
  cmd_render->add_flag("--points", r_points, "Draw the representative vertices");
  cmd_render->add_option("--size", r_size, "Image size W,H")->capture_default_str();
  cmd_render->add_option("--view", r_view, "iso|front|back|left|right|top|bottom")->capture_default_str();
  cmd_render->add_option("--camera", r_camera, "EX,EY,EZ,TX,TY,TZ,UX,UY,UZ (eye, target, up)");
  cmd_render->add_option("--depth", r_depth, "Sampling depth when the input is a mesh")->capture_default_str();
  bool r_crossings = false;
  cmd_render->add_flag("--crossings", r_crossings, "Draw triangles that cross another one in red (exact test)");
  double r_half_extent = 0;
  cmd_render->add_option("--half-extent", r_half_extent,
                         "Close-up: world units from the image centre to its nearer border (centred on the --camera target)");

  // view
  auto* cmd_view = app.add_subcommand("view", "Write a self-contained interactive HTML viewer");
  std::string v_in, v_out;
  int v_depth = 12;
  cmd_view->add_option("input", v_in, "A .pic file or a mesh")->required();
  cmd_view->add_option("-o,--output", v_out, "Output .html")->required();
  cmd_view->add_option("--depth", v_depth, "Sampling depth when the input is a mesh")->capture_default_str();

  // compare
  auto* cmd_cmp = app.add_subcommand("compare", "Two-sided (Hausdorff) distance between two surfaces");
  std::string k_a, k_b;
  double k_unit = 0;
  size_t k_samples = 200000;
  bool k_json = false;
  cmd_cmp->add_option("a", k_a, "A .pic file or a mesh")->required();
  cmd_cmp->add_option("b", k_b, "A .pic file or a mesh (the reference)")->required();
  cmd_cmp->add_option("--unit", k_unit, "Divide distances by this length (default: the root cube of the first .pic, else 1)");
  cmd_cmp->add_option("--samples", k_samples, "Area-weighted samples per side, besides all vertices")->capture_default_str();
  cmd_cmp->add_flag("--json", k_json, "Print one JSON object on stdout");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  try {
    if (*cmd_sample) {
      pic::SampleOptions o;
      o.depth = s_depth;
      o.error = s_error;
      o.parallel = !s_serial;
      if (!s_cube.empty()) o.cube = parse_cube(s_cube);
      const auto mode = pic::parse_inside_mode(s_inside);
      if (!mode) throw pic::InvalidInput("--inside must be auto, parity or winding");
      o.inside = *mode;
      progress("reading " + s_in);
      const pic::Geometry geo = pic::read_geometry(s_in);
      pic::SampleStats st;
      pic::Octree tree;
      if (geo.is_point_cloud()) {
        progress("sampling " + std::to_string(geo.points.positions.size()) + " points");
        tree = pic::sample(geo.points, o, &st);
      } else {
        progress("sampling " + std::to_string(geo.mesh.triangles.size()) + " triangles");
        tree = pic::sample(geo.mesh, o, &st);
      }
      pic::save(tree, s_out);
      if (s_json) {
        const pic::MeshDefects& d = st.defects;
        std::cout << Json()
                         .add("pics", st.pics)
                         .add("seconds", st.seconds)
                         .add("depth", s_depth)
                         .add("error", s_error)
                         .add("triangles_in", st.triangles_in)
                         .add("capped", st.capped)
                         .add("points_in", geo.points.positions.size())
                         .add("depth_used", st.depth)
                         .add("inside", st.classifier)
                         .raw("defects", Json()
                                             .add("boundary_edges", d.boundary_edges)
                                             .add("nonmanifold_edges", d.nonmanifold_edges)
                                             .add("inconsistent_edges", d.inconsistent_edges)
                                             .add("duplicated_faces", d.duplicated_faces)
                                             .add("degenerate_faces", d.degenerate_faces)
                                             .add("shells", d.shells)
                                             .add("overlapping_shells", d.overlapping_shells)
                                             .str())
                         .add("interior_triangles", st.interior_triangles)
                         .add("boundary_loops", st.boundary_loops)
                         .add("file_bytes", static_cast<size_t>(std::filesystem::file_size(s_out)))
                         .raw("cube", Json().raw("origin", vec_json(tree.cube.origin)).add("size", tree.cube.size).str())
                         .str()
                  << "\n";
      } else {
        std::printf("%zu PICs in %.3f s -> %s\n", st.pics, st.seconds, s_out.c_str());
      }
    } else if (*cmd_mesh) {
      const pic::Octree tree = pic::load(m_in);
      const auto t0 = Clock::now();
      pic::ContourOptions copt;
      copt.intersection_free = !m_fast;
      pic::ContourStats cst;
      pic::TriMesh mesh = pic::contour(tree, copt, &cst);
      const double secs = since(t0);
      const size_t split = m_no_split ? 0 : pic::split_nonmanifold(mesh);
      pic::write_mesh(mesh, m_out);
      const auto topo = pic::analyze_topology(mesh);
      if (m_json) {
        Json j;
        j.add("vertices", mesh.positions.size())
            .add("triangles", mesh.triangles.size())
            .add("seconds", secs)
            .add("split_vertices", split)
            .add("fans", cst.fans)
            .add("moved_vertices", cst.moved_vertices)
            .add("volume", pic::volume(mesh))
            .raw("topology", topology_json(topo));
        std::cout << add_validity(j, pic::check_validity(mesh, !m_no_check)).str() << "\n";
      } else {
        std::printf("%zu vertices, %zu triangles in %.4f s (%s) -> %s\n", mesh.positions.size(),
                    mesh.triangles.size(), secs, topo.manifold() ? "closed manifold" : topo.closed() ? "closed, NOT manifold" : "NOT closed", m_out.c_str());
      }
    } else if (*cmd_info) {
      const pic::Octree tree = pic::load(i_in);
      const size_t bytes = std::filesystem::file_size(i_in);
      if (i_json) {
        std::string j = info_json(tree, bytes);
        const pic::TriMesh contour = pic::contour(tree);
        const auto topo = pic::analyze_topology(contour);
        j.insert(j.size() - 1, ", \"contour\": " + topology_json(topo));
        // The contour's validity, also at the top level (issue 10's contract).
        Json v;
        const std::string vs = add_validity(v, pic::check_validity(contour, !i_no_check)).str();
        j.insert(j.size() - 1, ", " + vs.substr(1, vs.size() - 2));
        std::cout << j << "\n";
      } else {
        print_info_table(tree, bytes);
        const auto topo = pic::analyze_topology(pic::contour(tree));
        std::printf("contour: %s (%zu boundary edges, %zu non-manifold edges, %zu non-manifold vertices)\n",
                    topo.manifold() ? "closed manifold" : topo.closed() ? "closed, NOT manifold" : "NOT closed",
                    topo.boundary_edges, topo.nonmanifold_edges, topo.nonmanifold_vertices);
      }
    } else if (*cmd_csg) {
      if (c_args.size() < 3 || c_args.size() % 2 == 0)
        throw pic::InvalidInput("csg needs A.pic OP B.pic [OP C.pic ...]");
      const auto t0 = Clock::now();
      // Mesh operands are sampled into one cube around all of them, so the Booleans need no
      // resampling; .pic operands keep their own cube.
      std::vector<pic::TriMesh> meshes(c_args.size());
      pic::TriMesh all;
      for (size_t k = 0; k < c_args.size(); k += 2)
        if (c_args[k].size() < 4 || c_args[k].substr(c_args[k].size() - 4) != ".pic") {
          meshes[k] = pic::read_mesh(c_args[k]);
          all.positions.insert(all.positions.end(), meshes[k].positions.begin(), meshes[k].positions.end());
        }
      std::optional<pic::Cube> shared;
      if (!all.positions.empty()) shared = pic::bounding_cube(all);
      auto operand = [&](size_t k) {
        if (meshes[k].positions.empty()) return pic::load(c_args[k]);
        pic::SampleOptions so;
        so.depth = c_depth;
        so.error = c_error;
        so.cube = shared;
        progress("sampling " + c_args[k]);
        return pic::sample(meshes[k], so);
      };
      pic::Octree acc = operand(0);
      std::string ops = "[";
      pic::CsgOptions opt;
      opt.error = c_error;
      for (size_t k = 1; k + 1 < c_args.size(); k += 2) {
        const auto op = pic::parse_csg_op(c_args[k]);
        if (!op) throw pic::InvalidInput("unknown operation '" + c_args[k] + "' (union, intersect, subtract)");
        const pic::Octree b = operand(k + 1);
        pic::CsgStats st;
        progress(pic::to_string(*op) + " " + c_args[k + 1]);
        acc = pic::csg(acc, b, *op, opt, &st);
        ops += (k > 1 ? ", " : "") + Json()
                                         .add("op", pic::to_string(*op))
                                         .add("operand", c_args[k + 1])
                                         .add("seconds", st.seconds)
                                         .add("contour_a_seconds", st.contour_a_seconds)
                                         .add("contour_b_seconds", st.contour_b_seconds)
                                         .add("csg_seconds", st.csg_seconds)
                                         .add("cleanup_seconds", st.cleanup_seconds)
                                         .add("cells_visited", st.cells_visited)
                                         .add("cells_stamped", st.cells_stamped)
                                         .add("gray_pairs", st.gray_pairs)
                                         .add("forced_subdivisions", st.forced_subdivisions)
                                         .add("repaired", st.repaired)
                                         .add("stamp", static_cast<size_t>(st.stamp))
                                         .add("resampled_b", st.resampled_b)
                                         .str();
        if (!c_json)
          std::printf("%-9s %-24s %8.2f ms  %zu cells visited, %zu stamped\n", pic::to_string(*op).c_str(),
                      c_args[k + 1].c_str(), st.seconds * 1e3, st.cells_visited, st.cells_stamped);
      }
      ops += "]";
      const double secs = since(t0);
      Json j;
      const size_t pics = pic::analyze(acc).pics;
      j.add("pics", pics).add("seconds", secs).raw("ops", ops);
      if (is_mesh_path(c_out)) {
        pic::TriMesh mesh = pic::contour(acc);
        const size_t split = c_no_split ? 0 : pic::split_nonmanifold(mesh);
        pic::write_mesh(mesh, c_out);
        j.add("triangles", mesh.triangles.size()).add("split_vertices", split).add("volume", pic::volume(mesh))
            .raw("topology", topology_json(pic::analyze_topology(mesh)));
      } else {
        pic::save(acc, c_out);
      }
      if (!c_mesh.empty()) {
        pic::TriMesh mesh = pic::contour(acc);
        const size_t split = c_no_split ? 0 : pic::split_nonmanifold(mesh);
        pic::write_mesh(mesh, c_mesh);
        j.add("triangles", mesh.triangles.size()).add("split_vertices", split)
            .raw("topology", topology_json(pic::analyze_topology(mesh)));
        if (c_json) add_validity(j, pic::check_validity(mesh, !c_no_check));
      }
      if (c_json) std::cout << j.str() << "\n";
      else std::printf("%zu PICs -> %s\n", pics, c_out.c_str());
    } else if (*cmd_eval) {
      pic::EvalOptions eo;
      eo.depth = e_depth;
      eo.error = e_error;
      eo.smooth = e_smooth;
      eo.parallel = !e_serial;
      eo.progress = [](const std::string& m) { std::cerr << "pic: " << m << "\n"; };
      pic::EvalStats st;
      const pic::Octree tree = pic::eval_scad(e_in, eo, &st);
      Json j;
      j.add("seconds", st.seconds)
          .add("openscad_seconds", st.openscad_seconds)
          .add("mesh_seconds", st.mesh_seconds)
          .add("octree_seconds", st.octree_seconds)
          .add("nodes", st.nodes)
          .add("leaves", st.leaves)
          .add("leaf_triangles", st.triangles)
          .add("booleans", st.booleans)
          .add("depth", e_depth)
          .add("smooth", e_smooth)
          .add("pics", pic::analyze(tree).pics)
          .raw("cube", Json().raw("origin", vec_json(tree.cube.origin)).add("size", tree.cube.size).str());
      std::string summary;
      if (is_mesh_path(e_out)) {
        const auto t1 = Clock::now();
        pic::TriMesh mesh = pic::contour(tree);
        const size_t split = e_no_split ? 0 : pic::split_nonmanifold(mesh);
        const double csecs = since(t1);
        pic::write_mesh(mesh, e_out);
        const auto topo = pic::analyze_topology(mesh);
        j.add("contour_seconds", csecs).add("triangles", mesh.triangles.size()).add("split_vertices", split)
            .add("volume", pic::volume(mesh)).raw("topology", topology_json(topo));
        summary = std::to_string(mesh.triangles.size()) + " triangles (" +
                  (topo.manifold() ? "closed manifold" : topo.closed() ? "closed, NOT manifold" : "NOT closed") + ")";
      } else {
        pic::save(tree, e_out);
        summary = std::to_string(pic::analyze(tree).pics) + " PICs";
      }
      if (e_json) std::cout << j.str() << "\n";
      else
        std::printf("%zu leaves, %zu Booleans in %.3f s: %s -> %s\n", st.leaves, st.booleans, st.seconds,
                    summary.c_str(), e_out.c_str());
    } else if (*cmd_prim) {
      const auto c = parse_numbers(p_center, 3, "--center");
      const pic::Vec3 center{c[0], c[1], c[2]};
      pic::TriMesh mesh;
      const int axis = axis_of(p_axis);
      if (p_kind == "box") {
        const auto s = parse_numbers(p_size, 3, "--size");
        mesh = pic::make_box({center[0] - s[0] / 2, center[1] - s[1] / 2, center[2] - s[2] / 2},
                             {center[0] + s[0] / 2, center[1] + s[1] / 2, center[2] + s[2] / 2});
      } else if (p_kind == "sphere") {
        mesh = pic::make_sphere(center, p_radius, p_segments);
      } else if (p_kind == "cylinder") {
        mesh = pic::make_cylinder(center, p_radius, p_height, axis, p_segments);
      } else if (p_kind == "cone") {
        mesh = pic::make_cone(center, p_radius, p_height, axis, p_segments);
      } else if (p_kind == "torus") {
        mesh = pic::make_torus(center, p_radius, p_minor, axis, p_segments, std::max(8, p_segments / 2));
      } else {
        throw pic::InvalidInput("unknown primitive '" + p_kind + "' (box, sphere, cylinder, cone, torus)");
      }
      if (!p_rotate.empty()) {
        const auto r = parse_numbers(p_rotate, 4, "--rotate AX,AY,AZ,DEGREES");
        const auto rot = pic::rotation({r[0], r[1], r[2]}, r[3] * 3.14159265358979323846 / 180);
        mesh = pic::transformed(pic::transformed(mesh, {1, 0, 0, 0, 1, 0, 0, 0, 1}, {-center[0], -center[1], -center[2]}),
                                rot, center);
      }
      if (!p_mesh.empty()) pic::write_mesh(mesh, p_mesh);
      pic::SampleOptions o;
      o.depth = p_depth;
      o.error = p_error;
      if (!p_cube.empty()) o.cube = parse_cube(p_cube);
      pic::SampleStats st;
      const pic::Octree tree = pic::sample(mesh, o, &st);
      pic::save(tree, p_out);
      if (p_json)
        std::cout << Json().add("pics", st.pics).add("seconds", st.seconds).add("triangles_in", st.triangles_in).str() << "\n";
      else
        std::printf("%s: %zu PICs in %.3f s -> %s\n", p_kind.c_str(), st.pics, st.seconds, p_out.c_str());
    } else if (*cmd_cmp) {
      double unit = k_unit;
      auto surface = [&](const std::string& path) {
        if (path.size() > 4 && path.substr(path.size() - 4) == ".pic") {
          const pic::Octree t = pic::load(path);
          if (unit <= 0) unit = t.cube.size;
          return pic::contour(t);
        }
        return pic::read_mesh(path);
      };
      const pic::TriMesh a = surface(k_a), b = surface(k_b);
      if (unit <= 0) unit = 1;
      const pic::SurfaceDistance d = pic::surface_distance(a, b, k_samples);
      const double va = pic::volume(a), vb = pic::volume(b);
      Json j;
      j.add("hausdorff", d.hausdorff / unit)
          .add("a_to_b", d.a_to_b / unit)
          .add("b_to_a", d.b_to_a / unit)
          .add("mean_a_to_b", d.mean_a_to_b / unit)
          .add("mean_b_to_a", d.mean_b_to_a / unit)
          .add("unit", unit)
          .add("volume_a", va)
          .add("volume_b", vb)
          .add("volume_rel_diff", vb != 0 ? (va - vb) / std::abs(vb) : 0.0)
          .raw("topology_a", topology_json(pic::analyze_topology(a)));
      if (k_json) std::cout << j.str() << "\n";
      else
        std::printf("hausdorff %.3g (A->B %.3g, B->A %.3g) in units of %g; volume difference %.3g %%\n",
                    d.hausdorff / unit, d.a_to_b / unit, d.b_to_a / unit, unit,
                    vb != 0 ? 100 * (va - vb) / std::abs(vb) : 0.0);
    } else if (*cmd_render) {
#ifdef PIC_HAS_RENDER
      pic::RenderOptions ro;
      const auto wh = parse_numbers(r_size, 2, "--size W,H");
      if (wh[0] < 1 || wh[1] < 1 || wh[0] > 16384 || wh[1] > 16384) throw pic::InvalidInput("--size must be 1..16384");
      ro.width = static_cast<int>(wh[0]);
      ro.height = static_cast<int>(wh[1]);
      ro.view = r_view;
      ro.octree = r_octree;
      ro.points = r_points;
      ro.highlight_crossings = r_crossings;
      if (!r_camera.empty()) {
        const auto c = parse_numbers(r_camera, 9, "--camera");
        std::array<double, 9> cam;
        std::copy(c.begin(), c.end(), cam.begin());
        ro.camera = cam;
      }
      if (r_half_extent != 0) {
        if (!(r_half_extent > 0) || !std::isfinite(r_half_extent)) throw pic::InvalidInput("--half-extent must be > 0");
        ro.ortho_half_extent = r_half_extent;
      }
      pic::TriMesh mesh;
      const bool is_pic = r_in.size() > 4 && r_in.substr(r_in.size() - 4) == ".pic";
      if (is_pic || r_octree || r_points) {
        const pic::Octree tree = load_any(r_in, r_depth, &mesh);
        pic::write_png(pic::render(mesh, &tree, ro), r_out);
      } else {
        mesh = pic::read_mesh(r_in);
        pic::write_png(pic::render(mesh, nullptr, ro), r_out);
      }
#else
      throw std::runtime_error("this build has no renderer");
#endif
    } else if (*cmd_view) {
#ifdef PIC_HAS_VIEWER
      pic::TriMesh mesh;
      const pic::Octree tree = load_any(v_in, v_depth, &mesh);
      const bool is_pic = v_in.size() > 4 && v_in.substr(v_in.size() - 4) == ".pic";
      const std::string html = pic::view_html(mesh, &tree, info_json(tree, is_pic ? std::filesystem::file_size(v_in) : 0));
      pic::write_text(v_out, html);
#else
      throw std::runtime_error("this build has no viewer");
#endif
    }
  } catch (const pic::InvalidInput& e) {
    std::cerr << "pic: error: " << e.what() << "\n";
    return 2;
  } catch (const pic::IoError& e) {
    std::cerr << "pic: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "pic: internal error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
