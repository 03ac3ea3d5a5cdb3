// OpenSCAD models in: the CSG tree that `openscad -o x.csg` exports, evaluated on PIC octrees
// (docs/openscad.md). Curved primitives are tessellated by OpenSCAD's own rules ($fn, $fa, $fs),
// every leaf is sampled into one root cube around the whole model, and the Booleans run on the
// octrees bottom-up.
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "pic/octree.h"

namespace pic {

struct EvalOptions {
  int depth = 12;          ///< maximum octree level, 1..kMaxLevel
  double error = 1e-8;     ///< QEF residual threshold (as SampleOptions::error)
  /// Tessellate spheres, cylinders, cones and circles so finely that the chord error is at most
  /// `smooth_chord` finest cells, instead of by $fn/$fa/$fs. The sampler takes meshes only, so
  /// this is a very fine tessellation, not an exact curved surface.
  bool smooth = false;
  double smooth_chord = 0.05;
  bool parallel = true;    ///< independent subtrees and sampling with TBB
  /// Directory that `import(file = ...)` paths are relative to; default: the .csg file's own.
  std::filesystem::path base_dir;
  /// Called now and then with a one-line progress message (may be empty: silent).
  std::function<void(const std::string&)> progress;
  /// Called with each warning where OpenSCAD warns and goes on (an `import()` of a file that
  /// does not exist is an empty object, as in OpenSCAD); may be empty: silent.
  std::function<void(const std::string&)> warning;
};

struct EvalStats {
  size_t nodes = 0;        ///< nodes in the .csg tree
  size_t leaves = 0;       ///< closed meshes sampled
  size_t triangles = 0;    ///< triangles of all leaves
  size_t booleans = 0;     ///< octree Booleans
  size_t thin_points = 0;  ///< lattice points the Booleans gave a sub-cell wall's sign (CsgStats)
  double openscad_seconds = 0;  ///< `openscad -o x.csg` (for .scad input)
  double mesh_seconds = 0;      ///< parse, tessellate, extrude, hull
  double octree_seconds = 0;    ///< sampling plus Booleans (wall clock)
  double seconds = 0;           ///< total wall clock
  Cube cube;
};

/// The result of a 2D model: closed outlines that do not cross, outer boundaries
/// counter-clockwise and holes clockwise.
struct Outline {
  std::vector<std::vector<std::array<double, 2>>> rings;
};
/// Enclosed area (holes subtracted).
double area(const Outline& outline);
/// Writes an outline as SVG or DXF (by the extension), through a temporary file.
/// \throws InvalidInput for another extension, IoError when it cannot be written.
void write_outline(const Outline& outline, const std::filesystem::path& path);

/// Evaluates OpenSCAD CSG-tree text (the .csg format). `source` names it in error messages.
/// \throws InvalidInput for a syntax error or an unsupported node (the message names the node
///         and its line), or an empty model; IoError for an unreadable import.
Octree eval_csg(const std::string& text, const EvalOptions& options = {}, EvalStats* stats = nullptr,
                const std::string& source = "input");
/// Reads and evaluates a .csg file. \throws as eval_csg, IoError when unreadable.
Octree eval_csg_file(const std::filesystem::path& path, const EvalOptions& options = {},
                     EvalStats* stats = nullptr);
/// A .scad file is exported to .csg by the `openscad` program (a temporary file), then evaluated
/// with imports relative to the .scad file; a .csg file is evaluated directly.
/// \throws InvalidInput when `openscad` is missing or rejects the file; as eval_csg_file.
Octree eval_scad(const std::filesystem::path& path, const EvalOptions& options = {},
                 EvalStats* stats = nullptr);
/// A 2D model (.scad or .csg; one whose top level holds 2D objects only): its outline, as
/// OpenSCAD's `-o out.svg` computes it. nullopt for a 3D model (eval_scad of a 2D model throws).
std::optional<Outline> eval_outline(const std::filesystem::path& path, const EvalOptions& options = {},
                                    EvalStats* stats = nullptr);

}  // namespace pic
