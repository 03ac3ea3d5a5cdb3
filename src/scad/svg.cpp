// SVG for import(): see svg.h. A small XML scanner (elements and attributes; comments,
// declarations and text skipped), a path-data parser with every command, and a transform
// stack.
#include "scad/svg.h"

#include <cctype>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "pic/types.h"

namespace pic::detail::scad {
namespace {

using Map = std::array<double, 6>;  // [a c e; b d f] as SVG's matrix(a b c d e f)
constexpr Map kIdentity{1, 0, 0, 1, 0, 0};
Map compose(const Map& m, const Map& n) {  // m * n
  return {m[0] * n[0] + m[2] * n[1], m[1] * n[0] + m[3] * n[1], m[0] * n[2] + m[2] * n[3],
          m[1] * n[2] + m[3] * n[3], m[0] * n[4] + m[2] * n[5] + m[4], m[1] * n[4] + m[3] * n[5] + m[5]};
}
P2 map_point(const Map& m, const P2& p) { return {m[0] * p[0] + m[2] * p[1] + m[4], m[1] * p[0] + m[3] * p[1] + m[5]}; }

// Straight pieces per Bezier curve, and per circle or ellipse; an arc's count grows with the
// angle it turns: 4, and one more per 18 degrees (OpenSCAD 2021's imports, whatever $fn, $fa
// and $fs say).
constexpr int kCurvePieces = 20;
constexpr int kCirclePieces = 40;
int arc_pieces(double radians) { return int(std::floor(4 + std::abs(radians) * 10 / std::numbers::pi)); }

// Numbers in SVG syntax: "1.5e-3", "-2", ".5.5" (two numbers), separated by spaces or commas.
class Numbers {
 public:
  explicit Numbers(const std::string& s, size_t pos = 0) : s_(s), i_(pos) {}
  void seek(size_t pos) { i_ = pos; }
  bool more() {
    skip();
    return i_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[i_])) || s_[i_] == '-' || s_[i_] == '+' || s_[i_] == '.');
  }
  double next() {
    skip();
    const char* b = s_.c_str() + i_;
    char* e = nullptr;
    const double v = std::strtod(b, &e);
    if (e == b || !std::isfinite(v)) throw InvalidInput("SVG: bad number near '" + s_.substr(i_, 12) + "'");
    i_ += size_t(e - b);
    return v;
  }
  bool flag() {  // arc flags may be written without separators: "a1 1 0 01 5 5"
    skip();
    if (i_ < s_.size() && (s_[i_] == '0' || s_[i_] == '1')) return s_[i_++] == '1';
    throw InvalidInput("SVG: bad arc flag");
  }
  size_t pos() const { return i_; }
  void skip() {
    while (i_ < s_.size() && (std::isspace(static_cast<unsigned char>(s_[i_])) || s_[i_] == ',')) ++i_;
  }

 private:
  const std::string& s_;
  size_t i_;
};

Map parse_transform(const std::string& t) {
  Map m = kIdentity;
  size_t i = 0;
  while (i < t.size()) {
    while (i < t.size() && !std::isalpha(static_cast<unsigned char>(t[i]))) ++i;
    const size_t b = i;
    while (i < t.size() && std::isalpha(static_cast<unsigned char>(t[i]))) ++i;
    const std::string name = t.substr(b, i - b);
    if (name.empty()) break;
    const size_t open = t.find('(', i), close = t.find(')', i);
    if (open == std::string::npos || close == std::string::npos) throw InvalidInput("SVG: bad transform '" + t + "'");
    std::vector<double> a;
    const std::string args = t.substr(open + 1, close - open - 1);
    Numbers n(args);
    while (n.more()) a.push_back(n.next());
    const auto arg = [&](size_t k, double fallback) { return k < a.size() ? a[k] : fallback; };
    Map x = kIdentity;
    const double rad = arg(0, 0) * std::numbers::pi / 180;
    if (name == "matrix" && a.size() == 6) x = {a[0], a[1], a[2], a[3], a[4], a[5]};
    else if (name == "translate") x = {1, 0, 0, 1, arg(0, 0), arg(1, 0)};
    else if (name == "scale") x = {arg(0, 1), 0, 0, arg(1, arg(0, 1)), 0, 0};
    else if (name == "rotate") {
      const double c = std::cos(rad), s = std::sin(rad), cx = arg(1, 0), cy = arg(2, 0);
      x = {c, s, -s, c, cx - c * cx + s * cy, cy - s * cx - c * cy};
    } else if (name == "skewX") x = {1, 0, std::tan(rad), 1, 0, 0};
    else if (name == "skewY") x = {1, std::tan(rad), 0, 1, 0, 0};
    m = compose(m, x);
    i = close + 1;
  }
  return m;
}

