// Tests of the software renderer and PNG output. Silhouette areas are checked against the
// analytic projected areas, using an explicit orthographic scale.
#include "pic/render.h"

#include <gtest/gtest.h>
#include <png.h>
#include <sys/resource.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numbers>
#include <unistd.h>

#include "support/shapes.h"

namespace pic {
namespace {

namespace fs = std::filesystem;

size_t count_pixels(const Image& img, const std::function<bool(const uint8_t*)>& pred) {
  size_t n = 0;
  for (size_t i = 0; i < img.rgb.size(); i += 3) n += pred(&img.rgb[i]);
  return n;
}
size_t foreground(const Image& img) {
  return count_pixels(img, [](const uint8_t* p) {
    return p[0] != kRenderBackground[0] || p[1] != kRenderBackground[1] || p[2] != kRenderBackground[2];
  });
}
size_t dark(const Image& img) {
  // Line pixels: darker than any face of the test scenes (the dimmest has blue ~118), not red.
  return count_pixels(img, [](const uint8_t* p) { return p[2] < 105 && p[0] < 110; });
}
size_t red(const Image& img) {
  return count_pixels(img, [](const uint8_t* p) { return p[0] > 170 && p[1] < 80 && p[2] < 80; });
}

/// Options with a known pixel scale: 512 px across 8 units, so 64 px per unit.
RenderOptions ortho(const std::string& view) {
  RenderOptions o;
  o.width = o.height = 512;
  o.view = view;
  o.ortho_half_extent = 4.0;
  o.supersample = 1;
  return o;
}

double signed_volume(const TriMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles) {
    const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
    v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
  }
  return v;
}

/// Closed and consistently oriented: every directed edge once, and its reverse once.
bool closed_oriented(const TriMesh& m) {
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
  for (const auto& [e, n] : edges) {
    auto rev = edges.find({e.second, e.first});
    if (n != 1 || rev == edges.end() || rev->second != 1) return false;
  }
  return true;
}

TEST(Shapes, ClosedOutwardAndWelded) {
  const double pi = std::numbers::pi;
  TriMesh box = make_box({0, 0, 0}, {2, 1, 3});
  EXPECT_TRUE(closed_oriented(box));
  EXPECT_NEAR(signed_volume(box), 6.0, 1e-12);
  TriMesh sphere = make_uv_sphere({1, 2, 3}, 1.5, 48, 24);
  EXPECT_TRUE(closed_oriented(sphere));
  EXPECT_NEAR(signed_volume(sphere), 4.0 / 3 * pi * 1.5 * 1.5 * 1.5, 0.03 * 14.14);
  TriMesh cyl = make_cylinder_on({0, 0, 0}, 1, 2, 64);
  EXPECT_TRUE(closed_oriented(cyl));
  EXPECT_NEAR(signed_volume(cyl), pi * 2, 0.01 * pi * 2);
  TriMesh torus = make_torus_z({0, 0, 0}, 2, 0.5, 64, 32);
  EXPECT_TRUE(closed_oriented(torus));
  EXPECT_NEAR(signed_volume(torus), 2 * pi * pi * 2 * 0.25, 0.02 * 9.87);
}

TEST(Render, BoxSilhouetteMatchesProjectedArea) {
  TriMesh box = make_box({-1, -0.5, -1.5}, {1, 0.5, 1.5});
  Image front = render(box, nullptr, ortho("front"));
  ASSERT_EQ(front.width, 512);
  ASSERT_EQ(front.rgb.size(), 512u * 512 * 3);
  EXPECT_DOUBLE_EQ(front.pixels_per_unit, 64.0);
  const double s2 = 64.0 * 64.0;
  EXPECT_NEAR(double(foreground(front)), 2 * 3 * s2, 0.02 * 2 * 3 * s2);  // x by z
  Image top = render(box, nullptr, ortho("top"));
  EXPECT_NEAR(double(foreground(top)), 2 * 1 * s2, 0.02 * 2 * 1 * s2);  // x by y
  Image right = render(box, nullptr, ortho("right"));
  EXPECT_NEAR(double(foreground(right)), 1 * 3 * s2, 0.02 * 1 * 3 * s2);  // y by z
}

TEST(Render, SphereAndTorusSilhouettes) {
  const double pi = std::numbers::pi, s2 = 64.0 * 64.0;
  TriMesh sphere = make_uv_sphere({0.3, -0.2, 0.1}, 2.0, 96, 48);
  for (const char* view : {"front", "top", "left"}) {
    Image img = render(sphere, nullptr, ortho(view));
    EXPECT_NEAR(double(foreground(img)), pi * 4 * s2, 0.03 * pi * 4 * s2) << view;
  }
  // Seen from the top, the torus is an annulus: the hole must stay background.
  TriMesh torus = make_torus_z({0, 0, 0}, 2.0, 0.75, 128, 48);
  Image img = render(torus, nullptr, ortho("top"));
  const double annulus = pi * (2.75 * 2.75 - 1.25 * 1.25);
  EXPECT_NEAR(double(foreground(img)), annulus * s2, 0.03 * annulus * s2);
  const uint8_t* centre = &img.rgb[(256 * 512 + 256) * 3];
  EXPECT_EQ(centre[0], kRenderBackground[0]);
  // Closed meshes show no back faces (drawn in a warm colour), not even at silhouettes.
  for (bool persp : {false, true}) {
    RenderOptions o;
    o.width = o.height = 400;
    o.perspective = persp;
    size_t warm = count_pixels(render(torus, nullptr, o), [](const uint8_t* p) { return p[0] > p[2]; });
    EXPECT_EQ(warm, 0u) << "perspective=" << persp;
  }
}

TEST(Render, DefaultFramingFitsTheObject) {
  for (bool persp : {false, true})
    for (const char* view : {"iso", "front", "back", "left", "right", "top", "bottom"}) {
      RenderOptions o;
      o.width = 300;
      o.height = 200;
      o.view = view;
      o.perspective = persp;
      TriMesh m = make_cylinder_on({10, 20, 30}, 1.0, 5.0, 48);
      Image img = render(m, nullptr, o);
      size_t border = 0;
      for (int x = 0; x < o.width; ++x)
        for (int y : {0, o.height - 1})
          border += img.rgb[(size_t(y) * o.width + x) * 3] != kRenderBackground[0];
      for (int y = 0; y < o.height; ++y)
        for (int x : {0, o.width - 1})
          border += img.rgb[(size_t(y) * o.width + x) * 3] != kRenderBackground[0];
      EXPECT_EQ(border, 0u) << view << " perspective=" << persp;
      EXPECT_GT(foreground(img), size_t(0.05 * o.width * o.height)) << view;
    }
}

TEST(Render, FlatShadingDistinguishesFaces) {
  // Three faces of the box are visible in the iso view; flat shading gives each its colour.
  TriMesh box = make_box({0, 0, 0}, {1, 1, 1});
  RenderOptions o;
  o.width = o.height = 200;
  o.supersample = 1;
  Image img = render(box, nullptr, o);
  std::map<std::array<uint8_t, 3>, size_t> colours;
  for (size_t i = 0; i < img.rgb.size(); i += 3) ++colours[{img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]}];
  size_t big = 0;
  for (const auto& [c, n] : colours) big += n > 2000 && c != kRenderBackground;
  EXPECT_EQ(big, 3u);
}

