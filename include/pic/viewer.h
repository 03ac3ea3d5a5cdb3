// `pic view`: one self-contained HTML page showing a mesh (and optionally an octree) in 3D.
#pragma once

#include <string>

#include "pic/octree.h"

namespace pic {

/// Returns a complete HTML page: three.js (bundled into the library at build time), orbit
/// controls, the mesh flat shaded, checkboxes for the gray leaves' cell edges and the
/// representative vertices (the mesh vertices if `tree` is null), and a panel showing
/// `info_json` pretty-printed (shown as plain text if it is not valid JSON). The page needs
/// no network and no other file. Geometry is embedded as base64 little-endian arrays in a
/// `<script id="pic-data" type="application/json">` block; coordinates are stored as floats
/// relative to the bounding box centre.
/// \throws InvalidInput if a triangle index is out of range.
std::string view_html(const TriMesh& mesh, const Octree* tree, const std::string& info_json);

}  // namespace pic
