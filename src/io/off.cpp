// OFF (Geomview): "OFF" (or COFF, NOFF, CNOFF, STOFF, ... ; the header word may be missing),
// then "nv nf ne", nv vertex lines "x y z [extra]" and nf face lines "k i1 .. ik [color]".
// Read line by line: a vertex's or face's extra fields (normals, colors) are ignored, which
// is how COFF/NOFF variants are read without knowing how many color channels a writer used.
// '#' starts a comment anywhere. Binary OFF and 4OFF/nOFF are refused.
#include <string>
#include <vector>

#include "io/readers.h"
#include "io/text.h"

namespace pic::detail {
namespace {

[[noreturn]] void fail(const std::string& what) { throw InvalidInput("OFF: " + what); }

// Next token that is not in a comment, crossing lines; empty at the end.
std::string_view next_token(TextCursor& t) {
  while (true) {
    const std::string_view tok = t.token();
    if (tok.empty() || tok[0] != '#') return tok;
    t.skip_line();
  }
}

// The next token on this line, ignoring a comment.
std::string_view line_token(TextCursor& t) {
  const std::string_view tok = t.token_on_line();
  if (tok.empty() || tok[0] != '#') return tok;
  t.skip_to_line_end();
  return {};
}

uint64_t count(std::string_view tok, size_t line, const char* what) {
  if (tok.empty()) fail(std::string("the header ends before the ") + what + " count");
  const int64_t n = parse_int(tok, line);
  if (n < 0) fail(std::string("negative ") + what + " count");
  return uint64_t(n);
}

}  // namespace

RawGeometry read_off(Bytes bytes) {
  TextCursor t(bytes.chars(), bytes.chars() + bytes.size);
  std::string_view tok = next_token(t);
  if (tok.size() >= 3 && tok.substr(tok.size() - 3) == "OFF") {
    const std::string_view prefix = tok.substr(0, tok.size() - 3);
    for (char c : prefix)
      if (c != 'S' && c != 'T' && c != 'C' && c != 'N')
        fail("the variant " + quoted(tok) + " is not supported (only 3D OFF, COFF, NOFF, STOFF)");
    const std::string_view next = line_token(t);
    if (next == "BINARY") fail("binary OFF is not supported");
    tok = next.empty() ? next_token(t) : next;
  }
  const uint64_t nv = count(tok, t.line(), "vertex");
  const uint64_t nf = count(next_token(t), t.line(), "face");
  t.skip_line();  // the edge count (unused) and anything after it
  // A vertex takes at least "0 0 0\n" and a face at least "0\n".
  if (nv > t.remaining() / 5 + 1) fail(declares_too_many(nv, "vertices", bytes.size, t.remaining()));
  if (nf > t.remaining() / 2 + 1) fail(declares_too_many(nf, "faces", bytes.size, t.remaining()));
  RawGeometry g;
  g.positions.resize(size_t(nv));
  for (uint64_t i = 0; i < nv; ++i) {
    std::string_view x = next_token(t);
    if (x.empty()) fail("the file ends after " + std::to_string(i) + " of " + std::to_string(nv) + " vertices");
    const size_t line = t.line();
    const std::string_view y = line_token(t), z = line_token(t);
    if (z.empty()) fail("line " + std::to_string(line) + ": a vertex needs x y z");
    g.positions[size_t(i)] = {parse_double(x, line), parse_double(y, line), parse_double(z, line)};
    t.skip_line();
  }
  std::vector<uint32_t> polygon;
  for (uint64_t f = 0; f < nf; ++f) {
    const std::string_view k = next_token(t);
    if (k.empty()) fail("the file ends after " + std::to_string(f) + " of " + std::to_string(nf) + " faces");
    const size_t line = t.line();
    const int64_t n = parse_int(k, line);
    if (n < 0) fail("line " + std::to_string(line) + ": negative corner count");
    polygon.clear();
    for (int64_t c = 0; c < n; ++c) {
      const std::string_view idx = line_token(t);
      if (idx.empty()) fail("line " + std::to_string(line) + ": the face has fewer than " + std::to_string(n) + " indices");
      const int64_t i = parse_int(idx, line);
      if (i < 0 || uint64_t(i) >= nv)
        fail("line " + std::to_string(line) + ": vertex index " + std::to_string(i) + " out of range (" +
             std::to_string(nv) + " vertices)");
      polygon.push_back(uint32_t(i));
    }
    add_fan(polygon.data(), polygon.size(), g.triangles);
    t.skip_line();
  }
  return g;
}

}  // namespace pic::detail
