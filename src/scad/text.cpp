// text(): see text.h.
#include "scad/text.h"
#include "geometry/tolerances.h"

#include <fontconfig/fontconfig.h>
#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_OUTLINE_H
#include <hb-ft.h>
#include <hb.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <string>
#include <vector>


namespace pic::detail::scad {
namespace {

// OpenSCAD 2021's scale, measured on its exports (Liberation Sans, size 10): the em square is
// size * 100 / 72 model units (a font size in points at 100 dpi), and the pen advances by
// 1000 / 1024 of the glyphs' advance widths at that scale.
constexpr double kEmPerSize = 100.0 / 72.0;
constexpr double kAdvanceScale = 1000.0 / 1024.0;
// Vertical text is placed by FreeType's vertical metrics at the size OpenSCAD sets (1000 times
// the text's size in 26.6 points at 100 dpi); HarfBuzz's positions are then 26.6 pixels, 1024
// of them a model unit.
constexpr double kCharSizeScale = 1000;
constexpr double kPositionUnit = 1024;

// fontconfig's configuration, loaded once and released at exit (its default global one, from
// FcInit, is never released).
class FontConfig {
 public:
  FontConfig() : config_(FcInitLoadConfigAndFonts()) {}
  ~FontConfig() {
    if (config_) FcConfigDestroy(config_);
  }
  FontConfig(const FontConfig&) = delete;
  FontConfig& operator=(const FontConfig&) = delete;

  // The file of the font that best matches a fontconfig pattern ("Liberation Sans:style=Bold").
  std::string match(const std::string& pattern) {
    const std::lock_guard<std::mutex> guard(lock_);  // a configuration is not thread-safe
    if (!config_) throw InvalidInput("text: fontconfig could not load its configuration");
    FcPattern* pat = FcNameParse(reinterpret_cast<const FcChar8*>(pattern.c_str()));
    if (!pat) throw InvalidInput("text: bad font name '" + pattern + "'");
    FcConfigSubstitute(config_, pat, FcMatchPattern);
    FcDefaultSubstitute(pat);
    FcResult result;
    FcPattern* found = FcFontMatch(config_, pat, &result);
    FcPatternDestroy(pat);
    std::string file;
    FcChar8* path = nullptr;
    if (found && FcPatternGetString(found, FC_FILE, 0, &path) == FcResultMatch) file = reinterpret_cast<const char*>(path);
    if (found) FcPatternDestroy(found);
    if (file.empty()) throw InvalidInput("text: no font matches '" + pattern + "' (install fonts-liberation2)");
    return file;
  }

 private:
  FcConfig* config_;
  std::mutex lock_;
};

std::string font_file(const std::string& pattern) {
  static FontConfig fonts;
  return fonts.match(pattern.empty() ? "Liberation Sans" : pattern);
}

// Collects a glyph's outline as rings, each curve cut into `segments` straight pieces.
struct OutlineSink {
  std::vector<Ring> rings;
  double unit = 1;  // model units per 26.6 outline unit
  double dx = 0, dy = 0;
  int segments = 1;
  P2 last{0, 0};

