// OpenSCAD's import() of an SVG drawing (svg.cpp): path, rect, circle, ellipse, polygon and
// polyline elements, with group and element transforms, filled and united.
#pragma once

#include <filesystem>

#include "scad/region.h"

namespace pic::detail::scad {

/// The drawing's filled region in millimetres, y up: user units through the viewBox and the
/// document size (px at `dpi`, or mm/cm/in/pt/pc), y flipped about the document's height, as
/// OpenSCAD 2021 imports it. \throws IoError when unreadable, InvalidInput when malformed.
Region read_svg(const std::filesystem::path& path, double dpi = 72);

}  // namespace pic::detail::scad
