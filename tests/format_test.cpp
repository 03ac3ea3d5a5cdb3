// The .pic file: round trips, size, robustness against damaged or foreign files, atomic save.
#include <gtest/gtest.h>

#include <random>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "pic/pic.h"
#include "pic/primitives.h"
#include "support/mesh_checks.h"
#include "support/temp_dir.h"
#include "support/shapes.h"

namespace pic {
namespace {

namespace fs = std::filesystem;
using test::IsClosedManifold;

constexpr size_t kHeaderBytes = 68;  // magic 4, version 2, flags 2, depth 4, cube 32, counts 24

// A fresh directory per test, removed afterwards.
struct TempDir : test::TempDir {
  TempDir() : test::TempDir("pic_format") {}
};

std::vector<uint8_t> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void write_raw(const fs::path& p, const std::vector<uint8_t>& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

// CRC-32 (IEEE, as zlib) so tests can forge files whose checksum is valid.
uint32_t crc32_ieee(const uint8_t* data, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; ++i) {
    c ^= data[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1)));
  }
  return c ^ 0xffffffffu;
}
void fix_crc(std::vector<uint8_t>& b) {
  const uint32_t c = crc32_ieee(b.data(), b.size() - 4);
  std::memcpy(b.data() + b.size() - 4, &c, 4);
}

const Octree& fandisk_tree() {
  static const Octree t = [] {
    SampleOptions o;
    o.depth = 12;
    return sample(read_mesh(std::string(PIC_DATA_DIR) + "/fandisk.obj"), o);
  }();
  return t;
}
const Octree& sphere_tree() {
  static const Octree t = [] {
    SampleOptions o;
    o.depth = 8;
    return sample(make_sphere({1, 2, 3}, 0.5, 48), o);
  }();
  return t;
}
// Small tree for exhaustive corruption sweeps.
const Octree& small_tree() {
  static const Octree t = [] {
    SampleOptions o;
    o.depth = 5;
    return sample(make_torus({0, 0, 0}, 1, 0.35, 2, 16, 8), o);
  }();
  return t;
}

// Same structure; vertices within `tol` root-cube units.
void expect_same_tree(const Octree& a, const Octree& b, double tol) {
  EXPECT_EQ(a.cube, b.cube);
  EXPECT_EQ(a.max_depth, b.max_depth);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  size_t differ = 0;
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const Node &x = a.nodes[i], &y = b.nodes[i];
    differ += x.kind != y.kind || x.index != y.index || x.signs != y.signs || x.flags != y.flags;
  }
  EXPECT_EQ(differ, 0u) << "nodes differ";
  std::vector<Vec3> va, vb;
  for_each_leaf(a, [&](const LeafView& l) {
    if (l.kind == CellKind::Gray) va.push_back(l.vertex);
  });
  for_each_leaf(b, [&](const LeafView& l) {
    if (l.kind == CellKind::Gray) vb.push_back(l.vertex);
  });
  ASSERT_EQ(va.size(), vb.size());
  double worst = 0;
  for (size_t i = 0; i < va.size(); ++i) worst = std::max(worst, test::dist3(va[i], vb[i]) / a.cube.size);
  EXPECT_LE(worst, tol);
}