  P2 at(const FT_Vector* v) const { return {dx + v->x * unit, dy + v->y * unit}; }
  void add(const P2& p) {
    rings.back().push_back(p);
    last = p;
  }
  static int move_to(const FT_Vector* to, void* self) {
    auto* s = static_cast<OutlineSink*>(self);
    s->rings.emplace_back();
    s->add(s->at(to));
    return 0;
  }
  static int line_to(const FT_Vector* to, void* self) {
    auto* s = static_cast<OutlineSink*>(self);
    s->add(s->at(to));
    return 0;
  }
  static int conic_to(const FT_Vector* control, const FT_Vector* to, void* self) {
    auto* s = static_cast<OutlineSink*>(self);
    const P2 p0 = s->last, p1 = s->at(control), p2 = s->at(to);
    for (int i = 1; i <= s->segments; ++i) {
      const double t = double(i) / s->segments, u = 1 - t;
      s->add({u * u * p0[0] + 2 * u * t * p1[0] + t * t * p2[0], u * u * p0[1] + 2 * u * t * p1[1] + t * t * p2[1]});
    }
    return 0;
  }
  static int cubic_to(const FT_Vector* c1, const FT_Vector* c2, const FT_Vector* to, void* self) {
    auto* s = static_cast<OutlineSink*>(self);
    const P2 p0 = s->last, p1 = s->at(c1), p2 = s->at(c2), p3 = s->at(to);
    for (int i = 1; i <= s->segments; ++i) {
      const double t = double(i) / s->segments, u = 1 - t;
      const double a = u * u * u, b = 3 * u * u * t, c = 3 * u * t * t, d = t * t * t;
      s->add({a * p0[0] + b * p1[0] + c * p2[0] + d * p3[0], a * p0[1] + b * p1[1] + c * p2[1] + d * p3[1]});
    }
    return 0;
  }
};

hb_direction_t direction_of(const std::string& d) {
  if (d == "ltr") return HB_DIRECTION_LTR;
  if (d == "rtl") return HB_DIRECTION_RTL;
  if (d == "ttb") return HB_DIRECTION_TTB;
  if (d == "btt") return HB_DIRECTION_BTT;
  return HB_DIRECTION_INVALID;
}

// HarfBuzz's font for shaping: horizontal text with HarfBuzz's own OpenType tables, in font
// units (its default scale); vertical text through FreeType at OpenSCAD's size, whose
// synthesized vertical metrics (a glyph centred on the pen line, advancing by the typographic
// line height) are the ones OpenSCAD's glyphs stand on.
struct ShapingFont {
  hb_blob_t* blob = nullptr;
  hb_face_t* face = nullptr;
  hb_font_t* font = nullptr;
  double position_unit = 0;  // model units per HarfBuzz position unit