// Path data to rings (every subpath closed, as a filled shape is).
std::vector<Ring> parse_path(const std::string& d) {
  std::vector<Ring> rings;
  Ring cur;
  P2 pos{0, 0}, start{0, 0}, ctrl{0, 0};
  char last = 0;
  const auto close_ring = [&] {
    if (cur.size() >= 3) rings.push_back(cur);
    cur.clear();
  };
  const auto line_to = [&](const P2& p) {
    if (cur.empty()) cur.push_back(pos);
    cur.push_back(p);
    pos = p;
  };
  const auto cubic = [&](const P2& c1, const P2& c2, const P2& p) {
    const P2 p0 = pos;
    for (int k = 1; k <= kCurvePieces; ++k) {
      const double t = double(k) / kCurvePieces, u = 1 - t;
      line_to({u * u * u * p0[0] + 3 * u * u * t * c1[0] + 3 * u * t * t * c2[0] + t * t * t * p[0],
               u * u * u * p0[1] + 3 * u * u * t * c1[1] + 3 * u * t * t * c2[1] + t * t * t * p[1]});
    }
  };
  const auto quad = [&](const P2& c, const P2& p) {
    const P2 p0 = pos;
    for (int k = 1; k <= kCurvePieces; ++k) {
      const double t = double(k) / kCurvePieces, u = 1 - t;
      line_to({u * u * p0[0] + 2 * u * t * c[0] + t * t * p[0], u * u * p0[1] + 2 * u * t * c[1] + t * t * p[1]});
    }
  };
  // Elliptical arc, endpoint form (SVG implementation notes, F.6.5).
  const auto arc = [&](double rx, double ry, double phi_deg, bool large, bool sweep, const P2& p) {
    rx = std::abs(rx), ry = std::abs(ry);
    if (rx == 0 || ry == 0 || (p[0] == pos[0] && p[1] == pos[1])) return line_to(p);
    const double phi = phi_deg * std::numbers::pi / 180, c = std::cos(phi), s = std::sin(phi);
    const double dx = (pos[0] - p[0]) / 2, dy = (pos[1] - p[1]) / 2;
    const double x1 = c * dx + s * dy, y1 = -s * dx + c * dy;
    const double lambda = x1 * x1 / (rx * rx) + y1 * y1 / (ry * ry);
    if (lambda > 1) rx *= std::sqrt(lambda), ry *= std::sqrt(lambda);
    const double num = rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1;
    const double den = rx * rx * y1 * y1 + ry * ry * x1 * x1;
    double k = den > 0 ? std::sqrt(std::max(0.0, num / den)) : 0;
    if (large == sweep) k = -k;
    const double cx1 = k * rx * y1 / ry, cy1 = -k * ry * x1 / rx;
    const double cx = c * cx1 - s * cy1 + (pos[0] + p[0]) / 2, cy = s * cx1 + c * cy1 + (pos[1] + p[1]) / 2;
    const auto angle = [](double ux, double uy, double vx, double vy) { return std::atan2(ux * vy - uy * vx, ux * vx + uy * vy); };
    const double t1 = angle(1, 0, (x1 - cx1) / rx, (y1 - cy1) / ry);
    double dt = angle((x1 - cx1) / rx, (y1 - cy1) / ry, (-x1 - cx1) / rx, (-y1 - cy1) / ry);
    if (!sweep && dt > 0) dt -= 2 * std::numbers::pi;
    if (sweep && dt < 0) dt += 2 * std::numbers::pi;
    const int pieces = arc_pieces(dt);
    for (int j = 1; j <= pieces; ++j) {
      const double t = t1 + dt * j / pieces;
      line_to(j == pieces ? p : P2{cx + rx * std::cos(t) * c - ry * std::sin(t) * s,
                                    cy + rx * std::cos(t) * s + ry * std::sin(t) * c});
    }
  };
  Numbers n(d);
  size_t i = 0;
  while (true) {
    n.skip();
    i = n.pos();
    if (i >= d.size()) break;
    char cmd = d[i];
    if (std::isalpha(static_cast<unsigned char>(cmd))) {
      n.seek(i + 1);
    } else if (last && last != 'Z' && last != 'z') {
      cmd = last == 'M' ? 'L' : last == 'm' ? 'l' : last;  // repeated arguments
    } else {
      throw InvalidInput("SVG: bad path data near '" + d.substr(i, 12) + "'");
    }
    const bool rel = std::islower(static_cast<unsigned char>(cmd));
    const auto pt = [&] {
      const double x = n.next(), y = n.next();
      return rel ? P2{pos[0] + x, pos[1] + y} : P2{x, y};
    };
    switch (std::toupper(static_cast<unsigned char>(cmd))) {
      case 'M':
        close_ring();
        pos = start = pt();
        break;
      case 'L': line_to(pt()); break;
      case 'H': {
        const double x = n.next();
        line_to({rel ? pos[0] + x : x, pos[1]});
        break;
      }
      case 'V': {
        const double y = n.next();
        line_to({pos[0], rel ? pos[1] + y : y});
        break;
      }
      case 'C': {
        const P2 c1 = pt(), c2 = pt(), p = pt();
        cubic(c1, c2, p);
        ctrl = c2;
        break;
      }
      case 'S': {
        const bool smooth = last && std::strchr("CcSs", last);
        const P2 c1 = smooth ? P2{2 * pos[0] - ctrl[0], 2 * pos[1] - ctrl[1]} : pos;
        const P2 c2 = pt(), p = pt();
        cubic(c1, c2, p);
        ctrl = c2;
        break;
      }
      case 'Q': {
        const P2 c = pt(), p = pt();
        quad(c, p);
        ctrl = c;
        break;
      }
      case 'T': {
        const bool smooth = last && std::strchr("QqTt", last);
        const P2 c = smooth ? P2{2 * pos[0] - ctrl[0], 2 * pos[1] - ctrl[1]} : pos;
        const P2 p = pt();
        quad(c, p);
        ctrl = c;
        break;
      }
      case 'A': {
        const double rx = n.next(), ry = n.next(), phi = n.next();
        const bool large = n.flag(), sweep = n.flag();
        arc(rx, ry, phi, large, sweep, pt());
        break;
      }
      case 'Z':
        close_ring();
        pos = start;
        break;
      default: throw InvalidInput(std::string("SVG: unknown path command '") + cmd + "'");
    }
    last = cmd;
  }
  close_ring();
  return rings;
}