void expect_round_trip(const Octree& t, const TempDir& dir) {
  const fs::path p1 = dir / "a.pic", p2 = dir / "b.pic";
  save(t, p1);
  const Octree loaded = load(p1);
  save(loaded, p2);
  const auto b1 = read_bytes(p1), b2 = read_bytes(p2);
  EXPECT_EQ(b1.size(), b2.size());
  EXPECT_TRUE(b1 == b2) << "save -> load -> save is not byte-identical";
  EXPECT_TRUE(serialize(t) == b1) << "save writes serialize()";
  expect_same_tree(t, loaded, 1e-7);
  // The loaded tree contours to the same mesh, vertices within 1e-7 of the root cube.
  // The plain split: the default's exact re-triangulation may decide differently for a
  // vertex that moved by 1e-7.
  ContourOptions plain;
  plain.intersection_free = false;
  const TriMesh m0 = contour(t, plain), m1 = contour(loaded, plain);
  ASSERT_TRUE(IsClosedManifold(m1));
  ASSERT_EQ(m0.positions.size(), m1.positions.size());
  EXPECT_EQ(m0.triangles.size(), m1.triangles.size());
  EXPECT_EQ(test::euler_characteristic(m0), test::euler_characteristic(m1));
  double worst = 0;
  for (size_t i = 0; i < m0.positions.size(); ++i)
    worst = std::max(worst, test::dist3(m0.positions[i], m1.positions[i]) / t.cube.size);
  EXPECT_LE(worst, 1e-7);
  std::printf("  [measure] %zu bytes, %zu PICs, %.2f bytes/PIC, worst vertex move %.3g\n", b1.size(),
              t.vertices.size(), double(b1.size()) / double(t.vertices.size()), worst);
}

TEST(Format, RoundTripFandiskIsByteIdentical) {
  TempDir dir;
  expect_round_trip(fandisk_tree(), dir);
}

TEST(Format, RoundTripSphereIsByteIdentical) {
  TempDir dir;
  expect_round_trip(sphere_tree(), dir);
}

TEST(Format, RoundTripOfUniformAndHandBuiltTrees) {
  TempDir dir;
  Octree white;
  white.cube = Cube{{-1, 2, -3}, 0.5};
  white.max_depth = 3;
  save(white, dir / "w.pic");
  const Octree w = load(dir / "w.pic");
  EXPECT_EQ(w.nodes.size(), 1u);
  EXPECT_EQ(w.nodes[0].kind, CellKind::White);
  EXPECT_EQ(w.cube, white.cube);
  EXPECT_EQ(w.max_depth, 3);

  Octree black = white;
  black.nodes[0].kind = CellKind::Black;
  EXPECT_EQ(deserialize(serialize(black)).nodes[0].kind, CellKind::Black);

  // Depth 20, a single chain of cells down to the deepest level (4-bit coordinates), the
  // deepest gray with the root's corner inside, its siblings white (one sign per point).
  Octree deep;
  deep.max_depth = kMaxLevel;
  uint32_t node = 0;
  for (int level = 0; level < kMaxLevel; ++level) {
    const auto first = static_cast<uint32_t>(deep.nodes.size());
    deep.nodes.resize(deep.nodes.size() + 8);
    deep.nodes[node] = Node{first, CellKind::Internal, 0, 0, 0};
    for (int c = 1; c < 8; ++c) deep.nodes[first + c] = Node{0, CellKind::White, 0, 0, 0};
    node = first;
  }
  deep.nodes[node] = Node{0, CellKind::Gray, 0x01, kFlagCapped, 0};
  deep.vertices.push_back({0.5f, 0.25f, 0.75f});
  const Octree d = deserialize(serialize(deep));
  expect_same_tree(deep, d, 1e-7);
  EXPECT_TRUE(serialize(d) == serialize(deep));
}

TEST(Format, FandiskAtDepth12CostsAtMost12BytesPerPic) {
  const auto bytes = serialize(fandisk_tree());
  const double per_pic = double(bytes.size()) / double(fandisk_tree().vertices.size());
  std::printf("  [measure] fandisk depth 12: %zu bytes, %zu PICs, %.2f bytes/PIC\n", bytes.size(),
              fandisk_tree().vertices.size(), per_pic);
  EXPECT_LE(per_pic, 12.0);
  EXPECT_GT(fandisk_tree().vertices.size(), 1000u);
}

TEST(Format, SerializeIsDeterministic) {
  EXPECT_TRUE(serialize(sphere_tree()) == serialize(sphere_tree()));
}

