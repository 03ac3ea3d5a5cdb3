// The HTML viewer page. The JavaScript (three.js + viewer/main.js) is bundled by esbuild
// and embedded at build time (cmake/viewer.cmake), so a page opens offline.
#include "pic/viewer.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace pic {

extern const char* const kViewerBundle;  // generated: ${CMAKE_BINARY_DIR}/generated/viewer_bundle.cpp

namespace {

static_assert(std::endian::native == std::endian::little,
              "the viewer page stores arrays little-endian, as JavaScript typed arrays read them");

template <class T>
void append_base64(std::string& out, const std::vector<T>& values) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = reinterpret_cast<const uint8_t*>(values.data());
  const size_t n = values.size() * sizeof(T);
  out.reserve(out.size() + (n + 2) / 3 * 4 + 2);
  size_t i = 0;
  for (; i + 3 <= n; i += 3) {
    uint32_t v = uint32_t(p[i]) << 16 | uint32_t(p[i + 1]) << 8 | p[i + 2];
    out += kDigits[v >> 18];
    out += kDigits[v >> 12 & 63];
    out += kDigits[v >> 6 & 63];
    out += kDigits[v & 63];
  }
  if (size_t rest = n - i) {
    uint32_t v = uint32_t(p[i]) << 16 | (rest == 2 ? uint32_t(p[i + 1]) << 8 : 0);
    out += kDigits[v >> 18];
    out += kDigits[v >> 12 & 63];
    out += rest == 2 ? kDigits[v >> 6 & 63] : '=';
    out += '=';
  }
}

/// A JSON string literal. '<' and '>' are escaped too, so the text can never close the
/// <script> element that holds the data.
void append_json_string(std::string& out, const std::string& s) {
  out += '"';
  for (unsigned char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (c < 0x20 || c == '<' || c == '>' || c == '&') {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += char(c);
        }
    }
  }
  out += '"';
}

void append_number(std::string& out, double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", std::isfinite(v) ? v : 0.0);
  out += buf;
}

}  // namespace

std::string view_html(const TriMesh& mesh, const Octree* tree, const std::string& info_json) {
  for (const auto& t : mesh.triangles)
    for (uint32_t v : t)
      if (v >= mesh.positions.size()) throw InvalidInput("view_html: triangle index out of range");

  struct Cell {
    Vec3 min;
    double size;
    Vec3 vertex;
  };
  std::vector<Cell> cells;
  if (tree)
    for_each_leaf(*tree, [&](const LeafView& l) {
      if (l.kind == CellKind::Gray) cells.push_back({l.cell_min, l.cell_size, l.vertex});
    });

  // Store coordinates relative to the bounding box centre: floats then keep their
  // precision for models far from the origin.
  Vec3 lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  auto extend = [&](const Vec3& p) {
    for (int i = 0; i < 3; ++i)
      if (std::isfinite(p[i])) lo[i] = std::min(lo[i], p[i]), hi[i] = std::max(hi[i], p[i]);
  };
  for (const Vec3& p : mesh.positions) extend(p);
  for (const Cell& c : cells) extend(c.min), extend({c.min[0] + c.size, c.min[1] + c.size, c.min[2] + c.size});
  Vec3 offset{0, 0, 0};
  for (int i = 0; i < 3; ++i)
    if (lo[i] <= hi[i]) offset[i] = 0.5 * (lo[i] + hi[i]);

  auto rel = [&](const Vec3& p, int i) { return float(p[i] - offset[i]); };
  std::vector<float> positions, cell_data, points;
  positions.reserve(mesh.positions.size() * 3);
  for (const Vec3& p : mesh.positions)
    for (int i = 0; i < 3; ++i) positions.push_back(rel(p, i));
  std::vector<uint32_t> indices;
  indices.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) indices.insert(indices.end(), t.begin(), t.end());
  for (const Cell& c : cells) {
    for (int i = 0; i < 3; ++i) cell_data.push_back(rel(c.min, i));
    cell_data.push_back(float(c.size));
    for (int i = 0; i < 3; ++i) points.push_back(rel(c.vertex, i));
  }
  if (!tree) points = positions;  // no tree: the toggle shows the mesh vertices

  std::string data = "{\"info\":";
  append_json_string(data, info_json);
  data += ",\"offset\":[";
  for (int i = 0; i < 3; ++i) {
    if (i) data += ',';
    append_number(data, offset[i]);
  }
  data += "],\"positions\":\"";
  append_base64(data, positions);
  data += "\",\"indices\":\"";
  append_base64(data, indices);
  data += "\",\"cells\":\"";
  append_base64(data, cell_data);
  data += "\",\"points\":\"";
  append_base64(data, points);
  data += "\"}";

  // The bundle is inlined; a "</script" inside it would end the element early. esbuild
  // escapes that in strings, and this guards the rest.
  std::string bundle = kViewerBundle;
  for (size_t at = 0; (at = bundle.find("</script", at)) != std::string::npos;)
    bundle.replace(at, 2, "<\\/");

  std::string html;
  html.reserve(data.size() + bundle.size() + 2048);
  html +=
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      "<title>PIC viewer</title>\n<style>\n"
      "html, body { margin: 0; height: 100%; overflow: hidden; background: #fafafc;\n"
      "  font: 13px/1.4 system-ui, sans-serif; color: #1e2230; }\n"
      "canvas { display: block; }\n"
      "#ui, #stats { position: fixed; top: 10px; background: rgba(255,255,255,0.85);\n"
      "  border: 1px solid #d0d4dc; border-radius: 6px; padding: 8px 10px; margin: 0; }\n"
      "#ui { left: 10px; } #ui label { display: block; cursor: pointer; }\n"
      "#ui .title { font-weight: 600; margin-bottom: 4px; } #ui .counts { color: #606878; margin-top: 4px; }\n"
      "#stats { right: 10px; max-height: calc(100% - 40px); max-width: 40%; overflow: auto;\n"
      "  font: 12px/1.35 ui-monospace, monospace; }\n"
      "#stats:empty { display: none; }\n"
      ".error { position: fixed; top: 45%; width: 100%; text-align: center; color: #a02020; }\n"
      "</style>\n</head>\n<body>\n<script id=\"pic-data\" type=\"application/json\">";
  html += data;
  html += "</script>\n<script>\n";
  html += bundle;
  html += "\n</script>\n</body>\n</html>\n";
  return html;
}

}  // namespace pic
