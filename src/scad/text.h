// OpenSCAD's text(): glyph outlines of a string through fontconfig (font by name), HarfBuzz
// (shaping: kerning, ligatures, right-to-left and vertical text) and FreeType (outlines),
// flattened as OpenSCAD flattens them (text.cpp).
#pragma once

#include <string>

#include "scad/region.h"

namespace pic::detail::scad {

struct TextParams {
  std::string text;
  double size = 10;
  std::string font;  // fontconfig pattern, e.g. "Liberation Sans:style=Bold"; empty: Liberation Sans
  std::string halign = "left", valign = "baseline";
  double spacing = 1;
  std::string direction;  // ltr, rtl, ttb, btt; empty: from the script
  std::string language = "en", script;
  int segments = 1;  // straight pieces per curve of the outline
};

/// The text's region, in model units. \throws InvalidInput when the font cannot be found.
Region text_region(const TextParams& p);

}  // namespace pic::detail::scad
