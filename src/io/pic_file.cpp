// The .pic file (docs/pic-format.md): a fixed header, a pointerless bit stream of the tree in
// depth-first order, and a CRC-32 of everything before it.
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "io/file_util.h"
#include "octree/cell.h"
#include "signs/invariants.h"

namespace pic {
namespace {

constexpr char kMagic[4] = {'P', 'I', 'C', 'F'};
constexpr uint16_t kVersion = 1;
constexpr size_t kHeaderBytes = 4 + 2 + 2 + 4 + 32 + 8 + 8 + 8;  // 68
constexpr size_t kCrcBytes = 4;

/// Quantization of a vertex in a cell of `level`: each cell-local coordinate is rounded to
/// i / 2^q, i in [0, 2^q], stored in q+1 bits. The cell's faces and dyadic points (0, 1/2, ...)
/// stay exact — a box corner on an octree plane must stay on it — and the error
/// cell_size / 2^(q+1) is at most 2^-25 ~ 3e-8 of the root cube from level 2 on.
int quant_bits(int level) { return std::min(22, 24 - level); }

// Bits are packed least-significant first; whole bytes go through a 64-bit accumulator.
class BitWriter {
 public:
  void put(uint32_t v, int bits) {  // bits <= 32
    acc_ |= uint64_t(v & uint32_t((uint64_t{1} << bits) - 1)) << fill_;
    fill_ += bits;
    for (; fill_ >= 8; fill_ -= 8, acc_ >>= 8) bytes_.push_back(uint8_t(acc_));
  }
  /// The bytes written, the last one padded with zero bits.
  std::vector<uint8_t>& bytes() {
    if (fill_ > 0) bytes_.push_back(uint8_t(acc_)), acc_ = 0, fill_ = 0;
    return bytes_;
  }

 private:
  std::vector<uint8_t> bytes_;
  uint64_t acc_ = 0;
  int fill_ = 0;  // bits in acc_ (< 8 between calls)
};

class BitReader {
 public:
  BitReader(const uint8_t* data, size_t size) : data_(data), bits_(size * 8) {}
  uint32_t get(int bits) {  // bits <= 32
    if (pos_ + size_t(bits) > bits_) throw IoError("corrupted .pic file: tree data ends early");
    if (bits == 0) return 0;
    // Up to 5 bytes hold the field; bytes past the end are never read.
    const size_t first = pos_ / 8, last = (pos_ + size_t(bits) - 1) / 8;
    uint64_t word = 0;
    for (size_t k = first; k <= last; ++k) word |= uint64_t(data_[k]) << (8 * (k - first));
    const uint32_t v = uint32_t((word >> (pos_ % 8)) & ((uint64_t{1} << bits) - 1));
    pos_ += size_t(bits);
    return v;
  }

 private:
  const uint8_t* data_;
  size_t bits_;
  size_t pos_ = 0;
};

void put_bytes(std::vector<uint8_t>& out, const void* p, size_t n) {
  const auto* b = static_cast<const uint8_t*>(p);
  out.insert(out.end(), b, b + n);
}
template <class T>
void put(std::vector<uint8_t>& out, T v) {
  put_bytes(out, &v, sizeof v);  // little-endian hosts only (x86-64, arm64)
}
template <class T>
T get(const std::vector<uint8_t>& in, size_t& at) {
  T v;
  std::memcpy(&v, in.data() + at, sizeof v);
  at += sizeof v;
  return v;
}

// Counts are of the nodes reached from the root: an octree edited in place (csg_inplace)
// keeps replaced subtrees in its arrays until it is compacted.
void write_node(const Octree& t, uint32_t node, int level, BitWriter& w, uint64_t& nodes, uint64_t& grays) {
  const Node& n = t.nodes[node];
  ++nodes;
  w.put(static_cast<uint32_t>(n.kind), 2);
  if (n.kind == CellKind::Internal) {
    for (int c = 0; c < 8; ++c) write_node(t, n.index + c, level + 1, w, nodes, grays);
  } else if (n.kind == CellKind::Gray) {
    ++grays;
    w.put(n.signs, 8);
    if (level == t.max_depth) w.put(n.flags & kFlagCapped, 1);
    const int q = quant_bits(level);
    const double scale = double(1u << q);
    for (float x : t.vertices[n.index])
      w.put(static_cast<uint32_t>(std::nearbyint(std::clamp(double(x), 0.0, 1.0) * scale)), q + 1);
  }
}

struct Decoder {
  BitReader r;
  Octree& t;
  uint64_t max_nodes;

