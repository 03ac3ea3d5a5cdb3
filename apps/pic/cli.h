// What the subcommands of `pic` share: JSON output, argument parsing, reading any input.
// Each subcommand lives in its own file and registers itself with add_<name>(app).
#pragma once

#include <CLI/CLI.hpp>

#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "pic/fields.h"
#include "pic/pic.h"

namespace pic::cli {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0);

/// A message on stderr when it is a terminal (never in scripts' output).
void progress(const std::string& msg);

/// %.9g, or null for a non-finite number.
std::string num(double v);

/// Minimal JSON object writer: keys in insertion order.
class Json {
 public:
  Json& add(const std::string& k, double v) { return raw(k, num(v)); }
  Json& add(const std::string& k, size_t v) { return raw(k, std::to_string(v)); }
  Json& add(const std::string& k, uint32_t v) { return raw(k, std::to_string(v)); }
  Json& add(const std::string& k, int v) { return raw(k, std::to_string(v)); }
  Json& add(const std::string& k, bool v) { return raw(k, v ? "true" : "false"); }
  Json& add(const std::string& k, const std::string& v) { return raw(k, quote(v)); }
  Json& add(const std::string& k, const char* v) { return raw(k, quote(v)); }
  Json& raw(const std::string& k, const std::string& v);
  /// Every field of a stats struct (pic/fields.h); nested structs become nested objects.
  template <class S>
  Json& fields(const S& stats) {
    for_each_field(stats, [&](const char* name, const auto& value) {
      if constexpr (HasFields<std::decay_t<decltype(value)>>) raw(name, Json().fields(value).str());
      else add(name, value);
    });
    return *this;
  }
  std::string str() const { return "{" + s_ + "}"; }
  static std::string quote(const std::string& v);

 private:
  std::string s_;
};

std::string vec_json(const Vec3& v);
std::string cube_json(const Cube& c);
std::string topology_json(const MeshTopology& t);
/// "closed manifold", "closed, NOT manifold" or "NOT closed".
std::string topology_words(const MeshTopology& t);
/// A written mesh's validity (pic/fields.h); self_intersections is null when not checked.
Json& add_validity(Json& j, const MeshValidity& v);

/// The output was written, but it is not a valid solid (exit code 4).
class InvalidOutput : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
/// What is known of a written mesh's validity: its topology, and the exact self-intersecting
/// pairs when someone counted them (the intersection-free contour does; --json's check does).
struct WrittenMesh {
  std::string path;
  MeshTopology topology;
  std::optional<size_t> self_intersections;
};
/// Throws InvalidOutput naming the file and the counts that are off, unless it is closed,
/// 2-manifold and (where counted) free of self-intersections.
void require_valid(const WrittenMesh& m);
/// Crossings known without the exact test: 0 for the intersection-free construction, none
/// (unknown) for the plain split.
std::optional<size_t> known_crossings(const ContourOptions& o);

/// A contour written to a file, with what the CLI reports of it.
struct ContourFile {
  TriMesh mesh;
  ContourStats stats;
  double seconds = 0;  ///< contouring only, not writing
  WrittenMesh written;
};
/// Contours `tree` with options `o` and writes the mesh to `path`.
ContourFile write_contour(const Octree& tree, const std::string& path, const ContourOptions& o);
/// Writes a contour made with options `o` (f.mesh) to `path`, filling f.written.
void write_contoured(ContourFile& f, const std::string& path, const ContourOptions& o);

/// `pic info` as JSON and as a table.
std::string info_json(const Octree& tree, size_t file_bytes);
void print_info_table(const Octree& tree, size_t file_bytes);

/// `n` comma-separated finite numbers. \throws InvalidInput naming `what`.
std::vector<double> parse_numbers(const std::string& s, size_t n, const std::string& what);
/// --cube X,Y,Z,SIZE.
Cube parse_cube(const std::string& s);
/// The sampling flags every sampling command takes: --depth, --error, --serial, --cube (may be
/// empty: the input's own cube).
SampleOptions sample_options(int depth, double error, bool serial, const std::string& cube);

/// Lower-case extension with its dot ("" when none).
std::string extension(const std::string& path);
bool is_pic_path(const std::string& path);
/// Whether `path` names a mesh format (written by contouring) rather than a .pic file.
bool is_mesh_path(const std::string& path);
/// Loads a .pic, or samples a mesh or point cloud file with default options at `depth`;
/// `surface` (optional) gets its contour before sheets are split.
Octree load_any(const std::string& path, int depth, TriMesh* surface);

void add_sample(CLI::App& app);
void add_mesh(CLI::App& app);
void add_info(CLI::App& app);
void add_csg(CLI::App& app);
void add_eval(CLI::App& app);
void add_prim(CLI::App& app);
void add_render(CLI::App& app);
void add_view(CLI::App& app);
void add_compare(CLI::App& app);
void add_volume(CLI::App& app);

}  // namespace pic::cli
