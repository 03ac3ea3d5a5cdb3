// Headless software renderer for `pic render`.
//
// Why not OpenGL: the machines that build, test and run PIC have no GPU and no display, and
// an offscreen GL context would drag in Mesa/EGL for a few pictures. A z-buffer rasterizer
// with edge functions is small, has no dependencies, and renders a million triangles at
// 1024x1024 well within a second on one core.
#include "pic/render.h"

#include "io/file_util.h"
#include "geometry/tolerances.h"

#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <limits>

namespace pic {
namespace {

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3 mul(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
bool finite(const Vec3& a) {
  return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]);
}

constexpr double kFovY = 30.0 * 3.14159265358979323846 / 180.0;
constexpr float kFar = std::numeric_limits<float>::infinity();

/// A vertex in screen space. `q` is linear in screen space (view depth for orthographic,
/// 1 / depth for perspective), so it can be interpolated with barycentric weights.
struct ScreenPoint {
  double x = 0, y = 0, q = 0;
  bool ok = false;  // false: behind the near plane (perspective) or not finite
};

struct Camera {
  Vec3 origin{};  // perspective: the eye; orthographic: the point at the image centre
  Vec3 right{}, up{}, forward{};
  bool perspective = false;
  double scale = 1;  // orthographic: pixels per unit; perspective: focal length in pixels
  double cx = 0, cy = 0, near = 0;

  ScreenPoint project(const Vec3& p) const {
    ScreenPoint s;
    if (!finite(p)) return s;
    Vec3 r = sub(p, origin);
    double x = dot(r, right), y = dot(r, up), z = dot(r, forward);
    if (perspective) {
      if (z < near) return s;
      s.x = cx + x / z * scale;
      s.y = cy - y / z * scale;
      s.q = 1.0 / z;
    } else {
      s.x = cx + x * scale;
      s.y = cy - y * scale;
      s.q = z;
    }
    s.ok = true;
    return s;
  }
  double depth(double q) const { return perspective ? 1.0 / q : q; }
  /// World size of one pixel at view depth z: depth tests of lines and dots use a bias of a
  /// few pixels so that edges lying on the surface are not lost to z-fighting.
  double pixel_size(double z) const { return perspective ? z / scale : 1.0 / scale; }
};

struct ViewDir {
  Vec3 forward, up;
};

ViewDir named_view(const std::string& view) {
  const Vec3 z_up{0, 0, 1}, y_up{0, 1, 0};
  if (view == "iso") return {{-1, 1, -1}, z_up};
  if (view == "front") return {{0, 1, 0}, z_up};
  if (view == "back") return {{0, -1, 0}, z_up};
  if (view == "left") return {{1, 0, 0}, z_up};
  if (view == "right") return {{-1, 0, 0}, z_up};
  if (view == "top") return {{0, 0, -1}, y_up};
  if (view == "bottom") return {{0, 0, 1}, y_up};
  throw InvalidInput("unknown view '" + view +
                     "' (expected iso, front, back, left, right, top or bottom)");
}

struct Bounds {
  Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity()};
  Vec3 hi{-lo[0], -lo[1], -lo[2]};
  void add(const Vec3& p) {
    if (!finite(p)) return;
    for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], p[i]), hi[i] = std::max(hi[i], p[i]);
  }
  bool empty() const { return !(lo[0] <= hi[0]); }
  Vec3 center() const { return mul(pic::add(lo, hi), 0.5); }
  double radius() const { return 0.5 * norm(sub(hi, lo)); }
};

struct GrayCell {
  Vec3 min;
  double size;
  Vec3 vertex;
};

