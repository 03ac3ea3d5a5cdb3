// Lowering (lowering.h): affine maps, a node's arguments, fragment counts, file arguments.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "scad/lowering.h"

namespace pic::detail::scad {

Affine compose(const Affine& a, const Affine& b) {  // a * b
  Affine r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) {
      double s = j == 3 ? a[i * 4 + 3] : 0;
      for (int k = 0; k < 3; ++k) s += a[i * 4 + k] * b[k * 4 + j];
      r[i * 4 + j] = s;
    }
  return r;
}
Affine2 compose2(const Affine2& a, const Affine2& b) {
  return {a[0] * b[0] + a[1] * b[3], a[0] * b[1] + a[1] * b[4], a[0] * b[2] + a[1] * b[5] + a[2],
          a[3] * b[0] + a[4] * b[3], a[3] * b[1] + a[4] * b[4], a[3] * b[2] + a[4] * b[5] + a[5]};
}
double det3(const Affine& m) {
  return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
         m[2] * (m[4] * m[9] - m[5] * m[8]);
}
// Largest stretch of the linear part (max column norm; enough to size tessellations).
double stretch(const Affine& m) {
  double s = 0;
  for (int j = 0; j < 3; ++j)
    s = std::max(s, std::sqrt(m[j] * m[j] + m[4 + j] * m[4 + j] + m[8 + j] * m[8 + j]));
  return s;
}
double stretch2(const Affine2& m) {
  return std::max(std::hypot(m[0], m[3]), std::hypot(m[1], m[4]));
}

void apply(const Affine& m, TriMesh& mesh) {
  for (Vec3& p : mesh.positions) {
    const Vec3 q = p;
    for (int i = 0; i < 3; ++i) p[i] = m[i * 4] * q[0] + m[i * 4 + 1] * q[1] + m[i * 4 + 2] * q[2] + m[i * 4 + 3];
  }
  if (det3(m) < 0)
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
}
// A mirroring map reverses the ring, so outer boundaries stay counter-clockwise.
Ring apply2(const Affine2& m, const Ring& r) {
  Ring out;
  out.reserve(r.size());
  for (const P2& p : r) out.push_back({m[0] * p[0] + m[1] * p[1] + m[2], m[3] * p[0] + m[4] * p[1] + m[5]});
  if (m[0] * m[4] - m[1] * m[3] < 0) std::reverse(out.begin(), out.end());
  return out;
}
Region apply2(const Affine2& m, const Region& r) {
  Region out;
  out.reserve(r.size());
  for (const Ring& ring : r) out.push_back(apply2(m, ring));
  return out;
}

[[noreturn]] void fail(const Node& n, const std::string& what) {
  throw InvalidInput("line " + std::to_string(n.line) + ": " + n.name + ": " + what);
}

const Value* arg(const Node& n, const std::string& key) {
  const auto it = n.args.find(key);
  return it == n.args.end() ? nullptr : &it->second;
}
double number(const Node& n, const std::string& key, double fallback) {
  const Value* v = arg(n, key);
  if (!v || v->kind == Value::Kind::Undef) return fallback;
  if (v->kind == Value::Kind::Bool) return v->boolean ? 1 : 0;
  if (v->kind != Value::Kind::Number) fail(n, "'" + key + "' must be a number");
  return v->number;
}
bool flag(const Node& n, const std::string& key, bool fallback) {
  const Value* v = arg(n, key);
  if (!v || v->kind == Value::Kind::Undef) return fallback;
  if (v->kind == Value::Kind::Bool) return v->boolean;
  if (v->kind == Value::Kind::Number) return v->number != 0;
  return fallback;
}
std::vector<double> numbers(const Node& n, const Value& v, const std::string& key) {
  std::vector<double> out;
  if (v.kind == Value::Kind::Number) return {v.number};
  if (v.kind != Value::Kind::Vector) fail(n, "'" + key + "' must be a vector of numbers");
  for (const Value& x : v.items) {
    if (x.kind != Value::Kind::Number) fail(n, "'" + key + "' must be a vector of numbers");
    out.push_back(x.number);
  }
  return out;
}
void check_finite(const Node& n, std::initializer_list<double> xs) {
  for (double x : xs)
    if (!std::isfinite(x)) fail(n, "non-finite parameter");
}

bool is_2d_node(const std::string& s) {
  return s == "square" || s == "circle" || s == "polygon" || s == "text" || s == "offset";
}
bool is_group(const std::string& s) {
  return s == "group" || s == "union" || s == "color" || s == "render";
}

// Fragments for a circle of radius r (model units) drawn `st` times larger in the world:
// OpenSCAD's rule on r, or, with --smooth, enough that the chord's sagitta
// r st (1 - cos(pi / n)) stays below smooth_chord finest cells.
int Lowering::frags(const Node& n, double r, double st) const {
  const double world_r = r * st;
  if (opt_.smooth && cell_ > 0 && world_r > 0) {
    const double e = opt_.smooth_chord * cell_;
    if (e >= world_r) return 8;
    return std::clamp(static_cast<int>(std::ceil(std::numbers::pi / std::acos(1 - e / world_r))), 8, 4096);
  }
  return fragments_from_r(r, number(n, "$fn", 0), number(n, "$fs", 2), number(n, "$fa", 12));
}

Affine Lowering::matrix(const Node& n) const {
  const Value* v = arg(n, "m");
  if (!v) v = arg(n, "0");
  if (!v || v->kind != Value::Kind::Vector || v->items.size() < 3) fail(n, "needs a 4x4 matrix");
  Affine a{};
  for (int i = 0; i < 3; ++i) {
    const auto row = numbers(n, v->items[i], "m");
    if (row.size() < 4) fail(n, "needs a 4x4 matrix");
    for (int j = 0; j < 4; ++j) a[i * 4 + j] = row[j];
  }
  for (double x : a)
    if (!std::isfinite(x)) fail(n, "non-finite matrix");
  return a;
}

double Lowering::radius(const Node& n, const char* r, const char* d, double fallback) const {
  if (const Value* v = arg(n, r); v && v->kind == Value::Kind::Number) return v->number;
  if (const Value* v = arg(n, d); v && v->kind == Value::Kind::Number) return v->number / 2;
  return fallback;
}

// A node's `file` argument (or its first positional one), relative to the model's folder.
std::filesystem::path Lowering::file_arg(const Node& n) const {
  const Value* f = arg(n, "file");
  if (!f) f = arg(n, "0");
  if (!f || f->kind != Value::Kind::String) fail(n, "needs file = \"...\"");
  std::filesystem::path p = f->text;
  return p.is_relative() ? opt_.base_dir / p : p;
}

// OpenSCAD warns about an import() file that does not exist and goes on with nothing there.
bool Lowering::missing(const Node& n, const std::filesystem::path& p) const {
  std::error_code ec;
  if (std::filesystem::exists(p, ec)) return false;
  left_out(n, "cannot open " + p.string());
  return true;
}

void Lowering::left_out(const Node& n, const std::string& why) const {
  if (opt_.warning) opt_.warning("line " + std::to_string(n.line) + ": " + n.name + ": " + why + " (left out)");
}

}  // namespace pic::detail::scad
