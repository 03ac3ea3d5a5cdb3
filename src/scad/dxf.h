// OpenSCAD's import() of a DXF drawing (dxf.cpp): LINE, LWPOLYLINE, POLYLINE, CIRCLE, ARC,
// ELLIPSE and block INSERTs, joined end to end into closed rings.
#pragma once

#include <filesystem>
#include <string>

#include "scad/region.h"

namespace pic::detail::scad {

struct DxfImport {
  std::string layer;       // empty: every layer
  P2 origin{0, 0};         // subtracted from every point, before scaling
  double scale = 1;
  double fn = 0, fs = 2, fa = 12;  // circle and arc fragments, as for circle()
};

/// The drawing's rings, filled by the even-odd rule (a chain that does not close is closed).
/// \throws IoError when unreadable, InvalidInput when malformed.
Region read_dxf(const std::filesystem::path& path, const DxfImport& how);

}  // namespace pic::detail::scad