Camera make_camera(const RenderOptions& opt, int w, int h, const Bounds& b,
                   const TriMesh& mesh, const std::vector<GrayCell>& cells) {
  Camera cam;
  cam.perspective = opt.perspective;
  cam.cx = 0.5 * w;
  cam.cy = 0.5 * h;
  Vec3 forward, up;
  std::optional<Vec3> eye, target;
  if (opt.camera) {
    const auto& c = *opt.camera;
    eye = Vec3{c[0], c[1], c[2]};
    target = Vec3{c[3], c[4], c[5]};
    forward = sub(*target, *eye);
    up = {c[6], c[7], c[8]};
  } else {
    ViewDir v = named_view(opt.view);
    forward = v.forward;
    up = v.up;
  }
  double fl = norm(forward);
  if (!(fl > 0) || !std::isfinite(fl)) throw InvalidInput("render: camera eye equals target");
  cam.forward = mul(forward, 1.0 / fl);
  Vec3 right = cross(cam.forward, up);
  double rl = norm(right);
  if (!(rl > detail::kParallelUp) || !std::isfinite(rl))
    throw InvalidInput("render: camera up vector is parallel to the view direction");
  cam.right = mul(right, 1.0 / rl);
  cam.up = cross(cam.right, cam.forward);

  const double radius = b.radius() > 0 ? b.radius() : 1.0;
  const double half_pixels = 0.5 * std::min(w, h);
  // What will be drawn, for framing: the mesh vertices (tighter than the bounding box's
  // corners, which would leave an iso view of a sphere small in the frame) and the cells.
  auto for_each_drawn = [&](auto&& f) {
    for (const Vec3& p : mesh.positions)
      if (finite(p)) f(p);
    for (const GrayCell& c : cells)
      for (int k = 0; k < 8; ++k)
        f(add(c.min, {(k & 1) * c.size, (k >> 1 & 1) * c.size, (k >> 2 & 1) * c.size}));
  };
  const double inf = std::numeric_limits<double>::infinity();
  double x0 = inf, x1 = -inf, y0 = inf, y1 = -inf;
  auto extend = [&](double x, double y) {
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  };

  if (cam.perspective) {
    cam.scale = half_pixels / std::tan(0.5 * kFovY);
    cam.near = detail::kNearPlane * radius;
    if (eye) {
      cam.origin = *eye;
      return cam;
    }
    // Far enough that the bounding sphere is in front of the eye and fits; then zoom and
    // shift the image so the projected object fills it, like the orthographic framing.
    double dist = 1.08 * radius / std::sin(0.5 * kFovY);
    cam.origin = sub(b.center(), mul(cam.forward, dist));
    for_each_drawn([&](const Vec3& p) {
      Vec3 r = sub(p, cam.origin);
      double z = dot(r, cam.forward);
      if (z > cam.near) extend(dot(r, cam.right) / z, dot(r, cam.up) / z);
    });
    if (x0 < x1 || y0 < y1) {
      double ex = std::max(x1 - x0, detail::kMinViewExtent), ey = std::max(y1 - y0, detail::kMinViewExtent);
      cam.scale = 0.9 * std::min(w / ex, h / ey);
      cam.cx = 0.5 * w - 0.5 * (x0 + x1) * cam.scale;
      cam.cy = 0.5 * h + 0.5 * (y0 + y1) * cam.scale;
    }
    return cam;
  }

  if (opt.ortho_half_extent) {
    if (!(*opt.ortho_half_extent > 0)) throw InvalidInput("render: ortho_half_extent must be > 0");
    cam.scale = half_pixels / *opt.ortho_half_extent;
    cam.origin = target ? *target : b.center();
    return cam;
  }
  for_each_drawn([&](const Vec3& p) { extend(dot(p, cam.right), dot(p, cam.up)); });
  if (!(x0 <= x1)) x0 = x1 = y0 = y1 = 0;
  // A flat or single-point object still gets a finite zoom.
  double ex = std::max(x1 - x0, detail::kMinViewExtent * radius), ey = std::max(y1 - y0, detail::kMinViewExtent * radius);
  cam.scale = 0.9 * std::min(w / ex, h / ey);
  // origin: the point projecting to the centre of the projected extent, at the box centre depth.
  Vec3 c = b.center();
  double cz = dot(c, cam.forward);
  cam.origin = add(add(mul(cam.right, 0.5 * (x0 + x1)), mul(cam.up, 0.5 * (y0 + y1))),
                   mul(cam.forward, cz));
  return cam;
}

