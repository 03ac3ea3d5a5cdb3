// PIC — the value types every stage shares: points, meshes, point clouds, the root cube, errors.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace pic {

using Vec3 = std::array<double, 3>;

/// @name Errors thrown at the library boundary.
///@{
/// Bad user input: a malformed mesh, an open mesh, NaN coordinates, bad options.
class InvalidInput : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};
/// An operation whose result has no surface in its cube: nothing (or everything) inside.
class EmptySolid : public InvalidInput {
 public:
  using InvalidInput::InvalidInput;
};
/// A file could not be read or written, or a .pic file is corrupted / foreign.
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
///@}

/// Indexed triangle mesh, counter-clockwise triangles seen from outside.
struct TriMesh {
  std::vector<Vec3> positions;
  std::vector<std::array<uint32_t, 3>> triangles;
};

/// An oriented point cloud (a scan): one normal per point, pointing out of the solid.
struct PointCloud {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  ///< same length as positions (need not be unit length)
};

/// The root cube: minimum corner and side length, in the input's own coordinates.
struct Cube {
  Vec3 origin{0, 0, 0};
  double size = 1.0;
  friend bool operator==(const Cube&, const Cube&) = default;
};

}  // namespace pic