// ---------------------------------------------------------------------------------------
// Damaged and foreign files: always IoError, never a crash.

void expect_io_error(const std::vector<uint8_t>& bytes, const std::string& what) {
  try {
    (void)deserialize(bytes);
    ADD_FAILURE() << what << ": accepted";
  } catch (const IoError& e) {
    EXPECT_GT(std::strlen(e.what()), 10u) << what;
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": wrong exception type: " << e.what();
  }
}

TEST(Format, EveryTruncationIsRejected) {
  const auto bytes = serialize(small_tree());
  ASSERT_GT(bytes.size(), kHeaderBytes + 8);
  for (size_t n = 0; n < bytes.size(); ++n)
    expect_io_error(std::vector<uint8_t>(bytes.begin(), bytes.begin() + n), "truncated to " + std::to_string(n));
}

TEST(Format, TruncatedLargeFilesAreRejected) {
  TempDir dir;
  const auto bytes = serialize(fandisk_tree());
  for (size_t n : {size_t{1}, size_t{3}, size_t{4}, size_t{40}, kHeaderBytes - 1, kHeaderBytes, kHeaderBytes + 3,
                   kHeaderBytes + 4, bytes.size() / 3, bytes.size() / 2, bytes.size() - 5, bytes.size() - 4,
                   bytes.size() - 1}) {
    write_raw(dir / "t.pic", std::vector<uint8_t>(bytes.begin(), bytes.begin() + n));
    try {
      (void)load(dir / "t.pic");
      ADD_FAILURE() << "truncated to " << n << " bytes: accepted";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("t.pic"), std::string::npos) << "message names the file: " << e.what();
    }
  }
  // Trailing garbage is rejected too.
  auto longer = bytes;
  longer.push_back(0);
  expect_io_error(longer, "one trailing byte");
}

TEST(Format, EverySingleFlippedByteIsRejected) {
  const auto bytes = serialize(small_tree());
  for (size_t i = 0; i < bytes.size(); ++i) {
    for (uint8_t mask : {uint8_t{0x01}, uint8_t{0x80}, uint8_t{0xff}}) {
      auto bad = bytes;
      bad[i] ^= mask;
      expect_io_error(bad, "byte " + std::to_string(i) + " ^ " + std::to_string(mask));
    }
  }
}

TEST(Format, FlippedBytesInALargeFileAreRejected) {
  const auto bytes = serialize(fandisk_tree());
  for (size_t i = 0; i < bytes.size(); i += 1 + bytes.size() / 97) {
    auto bad = bytes;
    bad[i] ^= 0x10;
    expect_io_error(bad, "byte " + std::to_string(i));
  }
}

// Corruptions that keep a valid checksum (a buggy writer, or a forged file) must still fail
// cleanly or load into a tree that contours without crashing.
TEST(Format, ForgedFilesWithValidChecksumNeverCrash) {
  const auto bytes = serialize(small_tree());
  std::mt19937_64 rng(99);
  size_t rejected = 0, accepted = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    auto bad = bytes;
    const int flips = 1 + int(rng() % 4);
    for (int f = 0; f < flips; ++f) {
      // Half the flips in the header fields after the magic, half in the payload.
      const size_t lo = (rng() & 1) ? 6 : kHeaderBytes;
      const size_t i = lo + rng() % (bad.size() - 4 - lo);
      bad[i] ^= uint8_t(1u << (rng() % 8));
    }
    fix_crc(bad);
    try {
      const Octree t = deserialize(bad);
      ++accepted;
      (void)unsplit_contour(t);
      (void)analyze(t);
    } catch (const IoError&) {
      ++rejected;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "trial " << trial << ": wrong exception type: " << e.what();
    }
  }
  std::printf("  [measure] forged files: %zu rejected, %zu accepted\n", rejected, accepted);
  EXPECT_GT(rejected, 0u);
}

