// The lowering of a parsed .csg tree (lower.h), private to src/scad/: the affine maps and the
// readers of node arguments it shares, and the Lowering walk, whose members are defined by
// concern: lower.cpp (the 3D tree: Booleans, hull, minkowski, resize), lower_args.cpp
// (arguments, fragments, files), lower_primitives.cpp (3D primitives), lower_2d.cpp (2D
// subtrees), lower_extrude.cpp (extrusions and moving solids).
#pragma once

#include <array>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "scad/lower.h"
#include "scad/region.h"
#include "scad/scad_detail.h"

namespace pic::detail::scad {

// Node here is scad's parsed node (scad_detail.h), not pic::Node (an octree cell).

// Row-major 3x4 affine map.
using Affine = std::array<double, 12>;
inline constexpr Affine kIdentity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
// 2D affine map [a b tx; c d ty].
using Affine2 = std::array<double, 6>;
inline constexpr Affine2 kIdentity2{1, 0, 0, 0, 1, 0};

// Affine maps (lower_args.cpp).
Affine compose(const Affine& a, const Affine& b);  // a * b
Affine2 compose2(const Affine2& a, const Affine2& b);
double det3(const Affine& m);
double stretch(const Affine& m);
double stretch2(const Affine2& m);
void apply(const Affine& m, TriMesh& mesh);
Ring apply2(const Affine2& m, const Ring& r);
Region apply2(const Affine2& m, const Region& r);

// A node's arguments (lower_args.cpp).
[[noreturn]] void fail(const Node& n, const std::string& what);
const Value* arg(const Node& n, const std::string& key);
double number(const Node& n, const std::string& key, double fallback);
bool flag(const Node& n, const std::string& key, bool fallback);
std::vector<double> numbers(const Node& n, const Value& v, const std::string& key);
void check_finite(const Node& n, std::initializer_list<double> xs);
bool is_2d_node(const std::string& s);
bool is_group(const std::string& s);

class Lowering {
 public:
  Lowering(const EvalOptions& o, double finest_cell) : opt_(o), cell_(finest_cell) {}
  size_t nodes = 0;

  Region region(const Node& n) { return shape(n, kIdentity2); }

  Solid solid(const Node& n, const Affine& m);

 private:
  const EvalOptions& opt_;
  double cell_;  // finest cell, for --smooth

  // The 3D tree (lower.cpp).
  std::vector<Solid> children3(const Node& n, const Affine& m);
  static Solid combine(Solid::Kind kind, std::vector<Solid> kids);
  static Solid leaf(TriMesh mesh, const Affine& m);
  std::array<double, 3> resize_factors(const Node& n, const std::array<double, 3>& size, int dims) const;

  // Arguments, fragments, files (lower_args.cpp).
  int frags(const Node& n, double r, double st) const;
  Affine matrix(const Node& n) const;
  double radius(const Node& n, const char* r, const char* d, double fallback) const;
  std::filesystem::path file_arg(const Node& n) const;
  bool missing(const Node& n, const std::filesystem::path& p) const;
  /// Warns that node n is left out of the model (as OpenSCAD leaves it out) and why.
  void left_out(const Node& n, const std::string& why) const;

  // 3D primitives (lower_primitives.cpp).
  TriMesh cube(const Node& n) const;
  TriMesh cylinder(const Node& n, double st);
  TriMesh polyhedron(const Node& n) const;
  TriMesh import(const Node& n) const;

  // 2D subtrees (lower_2d.cpp).
  Region shape(const Node& n, const Affine2& m);
  Region minkowski_2d(const Node& n, const Affine2& m);
  void convex_parts_2d(const Node& n, const Affine2& m, std::vector<Ring>& out);
  std::vector<Region> children2(const Node& n, const Affine2& m);
  std::vector<Ring> polygon_rings(const Node& n) const;
  Region offset(const Node& n, const Affine2& m);
  Region import_2d(const Node& n) const;
  Region text(const Node& n, double st) const;

  // Extrusions and moving solids (lower_extrude.cpp).
  template <class Extrude>
  Solid extrude(const Region& region, const Extrude& ext);
  Region shape_children(const Node& n, double st);
  double stretch_3d_ = 1;
  Solid linear_extrude(const Node& n, const Affine& m);
  Solid rotate_extrude(const Node& n, const Affine& m);
  static std::pair<double, double> x_range(const Region& r);
  static void transform(Solid& s, const Affine& m);
};

}  // namespace pic::detail::scad
