// Helpers the subcommands share: see cli.h.
#include "cli.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

namespace pic::cli {

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void progress(const std::string& msg) {
  if (::isatty(2) != 0) std::cerr << "pic: " << msg << "\n";
}

std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

Json& Json::raw(const std::string& k, const std::string& v) {
  s_ += (s_.empty() ? "" : ", ") + quote(k) + ": " + v;
  return *this;
}

std::string Json::quote(const std::string& v) {
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

std::string vec_json(const Vec3& v) { return "[" + num(v[0]) + ", " + num(v[1]) + ", " + num(v[2]) + "]"; }

std::string cube_json(const Cube& c) { return Json().raw("origin", vec_json(c.origin)).add("size", c.size).str(); }

std::string topology_json(const MeshTopology& t) {
  return Json()
      .add("closed", t.closed())
      .add("manifold", t.manifold())
      .add("boundary_edges", t.boundary_edges)
      .add("nonmanifold_edges", t.nonmanifold_edges)
      .add("nonmanifold_vertices", t.nonmanifold_vertices)
      .str();
}

std::string topology_words(const MeshTopology& t) {
  return t.manifold() ? "closed manifold" : t.closed() ? "closed, NOT manifold" : "NOT closed";
}

Json& add_validity(Json& j, const MeshValidity& v) {
  if (!v.checked) j.raw("self_intersections", "null");
  return j.fields(v);
}

void require_valid(const WrittenMesh& m) {
  std::string off;
  auto count = [&](size_t n, const char* what) {
    if (n) off += (off.empty() ? "" : ", ") + std::to_string(n) + " " + what;
  };
  count(m.topology.boundary_edges, "boundary edges");
  count(m.topology.nonmanifold_edges, "non-manifold edges");
  count(m.topology.nonmanifold_vertices, "non-manifold vertices");
  count(m.topology.inconsistent_edges, "inconsistently oriented edges");
  if (m.self_intersections) count(*m.self_intersections, "self-intersecting triangle pairs");
  if (!off.empty()) throw InvalidOutput(m.path + " was written but is not a valid solid: " + off);
}

std::optional<size_t> known_crossings(const ContourOptions& o) {
  if (!o.intersection_free) return std::nullopt;
  return 0;  // by construction
}

ContourFile write_contour(const Octree& tree, const std::string& path, const ContourOptions& o) {
  ContourFile f;
  const auto t0 = Clock::now();
  f.mesh = contour(tree, o, &f.stats);
  f.seconds = since(t0);
  write_contoured(f, path, o);
  return f;
}

void write_contoured(ContourFile& f, const std::string& path, const ContourOptions& o) {
  // What the file will hold: the checks after this count the file's crossings, not those of
  // positions it cannot store.
  if (stores_float32(path)) f.mesh = round_to_float32(f.mesh);
  write_mesh(f.mesh, path);
  // An STL file has no shared vertices: a reader merges equal positions.
  const bool welded = extension(path) == ".stl";
  f.written = {path, welded ? analyze_welded_topology(f.mesh) : analyze_topology(f.mesh), known_crossings(o)};
}

std::string info_json(const Octree& tree, size_t file_bytes) {
  const auto s = analyze(tree);
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
      .raw("cube", cube_json(tree.cube))
      .raw("bbox", Json().raw("min", vec_json(s.bbox_min)).raw("max", vec_json(s.bbox_max)).str())
      .raw("levels", levels);
  return j.str();
}

void print_info_table(const Octree& tree, size_t file_bytes) {
  const auto s = analyze(tree);
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
      throw InvalidInput(what + ": '" + item + "' is not a number");
    }
  }
  if (out.size() != n) throw InvalidInput(what + " needs " + std::to_string(n) + " comma-separated numbers");
  for (double x : out)
    if (!std::isfinite(x)) throw InvalidInput(what + " must be finite");
  return out;
}

Cube parse_cube(const std::string& s) {
  const auto v = parse_numbers(s, 4, "--cube X,Y,Z,SIZE");
  if (!(v[3] > 0)) throw InvalidInput("--cube SIZE must be positive");
  return Cube{{v[0], v[1], v[2]}, v[3]};
}

SampleOptions sample_options(int depth, double error, bool serial, const std::string& cube) {
  SampleOptions o;
  o.depth = depth;
  o.error = error;
  o.parallel = !serial;
  if (!cube.empty()) o.cube = parse_cube(cube);
  return o;
}

std::string extension(const std::string& path) {
  const auto dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool is_pic_path(const std::string& path) { return extension(path) == ".pic"; }

bool is_mesh_path(const std::string& path) {
  const std::string ext = extension(path);
  return ext == ".obj" || ext == ".stl" || ext == ".ply" || ext == ".off" || ext == ".glb" || ext == ".gltf";
}

Octree load_any(const std::string& path, int depth, TriMesh* surface) {
  Octree t;
  if (is_pic_path(path)) {
    t = load(path);
  } else {
    SampleOptions o;
    o.depth = depth;
    const Geometry geo = read_geometry(path);
    t = geo.is_point_cloud() ? sample(geo.points, o) : sample(geo.mesh, o);
  }
  if (surface) *surface = unsplit_contour(t);
  return t;
}

}  // namespace pic::cli