// A forged payload with a valid checksum is refused, or else it is a tree the construction
// could have made: its contour (what `pic mesh` writes) is closed and 2-manifold.
TEST(Format, ForgedFilesAreRefusedOrContourValid) {
  for (const auto& [tree, trials] : {std::pair{&small_tree(), 400}, std::pair{&sphere_tree(), 60}}) {
    const auto bytes = serialize(*tree);
    std::mt19937_64 rng(7);
    size_t rejected = 0, accepted = 0;
    for (int trial = 0; trial < trials; ++trial) {
      auto bad = bytes;
      const size_t i = kHeaderBytes + rng() % (bad.size() - 4 - kHeaderBytes);
      bad[i] ^= uint8_t(1u << (rng() % 8));
      fix_crc(bad);
      Octree t;
      try {
        t = deserialize(bad);
      } catch (const IoError&) {
        ++rejected;
        continue;
      }
      ++accepted;
      EXPECT_TRUE(IsClosedManifold(contour(t))) << "trial " << trial << ": byte " << i;
    }
    std::printf("  [measure] forged payloads: %zu refused, %zu accepted and valid\n", rejected, accepted);
    EXPECT_GT(rejected, 0u);
  }
}

// One corner sign of a gray leaf changed (the rest of the file intact): where the lattice
// point then has two signs, which the contour cannot close around, the file is refused; the
// others (a point no other leaf has as a corner or inside) contour closed.
TEST(Format, ALeafWithAChangedCornerSignIsRefusedOrValid) {
  const Octree& good = sphere_tree();
  std::vector<uint32_t> grays;
  for (uint32_t i = 0; i < good.nodes.size(); ++i)
    if (good.nodes[i].kind == CellKind::Gray) grays.push_back(i);
  ASSERT_FALSE(grays.empty());
  std::mt19937_64 rng(3);
  size_t refused = 0, valid = 0;
  for (int trial = 0; trial < 100; ++trial) {
    Octree t = good;
    Node& n = t.nodes[grays[rng() % grays.size()]];
    n.signs ^= uint8_t(1u << (rng() % 8));
    if (n.signs == 0 || n.signs == 0xff) continue;
    try {
      t = deserialize(serialize(t));
    } catch (const IoError&) {
      ++refused;
      continue;
    }
    ++valid;
    EXPECT_TRUE(IsClosedManifold(contour(t))) << "trial " << trial;
  }
  std::printf("  [measure] changed corner signs: %zu refused, %zu accepted and valid\n", refused, valid);
  EXPECT_GT(refused, valid);
}

TEST(Format, ForgedHeaderFieldsAreRejected) {
  const auto good = serialize(small_tree());
  auto forge = [&](size_t offset, const void* value, size_t n) {
    auto b = good;
    std::memcpy(b.data() + offset, value, n);
    fix_crc(b);
    return b;
  };
  const uint8_t depth0 = 0, depth21 = 21, depth1 = 1;
  expect_io_error(forge(8, &depth0, 1), "depth 0");
  expect_io_error(forge(8, &depth21, 1), "depth 21");
  expect_io_error(forge(8, &depth1, 1), "depth smaller than the tree");
  const double nan = std::nan(""), zero = 0, neg = -1, inf = INFINITY;
  expect_io_error(forge(36, &nan, 8), "NaN cube size");
  expect_io_error(forge(36, &zero, 8), "zero cube size");
  expect_io_error(forge(36, &neg, 8), "negative cube size");
  expect_io_error(forge(36, &inf, 8), "infinite cube size");
  expect_io_error(forge(12, &nan, 8), "NaN cube origin");
  expect_io_error(forge(12, &inf, 8), "infinite cube origin");
  const uint64_t huge = uint64_t{1} << 62, zero64 = 0, one = 1;
  expect_io_error(forge(44, &huge, 8), "huge node count");
  expect_io_error(forge(44, &zero64, 8), "zero node count");
  expect_io_error(forge(44, &one, 8), "node count too small");
  expect_io_error(forge(52, &huge, 8), "huge gray count");
  expect_io_error(forge(52, &zero64, 8), "zero gray count");
  expect_io_error(forge(60, &huge, 8), "huge payload size");
  const uint16_t v2 = 2;
  try {
    (void)deserialize(forge(4, &v2, 2));
    ADD_FAILURE() << "version 2 accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("version"), std::string::npos) << e.what();
  }
}