struct Canvas {
  int w, h;
  std::vector<uint8_t> rgb;
  std::vector<float> z;
  Canvas(int w_, int h_) : w(w_), h(h_), rgb(size_t(w_) * h_ * 3), z(size_t(w_) * h_, kFar) {
    for (size_t i = 0; i < z.size(); ++i) std::memcpy(&rgb[i * 3], kRenderBackground.data(), 3);
  }
  void blend(size_t i, const std::array<uint8_t, 3>& c, double a) {
    for (int k = 0; k < 3; ++k)
      rgb[i * 3 + k] = uint8_t(std::lround(rgb[i * 3 + k] * (1 - a) + c[k] * a));
  }
};

std::array<uint8_t, 3> shade(const Camera& cam, const Vec3& normal, bool back) {
  // Flat shading: one colour per triangle so that sharp features stay sharp in the picture.
  // Back faces (seen only through holes or on inverted meshes) get a warm colour on purpose.
  Vec3 n = back ? mul(normal, -1) : normal;
  const Vec3 to_viewer = mul(cam.forward, -1);
  // Key light from above and slightly left of the viewer, plus ambient and a headlight so
  // that no visible face goes black: in the iso view of a box the three faces get about
  // 0.94, 0.71 and 0.54 of the material colour.
  Vec3 key = add(add(mul(cam.right, -0.25), mul(cam.up, 0.5)), mul(to_viewer, 0.8));
  key = mul(key, 1.0 / norm(key));
  double l = 0.35 + 0.5 * std::max(0.0, dot(n, key)) + 0.25 * std::max(0.0, dot(n, to_viewer));
  l = std::min(l, 1.0);
  const double front_col[3] = {0.66, 0.74, 0.86}, back_col[3] = {0.86, 0.55, 0.42};
  const double* col = back ? back_col : front_col;
  std::array<uint8_t, 3> out;
  for (int k = 0; k < 3; ++k) out[k] = uint8_t(std::lround(255 * std::min(1.0, col[k] * l)));
  return out;
}