TEST(Render, CrossingTrianglesAreHighlighted) {
  // Two boxes in one mesh cross along a loop; a single box crosses nothing.
  const TriMesh two = joined(make_box({0, 0, 0}, {1, 1, 1}), make_box({0.5, 0.5, 0.5}, {1.5, 1.5, 1.5}));
  RenderOptions o = ortho("iso");
  EXPECT_EQ(red(render(two, nullptr, o)), 0u);  // off by default
  o.highlight_crossings = true;
  EXPECT_GT(red(render(two, nullptr, o)), 1000u);
  EXPECT_EQ(red(render(make_box({0, 0, 0}, {1, 1, 1}), nullptr, o)), 0u);
}

/// A hand-built octree over the cube [0,2]^3: the root's four lower children (z < 1) are
/// gray with a vertex in the cell centre, the upper four white.
Octree make_tree() {
  Octree t;
  t.cube = {{0, 0, 0}, 2.0};
  t.max_depth = 1;
  t.nodes.assign(9, Node{});
  t.nodes[0].kind = CellKind::Internal;
  t.nodes[0].index = 1;
  for (int c = 0; c < 8; ++c) {
    Node& n = t.nodes[1 + c];
    if (c < 4) {
      n.kind = CellKind::Gray;
      n.index = uint32_t(t.vertices.size());
      n.signs = 0xF0 ^ 0xFF;  // lower corners inside
      t.vertices.push_back({0.5f, 0.5f, 0.5f});
    } else {
      n.kind = CellKind::White;
    }
  }
  return t;
}

TEST(Render, OctreeEdgesAndPointsAreDrawn) {
  // The slab the gray cells describe: z in [0, 0.5] over [0,2]^2.
  TriMesh slab = make_box({0.02, 0.02, 0.02}, {1.98, 1.98, 0.5});
  Octree tree = make_tree();
  RenderOptions o;
  o.width = o.height = 256;
  Image plain = render(slab, &tree, o);
  EXPECT_EQ(dark(plain), 0u);
  EXPECT_EQ(red(plain), 0u);

  o.octree = true;
  Image cells = render(slab, &tree, o);
  EXPECT_GT(dark(cells), 500u);
  EXPECT_EQ(red(cells), 0u);

  o.octree = false;
  o.points = true;
  Image points = render(slab, &tree, o);
  EXPECT_EQ(dark(points), 0u);
  EXPECT_GT(red(points), 4u);  // the visible vertices (z = 0.5, on the slab's top)

  // Without a tree, points marks the mesh vertices; octree draws nothing.
  o.octree = true;
  Image mesh_points = render(slab, nullptr, o);
  EXPECT_EQ(dark(mesh_points), 0u);
  EXPECT_GT(red(mesh_points), 4u);
}