TEST(Format, ForeignEmptyAndMissingFilesGiveClearErrors) {
  TempDir dir;
  auto expect_message = [&](const fs::path& p, const std::string& part) {
    try {
      (void)load(p);
      ADD_FAILURE() << p << ": accepted";
    } catch (const IoError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(p.filename().string()), std::string::npos) << "message names the file: " << msg;
      EXPECT_NE(msg.find(part), std::string::npos) << msg;
    }
  };
  // An OBJ renamed .pic.
  fs::copy_file(std::string(PIC_DATA_DIR) + "/fandisk.obj", dir / "fandisk.pic");
  expect_message(dir / "fandisk.pic", "not a .pic file");
  // A file that starts like a .pic but is only the magic.
  write_raw(dir / "magic.pic", {'P', 'I', 'C', 'F'});
  expect_message(dir / "magic.pic", "truncated");
  write_raw(dir / "empty.pic", {});
  expect_message(dir / "empty.pic", "empty.pic");
  expect_message(dir / "missing.pic", "no such file");
  fs::create_directories(dir / "folder.pic");
  expect_message(dir / "folder.pic", "directory");
  // Random bytes.
  std::vector<uint8_t> noise(5000);
  std::mt19937_64 rng(3);
  for (auto& b : noise) b = uint8_t(rng());
  write_raw(dir / "noise.pic", noise);
  expect_message(dir / "noise.pic", "not a .pic file");
}

// ---------------------------------------------------------------------------------------
// Atomic writes.

TEST(Format, SaveIntoMissingDirectoryThrowsAndLeavesNothing) {
  TempDir dir;
  const fs::path target = dir / "no" / "such" / "dir" / "x.pic";
  EXPECT_THROW(save(sphere_tree(), target), IoError);
  EXPECT_FALSE(fs::exists(dir / "no"));
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Format, SaveReplacesAnExistingFileAndLeavesNoTemporaries) {
  TempDir dir;
  const fs::path target = dir / "x.pic";
  write_raw(target, {'o', 'l', 'd'});
  save(sphere_tree(), target);
  EXPECT_TRUE(read_bytes(target) == serialize(sphere_tree()));
  save(small_tree(), target);
  EXPECT_TRUE(read_bytes(target) == serialize(small_tree()));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"x.pic"});
  const Octree back = load(target);
  EXPECT_EQ(back.vertices.size(), small_tree().vertices.size());
}

TEST(Format, FailedSaveOverADirectoryKeepsItAndLeavesNoTemporaries) {
  TempDir dir;
  const fs::path target = dir / "taken.pic";
  fs::create_directories(target / "inner");
  write_raw(target / "inner" / "keep.txt", {'k'});
  EXPECT_THROW(save(sphere_tree(), target), IoError);
  EXPECT_TRUE(fs::is_directory(target));
  EXPECT_TRUE(fs::exists(target / "inner" / "keep.txt"));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"taken.pic"});
}

TEST(Format, WriteTextIsAtomicToo) {
  TempDir dir;
  write_text(dir / "a.txt", "first");
  write_text(dir / "a.txt", "second");
  const auto b = read_bytes(dir / "a.txt");
  EXPECT_EQ(std::string(b.begin(), b.end()), "second");
  EXPECT_THROW(write_text(dir / "missing" / "a.txt", "x"), IoError);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"a.txt"});
}

}  // namespace
}  // namespace pic