  ShapingFont(FT_Face ft, const std::string& file, bool vertical, double size, double unit) {
    if (vertical) {
      if (FT_Set_Char_Size(ft, 0, FT_F26Dot6(size * kCharSizeScale), 100, 100))
        throw InvalidInput("text: cannot set the font's size");
      font = hb_ft_font_create_referenced(ft);
      position_unit = 1 / kPositionUnit;
    } else {
      blob = hb_blob_create_from_file(file.c_str());
      face = hb_face_create(blob, 0);
      font = hb_font_create(face);
      position_unit = kAdvanceScale * unit;
    }
  }
  ~ShapingFont() {
    hb_font_destroy(font);
    if (face) hb_face_destroy(face);
    if (blob) hb_blob_destroy(blob);
  }
  ShapingFont(const ShapingFont&) = delete;
  ShapingFont& operator=(const ShapingFont&) = delete;
};

// The glyphs' outlines where HarfBuzz puts them, and where the pen ends.
struct Line {
  std::vector<Ring> rings;
  double pen_x = 0, pen_y = 0;
  double widest = 0;  // vertical text: the widest glyph's box
};

Line lay_out(FT_Face face, const std::string& file, const TextParams& p, hb_direction_t direction, bool vertical) {
  // Outlines in font units: no hinting, the em square at its design size.
  const double unit = p.size * kEmPerSize / face->units_per_EM;
  const ShapingFont font(face, file, vertical, p.size, unit);
  const std::unique_ptr<hb_buffer_t, decltype(&hb_buffer_destroy)> buffer(hb_buffer_create(), hb_buffer_destroy);
  hb_buffer_t* buf = buffer.get();
  hb_buffer_add_utf8(buf, p.text.c_str(), int(p.text.size()), 0, int(p.text.size()));
  if (direction != HB_DIRECTION_INVALID) hb_buffer_set_direction(buf, direction);
  if (!p.script.empty()) hb_buffer_set_script(buf, hb_script_from_string(p.script.c_str(), int(p.script.size())));
  if (!p.language.empty()) hb_buffer_set_language(buf, hb_language_from_string(p.language.c_str(), int(p.language.size())));
  hb_buffer_guess_segment_properties(buf);
  hb_shape(font.font, buf, nullptr, 0);
  unsigned count = 0;
  const hb_glyph_info_t* info = hb_buffer_get_glyph_infos(buf, &count);
  const hb_glyph_position_t* pos = hb_buffer_get_glyph_positions(buf, &count);
  OutlineSink sink;
  sink.unit = unit;
  sink.segments = std::max(1, p.segments);
  FT_Outline_Funcs funcs{};
  funcs.move_to = &OutlineSink::move_to;
  funcs.line_to = &OutlineSink::line_to;
  funcs.conic_to = &OutlineSink::conic_to;
  funcs.cubic_to = &OutlineSink::cubic_to;
  Line line;
  // OpenSCAD measures a glyph's box hinted at its size; the unhinted outline's lies within a
  // few thousandths of it.
  const double pixel = p.size * kCharSizeScale / 72 * 100 / face->units_per_EM;  // 26.6 units per font unit
  for (unsigned i = 0; i < count; ++i) {
    if (FT_Load_Glyph(face, info[i].codepoint, FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING | FT_LOAD_NO_BITMAP) == 0 &&
        face->glyph->format == FT_GLYPH_FORMAT_OUTLINE) {
      sink.dx = line.pen_x + pos[i].x_offset * font.position_unit;
      sink.dy = line.pen_y + pos[i].y_offset * font.position_unit;
      FT_Outline_Decompose(&face->glyph->outline, &funcs, &sink);
      if (vertical) {
        FT_BBox box;
        FT_Outline_Get_CBox(&face->glyph->outline, &box);
        line.widest = std::max(line.widest, (box.xMax - box.xMin) * pixel / kPositionUnit);
      }
    }
    line.pen_x += pos[i].x_advance * font.position_unit * p.spacing;
    line.pen_y += pos[i].y_advance * font.position_unit * p.spacing;
  }
  line.rings = std::move(sink.rings);
  return line;
}

// Where halign and valign move the text. Horizontal: along the line by the advance, across it
// by the outlines' extent, which OpenSCAD measures at the advances' scale too. Vertical, as
// OpenSCAD 2021 places it: across the line by the widest glyph's box, along it by the advance
// (the pen goes down, so "top" lifts the column above the origin; "bottom" and "baseline"
// leave it hanging below).
P2 alignment_shift(const Region& region, const TextParams& p, const Line& line, bool vertical) {
  double sx = 0, sy = 0;
  if (vertical) {
    if (p.halign == "center") sx = -line.widest / 2;
    else if (p.halign == "right") sx = -line.widest;
    if (p.valign == "top") sy = -line.pen_y;
    else if (p.valign == "center") sy = -line.pen_y / 2;
    return {sx, sy};
  }
  double lo = kHuge, hi = -kHuge;
  for (const Ring& r : region)
    for (const P2& q : r) lo = std::min(lo, q[1]), hi = std::max(hi, q[1]);
  lo *= kAdvanceScale, hi *= kAdvanceScale;
  if (p.halign == "center") sx = -line.pen_x / 2;
  else if (p.halign == "right") sx = -line.pen_x;
  if (p.valign == "top") sy = -hi;
  else if (p.valign == "center") sy = -(lo + hi) / 2;
  else if (p.valign == "bottom") sy = -lo;
  return {sx, sy};
}

}  // namespace

Region text_region(const TextParams& p) {
  if (p.text.empty() || !(p.size > 0)) return {};
  const std::string file = font_file(p.font);
  FT_Library lib = nullptr;
  if (FT_Init_FreeType(&lib)) throw InvalidInput("text: FreeType could not start");
  const std::unique_ptr<FT_LibraryRec_, decltype(&FT_Done_FreeType)> lib_guard(lib, FT_Done_FreeType);
  FT_Face face = nullptr;
  if (FT_New_Face(lib, file.c_str(), 0, &face)) throw InvalidInput("text: cannot read font file " + file);
  const std::unique_ptr<FT_FaceRec_, decltype(&FT_Done_Face)> face_guard(face, FT_Done_Face);
  const hb_direction_t direction = direction_of(p.direction);
  const bool vertical = direction != HB_DIRECTION_INVALID && HB_DIRECTION_IS_VERTICAL(direction);
  Line line = lay_out(face, file, p, direction, vertical);
  // FreeType's outer contours run clockwise (TrueType): reverse all, fill by non-zero winding.
  for (Ring& r : line.rings) std::reverse(r.begin(), r.end());
  Region region = region_union({line.rings});
  if (region.empty()) return region;
  const P2 shift = alignment_shift(region, p, line, vertical);
  for (Ring& r : region)
    for (P2& q : r) q[0] += shift[0], q[1] += shift[1];
  return region;
}

}  // namespace pic::detail::scad
