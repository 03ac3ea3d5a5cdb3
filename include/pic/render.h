// Pictures of PIC objects: a headless software renderer and PNG output.
//
// Conventions: +Z is up (CAD convention). "front" looks along +Y (eye on the -Y side),
// "right" looks along -X, "top" looks down along -Z; "iso" looks from the front-right-top
// corner (+X, -Y, +Z).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "pic/measure.h"
#include "pic/octree.h"

namespace pic {

struct RenderOptions {
  int width = 1024, height = 1024;
  /// iso | front | back | left | right | top | bottom
  std::string view = "iso";
  /// Eye xyz, target xyz, up xyz; overrides `view`. Perspective uses the eye as given;
  /// orthographic uses the direction and up, and centres on the target only together with
  /// `ortho_half_extent` (otherwise it frames the object).
  std::optional<std::array<double, 9>> camera;
  /// Perspective projection (30 degree vertical field of view) instead of orthographic.
  bool perspective = false;
  /// Orthographic only: world distance from the image centre to the nearer image border,
  /// i.e. min(width, height) / 2 pixels == ortho_half_extent world units, and the view is
  /// centred on the bounding box centre. Default: frame the bounding box with a small margin.
  /// Tests use it to know the pixel scale exactly.
  std::optional<double> ortho_half_extent;
  /// Draw the edges of gray leaves' cells as thin dark lines (hidden ones are not drawn).
  bool octree = false;
  /// Draw representative vertices (or the mesh vertices if there is no tree) as red dots.
  bool points = false;
  /// Draw the triangles that cross another one (pic::self_intersecting_pairs, exact) in red:
  /// crossings are usually far below a pixel, this shows where they are.
  bool highlight_crossings = false;
  /// Supersampling factor per axis (1 = none). 2 gives smooth edges at 4x the pixels.
  int supersample = 2;
};

/// 8-bit RGB, row-major, top row first.
struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  /// Orthographic views: output pixels per world unit (0 for perspective views).
  double pixels_per_unit = 0;
};

/// The flat background colour of rendered images.
inline constexpr std::array<uint8_t, 3> kRenderBackground{250, 250, 252};

/// Renders `mesh` (flat shaded) and optionally `tree`'s cells / vertices. `tree` may be null.
/// \throws InvalidInput for a non-positive size, an unknown view or a degenerate camera.
Image render(const TriMesh& mesh, const Octree* tree, const RenderOptions& opt);

/// Writes a PNG atomically (temp file + rename), so a failed write leaves any existing
/// file untouched. \throws IoError if the file cannot be written.
void write_png(const Image& img, const std::filesystem::path& path);

}  // namespace pic
