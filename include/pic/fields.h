// PIC — the statistics structs, field by field: one list per struct, in the order the CLI's
// JSON prints them. The CLI's `--json` objects and the Python module's stats dicts are both
// generated from these lists, so a field added here appears in both.
//
//   for_each_field(stats, [](const char* name, const auto& value) { ... });
//
// `value` is a number, a bool, a std::string, or a nested struct (MeshDefects) that has a
// for_each_field of its own (see HasFields).
#pragma once

#include "pic/contour.h"
#include "pic/csg.h"
#include "pic/measure.h"
#include "pic/sample.h"
#include "pic/scad.h"

namespace pic {

template <class F>
void for_each_field(const MeshDefects& d, F&& f) {
  f("boundary_edges", d.boundary_edges);
  f("nonmanifold_edges", d.nonmanifold_edges);
  f("inconsistent_edges", d.inconsistent_edges);
  f("duplicated_faces", d.duplicated_faces);
  f("degenerate_faces", d.degenerate_faces);
  f("shells", d.shells);
  f("overlapping_shells", d.overlapping_shells);
}

template <class F>
void for_each_field(const SampleStats& s, F&& f) {
  f("pics", s.pics);
  f("seconds", s.seconds);
  f("depth", s.max_depth);
  f("error", s.error);
  f("triangles_in", s.triangles_in);
  f("capped", s.capped);
  f("points_in", s.points_in);
  f("depth_used", s.depth);
  f("inside", s.classifier);
  f("defects", s.defects);
  f("interior_triangles", s.interior_triangles);
  f("boundary_loops", s.boundary_loops);
}

template <class F>
void for_each_field(const ContourStats& s, F&& f) {
  f("split_vertices", s.split_vertices);
  f("fans", s.fans);
  f("other_diagonal", s.other_diagonal);
  f("face_points", s.face_points);
  f("moved_vertices", s.moved_vertices);
  f("initial_intersections", s.initial_intersections);
  f("remaining_intersections", s.remaining_intersections);
  f("rounds", s.rounds);
}

template <class F>
void for_each_field(const CsgStats& s, F&& f) {
  f("seconds", s.seconds);
  f("contour_a_seconds", s.contour_a_seconds);
  f("contour_b_seconds", s.contour_b_seconds);
  f("csg_seconds", s.csg_seconds);
  f("cleanup_seconds", s.cleanup_seconds);
  f("cells_visited", s.cells_visited);
  f("cells_stamped", s.cells_stamped);
  f("gray_pairs", s.gray_pairs);
  f("forced_subdivisions", s.forced_subdivisions);
  f("repaired", s.repaired);
  f("thin_points", s.thin_points);
  f("stamp", s.stamp);
  f("resampled_b", s.resampled_b);
}

template <class F>
void for_each_field(const EvalStats& s, F&& f) {
  f("seconds", s.seconds);
  f("openscad_seconds", s.openscad_seconds);
  f("mesh_seconds", s.mesh_seconds);
  f("octree_seconds", s.octree_seconds);
  f("nodes", s.nodes);
  f("leaves", s.leaves);
  f("leaf_triangles", s.triangles);
  f("booleans", s.booleans);
  f("thin_points", s.thin_points);
}

/// Validity of a written mesh: the exact self-intersection count (absent when not checked),
/// non-manifold vertices and edges, components.
template <class F>
void for_each_field(const MeshValidity& v, F&& f) {
  if (v.checked) f("self_intersections", v.self_intersections);
  f("nonmanifold_vertices", v.nonmanifold_vertices);
  f("nonmanifold_edges", v.nonmanifold_edges);
  f("components", v.components);
}

/// Whether T is one of the structs above.
template <class T>
concept HasFields = requires(const T& t) { for_each_field(t, [](const char*, const auto&) {}); };

}  // namespace pic