void draw_triangles(Canvas& cv, const Camera& cam, const TriMesh& mesh,
                    const std::vector<ScreenPoint>& sp, const std::vector<uint8_t>& marked) {
  const size_t nv = mesh.positions.size();
  for (size_t ti = 0; ti < mesh.triangles.size(); ++ti) {
    const auto& t = mesh.triangles[ti];
    if (t[0] >= nv || t[1] >= nv || t[2] >= nv) continue;  // validated by the caller
    const ScreenPoint &a = sp[t[0]], &b = sp[t[1]], &c = sp[t[2]];
    // Perspective: triangles crossing the near plane are dropped rather than clipped;
    // they only occur with a user camera placed inside the object.
    if (!a.ok || !b.ok || !c.ok) continue;
    double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (!(std::abs(area) > detail::kDegenerateScreenArea)) continue;
    int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x}))));
    int x1 = std::min(cv.w - 1, int(std::ceil(std::max({a.x, b.x, c.x}))));
    int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y}))));
    int y1 = std::min(cv.h - 1, int(std::ceil(std::max({a.y, b.y, c.y}))));
    if (x0 > x1 || y0 > y1) continue;
    const Vec3 &pa = mesh.positions[t[0]], &pb = mesh.positions[t[1]], &pc = mesh.positions[t[2]];
    Vec3 n = cross(sub(pb, pa), sub(pc, pa));
    double nl = norm(n);
    if (!(nl > 0)) continue;
    // Back faces lose depth ties: at silhouettes of closed meshes the front and back faces
    // meet at equal depth, and float rounding would otherwise let back-face pixels through.
    const bool back = dot(n, cam.perspective ? sub(pa, cam.origin) : cam.forward) > 0;
    std::array<uint8_t, 3> col = shade(cam, mul(n, 1.0 / nl), back);
    if (!marked.empty() && marked[ti]) col = {uint8_t(std::min(255, col[0] + 120)), uint8_t(col[1] / 3), uint8_t(col[2] / 3)};

    // Edge functions, normalised by the signed area so that they are barycentric weights
    // and positive inside whatever the winding on screen.
    const double inv = 1.0 / area;
    auto edge = [&](const ScreenPoint& p, const ScreenPoint& q, double& e0, double& dx, double& dy) {
      // weight of the vertex opposite edge p->q, at pixel centre (x0 + .5, y0 + .5)
      dx = (p.y - q.y) * inv;  // change per +1 in x
      dy = (q.x - p.x) * inv;  // change per +1 in y
      e0 = ((q.x - p.x) * (y0 + 0.5 - p.y) - (q.y - p.y) * (x0 + 0.5 - p.x)) * inv;
    };
    double wa, wadx, wady, wb, wbdx, wbdy, wc, wcdx, wcdy;
    edge(b, c, wa, wadx, wady);
    edge(c, a, wb, wbdx, wbdy);
    edge(a, b, wc, wcdx, wcdy);
    for (int y = y0; y <= y1; ++y) {
      double u = wa, v = wb, s = wc;
      size_t row = size_t(y) * cv.w;
      for (int x = x0; x <= x1; ++x) {
        // A small negative tolerance closes cracks between triangles sharing an edge.
        if (u >= -detail::kRasterEdgeSlack && v >= -detail::kRasterEdgeSlack && s >= -detail::kRasterEdgeSlack) {
          double zd = cam.depth(u * a.q + v * b.q + s * c.q);
          float z = float(back ? zd + cam.pixel_size(zd) : zd);
          size_t i = row + x;
          if (z < cv.z[i]) {
            cv.z[i] = z;
            std::memcpy(&cv.rgb[i * 3], col.data(), 3);
          }
        }
        u += wadx, v += wbdx, s += wcdx;
      }
      wa += wady, wb += wbdy, wc += wcdy;
    }
  }
}

/// Draws a line of `thick` pixels, depth-tested against the surface with `bias` pixels'
/// worth of depth, so lines on or just above the surface show and hidden ones do not.
void draw_line(Canvas& cv, const Camera& cam, ScreenPoint a, ScreenPoint b, int thick,
               const std::array<uint8_t, 3>& col, double alpha, double bias_px) {
  if (!a.ok || !b.ok) return;
  // Liang-Barsky clip against the canvas, so far off-screen segments cost nothing.
  double t0 = 0, t1 = 1, dx = b.x - a.x, dy = b.y - a.y;
  auto clip = [&](double p, double q) {
    if (p == 0) return q >= 0;
    double r = q / p;
    if (p < 0) {
      if (r > t1) return false;
      t0 = std::max(t0, r);
    } else {
      if (r < t0) return false;
      t1 = std::min(t1, r);
    }
    return true;
  };
  if (!clip(-dx, a.x) || !clip(dx, cv.w - 1 - a.x) || !clip(-dy, a.y) || !clip(dy, cv.h - 1 - a.y))
    return;
  double dq = b.q - a.q;
  ScreenPoint p{a.x + t0 * dx, a.y + t0 * dy, a.q + t0 * dq, true};
  ScreenPoint q{a.x + t1 * dx, a.y + t1 * dy, a.q + t1 * dq, true};
  double len = std::max(std::abs(q.x - p.x), std::abs(q.y - p.y));
  int steps = std::max(1, int(std::ceil(len)));
  bool x_major = std::abs(q.x - p.x) >= std::abs(q.y - p.y);
  int lo = -(thick - 1) / 2, hi = thick / 2;
  for (int s = 0; s <= steps; ++s) {
    double t = double(s) / steps;
    double x = p.x + t * (q.x - p.x), y = p.y + t * (q.y - p.y);
    double z = cam.depth(p.q + t * (q.q - p.q));
    double bias = bias_px * cam.pixel_size(z);
    int ix = int(std::floor(x)), iy = int(std::floor(y));
    for (int o = lo; o <= hi; ++o) {
      int px = x_major ? ix : ix + o, py = x_major ? iy + o : iy;
      if (px < 0 || py < 0 || px >= cv.w || py >= cv.h) continue;
      size_t i = size_t(py) * cv.w + px;
      if (z <= double(cv.z[i]) + bias) cv.blend(i, col, alpha);
    }
  }
}

