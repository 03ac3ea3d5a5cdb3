// PLY (Turk 1994): ascii, binary_little_endian and binary_big_endian. Reads the "vertex"
// element's x, y, z (any scalar type) and optional nx, ny, nz, and the "face" element's
// vertex_indices / vertex_index list (any count and index type), fan-triangulated. Every other
// element and property is read past according to its declared type. Before reading an element
// its declared count is checked against the bytes left, so a header that declares 10^9
// vertices in a small file is refused at once instead of allocating.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "io/readers.h"
#include "io/text.h"

namespace pic::detail {
namespace {

enum class Format { Ascii, BinaryLittle, BinaryBig };
enum class Type : uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

size_t type_size(Type t) {
  static constexpr size_t kSize[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSize[size_t(t)];
}

bool parse_type(std::string_view s, Type& t) {
  static constexpr std::pair<std::string_view, Type> kNames[] = {
      {"char", Type::Int8},     {"int8", Type::Int8},     {"uchar", Type::UInt8},    {"uint8", Type::UInt8},
      {"short", Type::Int16},   {"int16", Type::Int16},   {"ushort", Type::UInt16},  {"uint16", Type::UInt16},
      {"int", Type::Int32},     {"int32", Type::Int32},   {"uint", Type::UInt32},    {"uint32", Type::UInt32},
      {"float", Type::Float32}, {"float32", Type::Float32}, {"double", Type::Float64}, {"float64", Type::Float64}};
  for (const auto& [name, type] : kNames)
    if (s == name) {
      t = type;
      return true;
    }
  return false;
}

struct Property {
  std::string name;
  Type type = Type::Float32;  ///< scalar type, or the item type of a list
  bool is_list = false;
  Type count_type = Type::UInt8;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  size_t data_offset = 0;
};

[[noreturn]] void fail(const std::string& what) { throw InvalidInput("PLY: " + what); }

Header parse_header(Bytes bytes) {
  TextCursor text(bytes.chars(), bytes.chars() + bytes.size);
  if (text.rest_of_line() != "ply") fail("the file does not start with 'ply'");
  Header h;
  bool have_format = false;
  while (true) {
    if (text.at_end()) fail("the header has no 'end_header' line");
    const size_t line = text.line();
    const std::string_view key = text.token_on_line();
    if (key == "end_header") {
      text.skip_line();
      break;
    }
    if (key == "comment" || key == "obj_info" || key.empty()) {
      text.skip_line();
      continue;
    }
    const std::string at = " (header line " + std::to_string(line) + ")";
    if (key == "format") {
      const std::string_view f = text.token_on_line();
      if (f == "ascii") h.format = Format::Ascii;
      else if (f == "binary_little_endian") h.format = Format::BinaryLittle;
      else if (f == "binary_big_endian") h.format = Format::BinaryBig;
      else fail("unknown format " + quoted(f) + at);
      text.token_on_line();  // the version, "1.0"
      have_format = true;
    } else if (key == "element") {
      Element e;
      e.name = std::string(text.token_on_line());
      const std::string_view count = text.token_on_line();
      if (e.name.empty() || count.empty()) fail("'element' needs a name and a count" + at);
      const int64_t n = parse_int(count, line);
      if (n < 0) fail("negative element count" + at);
      e.count = uint64_t(n);
      h.elements.push_back(std::move(e));
    } else if (key == "property") {
      if (h.elements.empty()) fail("'property' before any 'element'" + at);
      Property p;
      std::string_view t = text.token_on_line();
      if (t == "list") {
        p.is_list = true;
        if (!parse_type(text.token_on_line(), p.count_type)) fail("unknown list count type" + at);
        if (p.count_type == Type::Float32 || p.count_type == Type::Float64) fail("a list count must be an integer type" + at);
        t = text.token_on_line();
      }
      if (!parse_type(t, p.type)) fail("unknown property type " + quoted(t) + at);
      p.name = std::string(text.token_on_line());
      if (p.name.empty()) fail("'property' without a name" + at);
      h.elements.back().properties.push_back(std::move(p));
    } else {
      fail("unknown header keyword " + quoted(key) + at);
    }
    if (!text.token_on_line().empty()) fail("unexpected text after " + quoted(key) + at);
    text.skip_line();
  }
  if (!have_format) fail("the header has no 'format' line");
  h.data_offset = size_t(text.position() - bytes.chars());
  return h;
}

// Reads values one at a time from the data section, ascii or binary.
class ValueReader {
 public:
  ValueReader(Bytes bytes, const Header& h)
      : format_(h.format), data_(bytes.data), pos_(h.data_offset), size_(bytes.size),
        text_(bytes.chars() + h.data_offset, bytes.chars() + bytes.size) {}

  size_t remaining() const { return format_ == Format::Ascii ? text_.remaining() : size_ - pos_; }
  bool ascii() const { return format_ == Format::Ascii; }

  double value(Type t) {
    if (format_ == Format::Ascii) {
      const std::string_view tok = text_.token();
      if (tok.empty()) fail("the data ends early");
      return parse_double(tok, text_.line());
    }
    const size_t n = type_size(t);
    if (size_ - pos_ < n) fail("the data ends early");
    uint8_t b[8];
    std::memcpy(b, data_ + pos_, n);
    pos_ += n;
    if ((format_ == Format::BinaryBig) == (std::endian::native == std::endian::little)) std::reverse(b, b + n);
    switch (t) {
      case Type::Int8: return double(int8_t(b[0]));
      case Type::UInt8: return double(b[0]);
      case Type::Int16: return double(load<int16_t>(b));
      case Type::UInt16: return double(load<uint16_t>(b));
      case Type::Int32: return double(load<int32_t>(b));
      case Type::UInt32: return double(load<uint32_t>(b));
      case Type::Float32: return double(load<float>(b));
      case Type::Float64: return load<double>(b);
    }
    return 0;
  }

  /// A list count or an index: a whole number in [0, limit].
  uint64_t whole(Type t, uint64_t limit, const char* what) {
    const double v = value(t);
    if (!(v >= 0) || v != std::floor(v) || v > double(limit))
      fail(std::string("bad ") + what + " " + std::to_string(v) + where());
    return uint64_t(v);
  }

  void skip(Type t, uint64_t n) {
    if (format_ == Format::Ascii) {
      for (uint64_t i = 0; i < n; ++i) value(t);
      return;
    }
    const uint64_t bytes = n * type_size(t);  // n <= size_, no overflow
    if (bytes > size_ - pos_) fail("the data ends early");
    pos_ += size_t(bytes);
  }

  std::string where() const {
    return ascii() ? " (line " + std::to_string(text_.line()) + ")" : " (byte " + std::to_string(pos_) + ")";
  }

 private:
  template <class T>
  static T load(const uint8_t* b) {
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }

  Format format_;
  const uint8_t* data_;
  size_t pos_, size_;
  TextCursor text_;
};

// Fewest bytes one record of `e` can take: binary, the scalars plus the list counts;
// ascii, one character and one separator per value (the last may lack its separator).
uint64_t min_record_bytes(const Element& e, Format f) {
  uint64_t n = 0;
  for (const Property& p : e.properties)
    n += f == Format::Ascii ? 2 : type_size(p.is_list ? p.count_type : p.type);
  return n;
}

int find_scalar(const Element& e, std::string_view name) {
  for (size_t i = 0; i < e.properties.size(); ++i)
    if (e.properties[i].name == name) {
      if (e.properties[i].is_list) fail("vertex property " + quoted(name) + " is a list");
      return int(i);
    }
  return -1;
}

}  // namespace

RawGeometry read_ply(Bytes bytes) {
  const Header h = parse_header(bytes);
  ValueReader in(bytes, h);
  RawGeometry g;
  bool have_vertices = false, have_faces = false;
  uint64_t face_count = 0;
  std::vector<uint32_t> polygon;
  for (const Element& e : h.elements) {
    if (e.properties.empty()) continue;  // nothing stored, whatever the count
    const uint64_t need = min_record_bytes(e, h.format);
    const uint64_t left = in.remaining() + (in.ascii() ? 1 : 0);
    if (e.count > left / need) {
      const std::string what = e.name == "vertex" ? "vertices" : e.name == "face" ? "faces" : "'" + e.name + "' elements";
      fail(declares_too_many(e.count, what, bytes.size, in.remaining()));
    }
    const bool is_vertex = e.name == "vertex" && !have_vertices;
    const bool is_face = e.name == "face" && !have_faces;
    int role[6] = {-1, -1, -1, -1, -1, -1};  // x y z nx ny nz
    int index_list = -1;
    if (is_vertex) {
      static constexpr const char* kNames[6] = {"x", "y", "z", "nx", "ny", "nz"};
      for (int k = 0; k < 6; ++k) role[k] = find_scalar(e, kNames[k]);
      if (role[0] < 0 || role[1] < 0 || role[2] < 0) fail("the vertex element has no x, y, z properties");
      if (e.count > UINT32_MAX) fail("more than 2^32 vertices");
      have_vertices = true;
      const bool normals = role[3] >= 0 && role[4] >= 0 && role[5] >= 0;
      g.positions.resize(size_t(e.count));
      if (normals) g.normals.resize(size_t(e.count));
      if (!normals) role[3] = role[4] = role[5] = -1;
    }
    if (is_face) {
      for (size_t i = 0; i < e.properties.size(); ++i)
        if (e.properties[i].is_list && (e.properties[i].name == "vertex_indices" || e.properties[i].name == "vertex_index"))
          index_list = int(i);
      if (index_list < 0) fail("the face element has no vertex_indices list");
      have_faces = true;
      face_count = e.count;
    }
    for (uint64_t r = 0; r < e.count; ++r) {
      for (size_t k = 0; k < e.properties.size(); ++k) {
        const Property& p = e.properties[k];
        if (!p.is_list) {
          if (!is_vertex) {
            in.skip(p.type, 1);
            continue;
          }
          const double v = in.value(p.type);
          for (int c = 0; c < 6; ++c)
            if (role[c] == int(k)) (c < 3 ? g.positions : g.normals)[size_t(r)][c % 3] = v;
          continue;
        }
        // A list: its items are bounded by the bytes left (each takes at least one).
        const uint64_t n = in.whole(p.count_type, in.remaining(), "list length");
        if (int(k) != index_list) {
          in.skip(p.type, n);
          continue;
        }
        polygon.resize(size_t(n));
        for (uint64_t i = 0; i < n; ++i) polygon[size_t(i)] = uint32_t(in.whole(p.type, UINT32_MAX, "vertex index"));
        add_fan(polygon.data(), polygon.size(), g.triangles);
      }
    }
  }
  if (!have_vertices) fail("no vertex element");
  for (const auto& t : g.triangles)
    for (uint32_t i : t)
      if (i >= g.positions.size())
        fail("face index " + std::to_string(i) + " out of range (" + std::to_string(g.positions.size()) + " vertices)");
  g.point_cloud = face_count == 0;
  return g;
}

}  // namespace pic::detail