double length_mm(const std::string& v, double dpi, double fallback) {
  if (v.empty()) return fallback;
  char* e = nullptr;
  const double x = std::strtod(v.c_str(), &e);
  if (e == v.c_str() || !std::isfinite(x)) return fallback;
  const std::string unit(e);
  if (unit == "mm") return x;
  if (unit == "cm") return 10 * x;
  if (unit == "in") return 25.4 * x;
  if (unit == "pt") return 25.4 * x / 72;
  if (unit == "pc") return 25.4 * x / 6;
  return 25.4 * x / dpi;  // px or unitless
}

using Attrs = std::map<std::string, std::string>;

}  // namespace

Region read_svg(const std::filesystem::path& path, double dpi) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot read " + path.string());
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string x = ss.str();
  const std::string name = path.string();
  std::vector<Map> stack{kIdentity};
  Region out;
  Map doc = kIdentity;
  bool have_doc = false;
  int skip_depth = 0;  // inside <defs>, <clipPath>, ... whose content is not drawn
  size_t i = 0;
  while ((i = x.find('<', i)) != std::string::npos) {
    if (x.compare(i, 4, "<!--") == 0) {
      const size_t e = x.find("-->", i);
      if (e == std::string::npos) throw InvalidInput(name + ": unterminated SVG comment");
      i = e + 3;
      continue;
    }
    if (x.compare(i, 2, "<?") == 0 || x.compare(i, 2, "<!") == 0) {
      i = x.find('>', i);
      if (i == std::string::npos) break;
      continue;
    }
    const size_t end = x.find('>', i);
    if (end == std::string::npos) throw InvalidInput(name + ": truncated SVG element");
    const bool closing = x[i + 1] == '/', self = x[end - 1] == '/';
    std::string body = x.substr(i + 1 + closing, end - i - 1 - closing - self);
    i = end + 1;
    size_t k = 0;
    while (k < body.size() && !std::isspace(static_cast<unsigned char>(body[k]))) ++k;
    std::string tag = body.substr(0, k);
    if (const size_t colon = tag.find(':'); colon != std::string::npos) tag = tag.substr(colon + 1);
    const bool container = tag == "g" || tag == "svg" || tag == "a" || tag == "switch";
    const bool hidden = tag == "defs" || tag == "clipPath" || tag == "mask" || tag == "symbol" || tag == "marker" ||
                        tag == "pattern" || tag == "style" || tag == "metadata";
    if (closing) {
      if (hidden && skip_depth > 0) --skip_depth;
      else if (container && stack.size() > 1) stack.pop_back();
      continue;
    }
    if (hidden) {
      if (!self) ++skip_depth;
      continue;
    }
    if (skip_depth > 0) continue;
    Attrs a;
    while (k < body.size()) {
      while (k < body.size() && std::isspace(static_cast<unsigned char>(body[k]))) ++k;
      const size_t eq = body.find('=', k);
      if (eq == std::string::npos) break;
      std::string key = body.substr(k, eq - k);
      while (!key.empty() && std::isspace(static_cast<unsigned char>(key.back()))) key.pop_back();
      size_t q = eq + 1;
      while (q < body.size() && std::isspace(static_cast<unsigned char>(body[q]))) ++q;
      if (q >= body.size() || (body[q] != '"' && body[q] != '\'')) throw InvalidInput(name + ": bad SVG attribute " + key);
      const size_t qe = body.find(body[q], q + 1);
      if (qe == std::string::npos) throw InvalidInput(name + ": unterminated SVG attribute " + key);
      a[key] = body.substr(q + 1, qe - q - 1);
      k = qe + 1;
    }
    const auto num = [&](const char* key, double fallback = 0) {
      const auto it = a.find(key);
      return it == a.end() ? fallback : length_mm(it->second, 25.4, fallback);  // user units, no unit conversion
    };
    if (tag == "svg" && !have_doc) {
      // Document size in mm, user units through the viewBox; y flipped about the height.
      have_doc = true;
      double vb[4] = {0, 0, 0, 0};
      bool has_vb = false;
      if (const auto it = a.find("viewBox"); it != a.end()) {
        Numbers n(it->second);
        for (double& v : vb) v = n.more() ? n.next() : 0;
        has_vb = vb[2] > 0 && vb[3] > 0;
      }
      const double w = length_mm(a.count("width") ? a["width"] : "", dpi, has_vb ? vb[2] * 25.4 / dpi : 0);
      const double h = length_mm(a.count("height") ? a["height"] : "", dpi, has_vb ? vb[3] * 25.4 / dpi : 0);
      const double sx = has_vb ? w / vb[2] : 25.4 / dpi, sy = has_vb ? h / vb[3] : 25.4 / dpi;
      doc = {sx, 0, 0, -sy, -vb[0] * sx, h + vb[1] * sy};
    }
    Map m = stack.back();
    if (const auto it = a.find("transform"); it != a.end()) m = compose(m, parse_transform(it->second));
    if (container) {
      if (!self) stack.push_back(m);
      continue;
    }
    std::vector<Ring> rings;
    if (tag == "path") {
      rings = parse_path(a["d"]);
    } else if (tag == "rect") {
      const double rx0 = num("x"), ry0 = num("y"), w = num("width"), h = num("height");
      if (w > 0 && h > 0) rings.push_back({{rx0, ry0}, {rx0 + w, ry0}, {rx0 + w, ry0 + h}, {rx0, ry0 + h}});
    } else if (tag == "circle" || tag == "ellipse") {
      const double cx = num("cx"), cy = num("cy");
      const double rx = tag == "circle" ? num("r") : num("rx"), ry = tag == "circle" ? num("r") : num("ry");
      if (rx > 0 && ry > 0) {
        Ring r;
        for (int j = 0; j < kCirclePieces; ++j) {
          const double t = 2 * std::numbers::pi * j / kCirclePieces;
          r.push_back({cx + rx * std::cos(t), cy + ry * std::sin(t)});
        }
        rings.push_back(std::move(r));
      }
    } else if (tag == "polygon" || tag == "polyline") {
      Ring r;
      Numbers n(a["points"]);
      while (n.more()) {
        const double px = n.next(), py = n.next();
        r.push_back({px, py});
      }
      if (r.size() >= 3) rings.push_back(std::move(r));
    }
    if (rings.empty()) continue;
    for (Ring& r : rings)
      for (P2& p : r) p = map_point(m, p);
    // Each shape is filled on its own by the even-odd rule (as OpenSCAD fills them, whatever
    // their fill-rule), then united with the others.
    Region shape = region_even_odd(rings);
    out.insert(out.end(), shape.begin(), shape.end());
  }
  for (Ring& r : out) {
    for (P2& p : r) p = map_point(doc, p);
    std::reverse(r.begin(), r.end());  // the y flip reversed every ring
  }
  return region_union({out});
}

}  // namespace pic::detail::scad
