// pic render: a PIC object or a mesh -> PNG; pic view: -> a self-contained HTML viewer.
#include <cmath>
#include <filesystem>
#include <memory>

#include "cli.h"
#include "pic/render.h"
#include "pic/viewer.h"

namespace pic::cli {

namespace {
struct RenderArgs {
  std::string in, out, size = "1024,1024", view = "iso", camera;
  bool octree = false, points = false, crossings = false;
  int depth = 12;
  double half_extent = 0;
};

void run_render(const RenderArgs& a) {
  RenderOptions ro;
  const auto wh = parse_numbers(a.size, 2, "--size W,H");
  if (wh[0] < 1 || wh[1] < 1 || wh[0] > 16384 || wh[1] > 16384) throw InvalidInput("--size must be 1..16384");
  ro.width = static_cast<int>(wh[0]);
  ro.height = static_cast<int>(wh[1]);
  ro.view = a.view;
  ro.octree = a.octree;
  ro.points = a.points;
  ro.highlight_crossings = a.crossings;
  if (!a.camera.empty()) {
    const auto c = parse_numbers(a.camera, 9, "--camera");
    std::array<double, 9> cam;
    std::copy(c.begin(), c.end(), cam.begin());
    ro.camera = cam;
  }
  if (a.half_extent != 0) {
    if (!(a.half_extent > 0) || !std::isfinite(a.half_extent)) throw InvalidInput("--half-extent must be > 0");
    ro.ortho_half_extent = a.half_extent;
  }
  TriMesh mesh;
  if (is_pic_path(a.in) || a.octree || a.points) {
    const Octree tree = load_any(a.in, a.depth, &mesh);
    write_png(render(mesh, &tree, ro), a.out);
  } else {
    mesh = read_mesh(a.in);
    write_png(render(mesh, nullptr, ro), a.out);
  }
}

struct ViewArgs {
  std::string in, out;
  int depth = 12;
};

void run_view(const ViewArgs& a) {
  TriMesh mesh;
  const Octree tree = load_any(a.in, a.depth, &mesh);
  const size_t bytes = is_pic_path(a.in) ? std::filesystem::file_size(a.in) : 0;
  write_text(a.out, view_html(mesh, &tree, info_json(tree, bytes)));
}
}  // namespace

void add_render(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  auto* c = app.add_subcommand("render", "Render a PIC object or a mesh to PNG");
  c->add_option("input", a->in, "A .pic file or a mesh")->required();
  c->add_option("-o,--output", a->out, "Output PNG")->required();
  c->add_flag("--octree", a->octree, "Draw the cells of gray leaves");
  c->add_flag("--points", a->points, "Draw the representative vertices");
  c->add_option("--size", a->size, "Image size W,H")->capture_default_str();
  c->add_option("--view", a->view, "iso|front|back|left|right|top|bottom")->capture_default_str();
  c->add_option("--camera", a->camera, "EX,EY,EZ,TX,TY,TZ,UX,UY,UZ (eye, target, up)");
  c->add_option("--depth", a->depth, "Sampling depth when the input is a mesh")->capture_default_str();
  c->add_flag("--crossings", a->crossings, "Draw triangles that cross another one in red (exact test)");
  c->add_option("--half-extent", a->half_extent,
                "Close-up: world units from the image centre to its nearer border (centred on the --camera target)");
  c->callback([a] { run_render(*a); });
}

void add_view(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  auto* c = app.add_subcommand("view", "Write a self-contained interactive HTML viewer");
  c->add_option("input", a->in, "A .pic file or a mesh")->required();
  c->add_option("-o,--output", a->out, "Output .html")->required();
  c->add_option("--depth", a->depth, "Sampling depth when the input is a mesh")->capture_default_str();
  c->callback([a] { run_view(*a); });
}

}  // namespace pic::cli
