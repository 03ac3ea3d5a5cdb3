// surface(): a height map (.dat text matrix, or a PNG's luminance) as OpenSCAD 2021 builds it,
// measured on its exports: grid point (column j, row i) at (j, i, height), rows of an image
// counted from its bottom; each cell cut into 4 triangles through its centre at the mean
// height; walls down to a flat bottom 1 below the lowest height.
#include <png.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "io/file_util.h"
#include "scad/lower.h"
#include "geometry/tolerances.h"

namespace pic::detail::scad {
namespace {

std::vector<std::vector<double>> read_dat(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw IoError("cannot read " + path.string());
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);) {
    const size_t start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream ss(line);
    std::vector<double> row;
    for (std::string w; ss >> w;) {
      char* end = nullptr;
      const double v = std::strtod(w.c_str(), &end);
      if (*end != '\0' || !std::isfinite(v)) throw InvalidInput(path.string() + ": bad height '" + w + "'");
      row.push_back(v);
    }
    if (!row.empty()) rows.push_back(std::move(row));
  }
  return rows;
}

std::vector<std::vector<double>> read_png(const std::filesystem::path& path, bool invert) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path.c_str()))
    throw InvalidInput(path.string() + ": cannot read PNG (" + std::string(img.message) + ")");
  img.format = PNG_FORMAT_RGB;
  std::vector<png_byte> px(PNG_IMAGE_SIZE(img));
  if (!png_image_finish_read(&img, nullptr, px.data(), 0, nullptr))
    throw InvalidInput(path.string() + ": cannot read PNG (" + std::string(img.message) + ")");
  std::vector<std::vector<double>> rows(img.height, std::vector<double>(img.width));
  for (png_uint_32 r = 0; r < img.height; ++r)
    for (png_uint_32 c = 0; c < img.width; ++c) {
      const png_byte* p = &px[3 * (size_t(r) * img.width + c)];
      const double h = 100 * (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255;
      rows[img.height - 1 - r][c] = invert ? 100.0 / 255 - h : h;  // row 0 is the image's bottom
    }
  return rows;
}

}  // namespace

TriMesh surface_mesh(const std::filesystem::path& path, bool center, bool invert) {
  const std::string ext = lower_extension(path);
  const auto h = ext == ".png" ? read_png(path, invert) : read_dat(path);
  const size_t rows = h.size(), cols = rows ? h[0].size() : 0;
  for (const auto& r : h)
    if (r.size() != cols) throw InvalidInput(path.string() + ": rows of different lengths");
  TriMesh m;
  if (rows < 2 || cols < 2) return m;
  double lo = kHuge;
  for (const auto& r : h)
    for (double v : r) lo = std::min(lo, v);
  const double bottom = lo - 1;
  const double ox = center ? -(double(cols) - 1) / 2 : 0, oy = center ? -(double(rows) - 1) / 2 : 0;
  // Top grid, bottom grid, then the cell centres.
  const auto top = [&](size_t i, size_t j) { return uint32_t(i * cols + j); };
  const auto low = [&](size_t i, size_t j) { return uint32_t(rows * cols + i * cols + j); };
  for (int layer = 0; layer < 2; ++layer)
    for (size_t i = 0; i < rows; ++i)
      for (size_t j = 0; j < cols; ++j) m.positions.push_back({ox + double(j), oy + double(i), layer ? bottom : h[i][j]});
  for (size_t i = 0; i + 1 < rows; ++i)
    for (size_t j = 0; j + 1 < cols; ++j) {
      const uint32_t c = uint32_t(m.positions.size());
      m.positions.push_back({ox + double(j) + 0.5, oy + double(i) + 0.5,
                             (h[i][j] + h[i][j + 1] + h[i + 1][j] + h[i + 1][j + 1]) / 4});
      const uint32_t a = top(i, j), b = top(i, j + 1), d = top(i + 1, j + 1), e = top(i + 1, j);
      m.triangles.insert(m.triangles.end(), {{a, b, c}, {b, d, c}, {d, e, c}, {e, a, c}});
      m.triangles.push_back({low(i, j), low(i + 1, j + 1), low(i, j + 1)});
      m.triangles.push_back({low(i, j), low(i + 1, j), low(i + 1, j + 1)});
    }
  // Walls along the border, walked counter-clockwise seen from above.
  const auto wall = [&](size_t i0, size_t j0, size_t i1, size_t j1) {
    m.triangles.push_back({top(i1, j1), top(i0, j0), low(i0, j0)});
    m.triangles.push_back({top(i1, j1), low(i0, j0), low(i1, j1)});
  };
  for (size_t j = 0; j + 1 < cols; ++j) wall(0, j, 0, j + 1);
  for (size_t i = 0; i + 1 < rows; ++i) wall(i, cols - 1, i + 1, cols - 1);
  for (size_t j = cols - 1; j > 0; --j) wall(rows - 1, j, rows - 1, j - 1);
  for (size_t i = rows - 1; i > 0; --i) wall(i, 0, i - 1, 0);
  return m;
}

}  // namespace pic::detail::scad