void draw_dot(Canvas& cv, const Camera& cam, const ScreenPoint& p, double radius,
              const std::array<uint8_t, 3>& col, double bias_px) {
  if (!p.ok) return;
  int cx = int(std::floor(p.x)), cy = int(std::floor(p.y));
  if (cx < 0 || cy < 0 || cx >= cv.w || cy >= cv.h) return;
  double z = cam.depth(p.q);
  // The vertex lies on the surface: test its centre against the surface with a bias.
  if (!(z <= double(cv.z[size_t(cy) * cv.w + cx]) + bias_px * cam.pixel_size(z))) return;
  int r = int(std::ceil(radius));
  for (int y = cy - r; y <= cy + r; ++y)
    for (int x = cx - r; x <= cx + r; ++x) {
      if (x < 0 || y < 0 || x >= cv.w || y >= cv.h) continue;
      double ddx = x + 0.5 - p.x, ddy = y + 0.5 - p.y;
      if (ddx * ddx + ddy * ddy <= radius * radius) cv.blend(size_t(y) * cv.w + x, col, 1.0);
    }
}

}  // namespace

Image render(const TriMesh& mesh, const Octree* tree, const RenderOptions& opt) {
  if (opt.width <= 0 || opt.height <= 0 || opt.width > 16384 || opt.height > 16384)
    throw InvalidInput("render: image size must be between 1 and 16384 pixels per side");
  if (opt.supersample < 1 || opt.supersample > 4)
    throw InvalidInput("render: supersample must be 1..4");
  for (const auto& t : mesh.triangles)
    for (uint32_t v : t)
      if (v >= mesh.positions.size()) throw InvalidInput("render: triangle index out of range");

  const int ss = opt.supersample;
  const int w = opt.width * ss, h = opt.height * ss;

  std::vector<GrayCell> cells;
  // Cells are framed and drawn only when asked for (or when there is nothing else).
  if (tree && (opt.octree || opt.points || mesh.positions.empty()))
    for_each_leaf(*tree, [&](const LeafView& l) {
      if (l.kind == CellKind::Gray) cells.push_back({l.cell_min, l.cell_size, l.vertex});
    });

  Bounds b;
  for (const Vec3& p : mesh.positions) b.add(p);
  if (b.empty() || opt.octree)
    for (const GrayCell& c : cells) {
      b.add(c.min);
      b.add(add(c.min, {c.size, c.size, c.size}));
    }

  const std::vector<GrayCell> no_cells;
  Camera cam = make_camera(opt, w, h, b, mesh, opt.octree || mesh.positions.empty() ? cells : no_cells);
  Canvas cv(w, h);

  std::vector<ScreenPoint> sp(mesh.positions.size());
  for (size_t i = 0; i < sp.size(); ++i) sp[i] = cam.project(mesh.positions[i]);
  std::vector<uint8_t> marked;
  if (opt.highlight_crossings) {
    marked.assign(mesh.triangles.size(), 0);
    for (const auto& [a, c] : self_intersecting_pairs(mesh)) marked[a] = marked[c] = 1;
  }
  draw_triangles(cv, cam, mesh, sp, marked);

  if (opt.octree) {
    const std::array<uint8_t, 3> line_col{30, 34, 44};
    for (const GrayCell& c : cells) {
      ScreenPoint corner[8];
      for (int k = 0; k < 8; ++k)
        corner[k] = cam.project(add(c.min, {(k & 1) * c.size, (k >> 1 & 1) * c.size,
                                            (k >> 2 & 1) * c.size}));
      // The 12 edges join corners that differ in exactly one bit.
      for (int k = 0; k < 8; ++k)
        for (int bit = 1; bit < 8; bit <<= 1)
          if (!(k & bit)) draw_line(cv, cam, corner[k], corner[k | bit], ss, line_col, 0.85, 2.0 * ss);
    }
  }
  if (opt.points) {
    const std::array<uint8_t, 3> dot_col{215, 30, 35};
    const double radius = 1.3 * ss;  // about 2.5 output pixels across
    if (tree) {
      for (const GrayCell& c : cells) draw_dot(cv, cam, cam.project(c.vertex), radius, dot_col, 3.0 * ss);
    } else {
      for (const ScreenPoint& p : sp) draw_dot(cv, cam, p, radius, dot_col, 3.0 * ss);
    }
  }

  Image img;
  img.width = opt.width;
  img.height = opt.height;
  img.pixels_per_unit = cam.perspective ? 0.0 : cam.scale / ss;
  img.rgb.resize(size_t(opt.width) * opt.height * 3);
  // Box-filter the supersampled canvas down to the output size.
  const int n = ss * ss;
  for (int y = 0; y < opt.height; ++y)
    for (int x = 0; x < opt.width; ++x)
      for (int k = 0; k < 3; ++k) {
        int sum = 0;
        for (int sy = 0; sy < ss; ++sy)
          for (int sx = 0; sx < ss; ++sx)
            sum += cv.rgb[(size_t(y * ss + sy) * w + (x * ss + sx)) * 3 + k];
        img.rgb[(size_t(y) * opt.width + x) * 3 + k] = uint8_t((sum + n / 2) / n);
      }
  return img;
}