  void read_node(uint32_t slot, int level) {
    const auto kind = static_cast<CellKind>(r.get(2));
    Node n{0, kind, 0, 0, 0};
    if (kind == CellKind::Internal) {
      if (level >= t.max_depth) throw IoError("corrupted .pic file: tree deeper than its depth");
      if (t.nodes.size() + 8 > max_nodes) throw IoError("corrupted .pic file: more nodes than declared");
      n.index = static_cast<uint32_t>(t.nodes.size());
      t.nodes[slot] = n;
      t.nodes.resize(t.nodes.size() + 8);
      for (int c = 0; c < 8; ++c) read_node(n.index + c, level + 1);
      return;
    }
    if (kind == CellKind::Gray) {
      n.signs = static_cast<uint8_t>(r.get(8));
      if (level == t.max_depth) n.flags = static_cast<uint8_t>(r.get(1));
      const int q = quant_bits(level);
      std::array<float, 3> v;
      for (float& x : v) {
        const uint32_t i = r.get(q + 1);
        if (i > (1u << q)) throw IoError("corrupted .pic file: vertex outside its cell");
        x = static_cast<float>(double(i) / double(1u << q));
      }
      n.index = static_cast<uint32_t>(t.vertices.size());
      t.vertices.push_back(v);
    }
    t.nodes[slot] = n;
  }
};

}  // namespace

std::vector<uint8_t> serialize(const Octree& tree) {
  BitWriter w;
  uint64_t nodes = 0, grays = 0;
  write_node(tree, 0, 0, w, nodes, grays);
  std::vector<uint8_t> out;
  out.reserve(kHeaderBytes + w.bytes().size() + kCrcBytes);
  put_bytes(out, kMagic, 4);
  put<uint16_t>(out, kVersion);
  put<uint16_t>(out, 0);  // flags, reserved
  put<uint8_t>(out, static_cast<uint8_t>(tree.max_depth));
  put<uint8_t>(out, 0);
  put<uint16_t>(out, 0);
  for (double x : tree.cube.origin) put<double>(out, x);
  put<double>(out, tree.cube.size);
  put<uint64_t>(out, nodes);
  put<uint64_t>(out, grays);
  put<uint64_t>(out, w.bytes().size());
  put_bytes(out, w.bytes().data(), w.bytes().size());
  put<uint32_t>(out, static_cast<uint32_t>(crc32(0L, out.data(), static_cast<uInt>(out.size()))));
  return out;
}

Octree deserialize(const std::vector<uint8_t>& in) {
  if (in.size() < 4 || std::memcmp(in.data(), kMagic, 4) != 0)
    throw IoError("not a .pic file (bad magic number)");
  if (in.size() < kHeaderBytes + kCrcBytes) throw IoError("corrupted .pic file: truncated header");
  size_t at = 4;
  const auto version = get<uint16_t>(in, at);
  if (version != kVersion)
    throw IoError("unsupported .pic version " + std::to_string(version) + " (this build reads 1)");
  at += 2;
  const auto depth = get<uint8_t>(in, at);
  at += 3;
  Octree t;
  for (double& x : t.cube.origin) x = get<double>(in, at);
  t.cube.size = get<double>(in, at);
  const auto node_count = get<uint64_t>(in, at);
  const auto gray_count = get<uint64_t>(in, at);
  const auto payload = get<uint64_t>(in, at);
  if (payload != in.size() - kHeaderBytes - kCrcBytes)
    throw IoError("corrupted .pic file: truncated or trailing data (size mismatch)");
  size_t crc_at = in.size() - kCrcBytes;
  const auto stored_crc = get<uint32_t>(in, crc_at);
  const auto crc = static_cast<uint32_t>(crc32(0L, in.data(), static_cast<uInt>(in.size() - kCrcBytes)));
  if (crc != stored_crc) throw IoError("corrupted .pic file: checksum mismatch");
  if (depth < 1 || depth > kMaxLevel) throw IoError("corrupted .pic file: bad depth");
  if (!(t.cube.size > 0) || !std::isfinite(t.cube.size) || !std::isfinite(t.cube.origin[0]) ||
      !std::isfinite(t.cube.origin[1]) || !std::isfinite(t.cube.origin[2]))
    throw IoError("corrupted .pic file: bad cube");
  // Every node costs at least 2 bits: bound allocations by the payload size.
  if (node_count == 0 || node_count > payload * 4 + 1 || gray_count > node_count)
    throw IoError("corrupted .pic file: bad node counts");
  t.max_depth = depth;
  t.nodes.reserve(node_count);
  t.vertices.reserve(gray_count);
  Decoder d{BitReader(in.data() + kHeaderBytes, payload), t, node_count};
  d.read_node(0, 0);
  if (t.nodes.size() != node_count || t.vertices.size() != gray_count)
    throw IoError("corrupted .pic file: node counts do not match the tree");
  // A loaded tree is input like any other: the contour is closed and 2-manifold only for the
  // trees the construction makes (one sign per lattice point, one component per leaf above
  // the cap), so a file whose checksum is right but whose signs are not is refused here.
  try {
    detail::check_octree(t, "loading");
  } catch (const std::logic_error& e) {
    const std::string what = e.what();
    throw IoError("corrupted .pic file: " + what.substr(what.find(": ") + 2));
  }
  return t;
}

void save(const Octree& tree, const std::filesystem::path& path) {
  detail::write_bytes(path, serialize(tree));
}

Octree load(const std::filesystem::path& path) {
  const auto bytes = detail::read_file(path);
  try {
    return deserialize(bytes);
  } catch (const IoError& e) {
    throw IoError(path.string() + ": " + e.what());
  }
}

}  // namespace pic