TEST(Render, HiddenOctreeEdgesAreNotDrawn) {
  // A big box in front (seen from the front) hides the cells behind it entirely.
  Octree tree = make_tree();
  TriMesh wall = make_box({-2, -3, -2}, {4, -2.5, 4});
  RenderOptions o = ortho("front");
  o.octree = true;
  o.ortho_half_extent = 2.5;
  o.camera = std::array<double, 9>{1, -10, 1, 1, 0, 1, 0, 0, 1};
  Image img = render(wall, &tree, o);
  EXPECT_EQ(dark(img), 0u);
}

TEST(Render, RejectsBadOptions) {
  TriMesh box = make_box({0, 0, 0}, {1, 1, 1});
  RenderOptions o;
  o.view = "sideways";
  EXPECT_THROW(render(box, nullptr, o), InvalidInput);
  o = {};
  o.width = 0;
  EXPECT_THROW(render(box, nullptr, o), InvalidInput);
  o = {};
  o.camera = std::array<double, 9>{0, 0, 5, 0, 0, 0, 0, 0, 1};  // up parallel to the view
  EXPECT_THROW(render(box, nullptr, o), InvalidInput);
  TriMesh bad = box;
  bad.triangles.push_back({0, 1, 99});
  EXPECT_THROW(render(bad, nullptr, RenderOptions{}), InvalidInput);
}

TEST(Render, EmptyMeshGivesBackground) {
  RenderOptions o;
  o.width = o.height = 64;
  Image img = render(TriMesh{}, nullptr, o);
  EXPECT_EQ(foreground(img), 0u);
}

TEST(Render, MillionTrianglesIsFast) {
  TriMesh torus = make_torus_z({0, 0, 0}, 2.0, 0.7, 1000, 500);  // 1,000,000 triangles
  ASSERT_EQ(torus.triangles.size(), 1000000u);
  RenderOptions o;  // 1024 x 1024, 2x2 supersampling
  auto t0 = std::chrono::steady_clock::now();
  Image img = render(torus, nullptr, o);
  double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("1M triangles at 1024x1024: %.2f s\n", s);
  EXPECT_GT(foreground(img), 100000u);
#ifdef NDEBUG
  EXPECT_LT(s, 5.0);  // typically well under a second; generous for a loaded machine
#endif
}

class TempDir {
 public:
  TempDir() {
    std::string templ = (fs::temp_directory_path() / "pic-render-XXXXXX").string();
    if (!mkdtemp(templ.data())) throw std::runtime_error("mkdtemp failed");
    path_ = templ;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

Image read_png(const fs::path& path) {
  png_image pi{};
  pi.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&pi, path.c_str())) return {};
  pi.format = PNG_FORMAT_RGB;
  Image img;
  img.width = int(pi.width);
  img.height = int(pi.height);
  img.rgb.resize(PNG_IMAGE_SIZE(pi));
  if (!png_image_finish_read(&pi, nullptr, img.rgb.data(), 0, nullptr)) return {};
  return img;
}

TEST(WritePng, RoundTrips) {
  TempDir dir;
  TriMesh sphere = make_uv_sphere({0, 0, 0}, 1, 32, 16);
  RenderOptions o;
  o.width = 160;
  o.height = 90;
  o.points = true;
  Image img = render(sphere, nullptr, o);
  fs::path file = dir.path() / "sphere.png";
  write_png(img, file);
  Image back = read_png(file);
  EXPECT_EQ(back.width, 160);
  EXPECT_EQ(back.height, 90);
  EXPECT_EQ(back.rgb, img.rgb);
  // Overwriting works and leaves no temp file behind.
  write_png(img, file);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator{}), 1);
}

TEST(WritePng, UnwritablePathThrowsIoError) {
  Image img{2, 2, std::vector<uint8_t>(12, 128)};
  try {
    write_png(img, "/nonexistent-dir/x.png");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.png"), std::string::npos) << e.what();
  }
  EXPECT_THROW(write_png(Image{2, 2, {}}, "/tmp/never.png"), InvalidInput);
}

TEST(WritePng, FailedWriteKeepsExistingFile) {
  // Make the write itself fail (file size limit), which works even when running as root,
  // where permission bits would not stop us.
  TempDir dir;
  fs::path file = dir.path() / "keep.png";
  { std::ofstream(file) << "previous contents"; }
  Image img;
  img.width = img.height = 256;
  img.rgb.resize(256 * 256 * 3);
  uint32_t x = 12345;
  for (auto& b : img.rgb) b = uint8_t((x = x * 1664525u + 1013904223u) >> 24);  // incompressible

  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = old;
  small.rlim_cur = 4096;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  bool threw = false;
  try {
    write_png(img, file);
  } catch (const IoError&) {
    threw = true;
  }
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_TRUE(threw);
  std::ifstream in(file);
  std::string contents((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(contents, "previous contents");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator{}), 1);
}

}  // namespace
}  // namespace pic