namespace {

struct PngError {
  std::jmp_buf jmp;
  char message[256] = "";
};

void png_error_fn(png_structp png, png_const_charp msg) {
  auto* e = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(e->message, sizeof e->message, "%s", msg);
  std::longjmp(e->jmp, 1);
}
void png_warning_fn(png_structp, png_const_charp) {}

/// libpng reports errors by longjmp, so this function keeps only trivially destructible
/// locals between setjmp and the calls that may jump.
bool encode_png(std::FILE* f, const Image& img, png_bytep* rows, PngError& err) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, png_error_fn, png_warning_fn);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(err.jmp)) {
    png_destroy_write_struct(&png, info ? &info : nullptr);
    return false;
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, png_uint_32(img.width), png_uint_32(img.height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

void write_png(const Image& img, const std::filesystem::path& path) {
  if (img.width <= 0 || img.height <= 0 || img.rgb.size() != size_t(img.width) * img.height * 3)
    throw InvalidInput("write_png: image size does not match its pixel buffer");
  // Written beside the target and renamed over it (file_util.h): a failed write keeps an
  // existing file.
  detail::write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw IoError("cannot write PNG '" + path.string() + "': " + std::strerror(errno));
    std::vector<png_bytep> rows(size_t(img.height));
    for (int y = 0; y < img.height; ++y)
      rows[size_t(y)] = const_cast<png_bytep>(&img.rgb[size_t(y) * img.width * 3]);
    PngError err;
    bool ok = encode_png(f, img, rows.data(), err);
    ok = std::fflush(f) == 0 && ok && !std::ferror(f);
    const int saved_errno = errno;
    ok = std::fclose(f) == 0 && ok;
    if (!ok)
      throw IoError("cannot write PNG '" + path.string() + "': " + (err.message[0] ? err.message : std::strerror(saved_errno)));
  });
}

}  // namespace pic
