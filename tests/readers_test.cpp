// PIC's own mesh readers (src/io/): every PLY type and layout, OFF variants, STL detection by
// size, OBJ corner forms, point clouds (read_geometry), and the refusals of bad or oversized
// files — each checked for the geometry read back, or for the error and how fast it comes.
// The files under tests/data/fuzz/ (inputs the fuzzers once broke) are replayed here too.
#include <gtest/gtest.h>
#include <dlfcn.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "pic/pic.h"
#include "support/mesh_checks.h"
#include "support/temp_dir.h"

namespace pic {
namespace {

namespace fs = std::filesystem;
using test::IsClosedManifold;

struct TempDir : test::TempDir {
  TempDir() : test::TempDir("pic_readers") {}
};

void write_file(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << bytes;
}

template <class T>
std::string le(T v) {
  std::string s(sizeof(T), '\0');
  std::memcpy(s.data(), &v, sizeof(T));
  return s;
}
template <class T>
std::string be(T v) {
  std::string s = le(v);
  return std::string(s.rbegin(), s.rend());
}

// Runs `f` and returns the message of the InvalidInput/IoError it throws ("" if none).
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

const double kTet[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
const int kTetFaces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
const int kCubeQuads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};

void expect_tet(const TriMesh& m) {
  EXPECT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.triangles.size(), 4u);
  EXPECT_TRUE(IsClosedManifold(m));
  EXPECT_NEAR(volume(m), 1.0 / 6, 1e-12);
}

void expect_unit_cube(const TriMesh& m) {
  EXPECT_EQ(m.positions.size(), 8u);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_TRUE(IsClosedManifold(m));
  EXPECT_NEAR(volume(m), 1.0, 1e-12);
}

std::string cube_ascii_ply(const std::string& face_list) {
  std::string s = "ply\nformat ascii 1.0\ncomment a cube of quads\nelement vertex 8\nproperty float x\n"
                  "property float y\nproperty float z\nelement face 6\n" + face_list + "\nend_header\n";
  for (int c = 0; c < 8; ++c) s += std::to_string(c & 1) + " " + std::to_string(c >> 1 & 1) + " " + std::to_string(c >> 2 & 1) + "\n";
  for (const auto& q : kCubeQuads) s += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) + " " + std::to_string(q[3]) + "\n";
  return s;
}

// ---------------------------------------------------------------------------------------
// PLY

TEST(Readers, PlyAsciiQuadsAreFanned) {
  TempDir dir;
  write_file(dir / "a.ply", cube_ascii_ply("property list uchar int vertex_indices"));
  expect_unit_cube(read_mesh(dir / "a.ply"));
  write_file(dir / "b.ply", cube_ascii_ply("property list int uint vertex_index"));  // other spelling and types
  expect_unit_cube(read_mesh(dir / "b.ply"));
}

TEST(Readers, PlyBinaryBigEndianWithUnknownElementsAndProperties) {
  TempDir dir;
  // int16 coordinates, an unknown uchar property, an unknown list on faces, an unknown element.
  std::string s = "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty short x\nproperty uchar red\n"
                  "property short y\nproperty short z\nelement face 4\nproperty float quality\n"
                  "property list ushort uint vertex_indices\nproperty list uchar double texcoord\n"
                  "element material 2\nproperty list uint int16 stuff\nend_header\n";
  for (const auto& p : kTet) s += be<int16_t>(int16_t(p[0] * 2)) + be<uint8_t>(7) + be<int16_t>(int16_t(p[1] * 2)) + be<int16_t>(int16_t(p[2] * 2));
  for (const auto& f : kTetFaces) {
    s += be<float>(0.5f) + be<uint16_t>(3);
    for (int i : f) s += be<uint32_t>(uint32_t(i));
    s += be<uint8_t>(2) + be<double>(0.25) + be<double>(0.75);
  }
  s += be<uint32_t>(1) + be<int16_t>(5) + be<uint32_t>(0);
  write_file(dir / "t.ply", s);
  const TriMesh m = read_mesh(dir / "t.ply");
  ASSERT_EQ(m.triangles.size(), 4u);
  EXPECT_TRUE(IsClosedManifold(m));
  EXPECT_NEAR(volume(m), 8.0 / 6, 1e-12);  // coordinates doubled
}

TEST(Readers, PlyBinaryLittleEndianEveryScalarType) {
  TempDir dir;
  for (const char* type : {"char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "float64"}) {
    SCOPED_TRACE(type);
    const std::string t = type;
    auto val = [&](double v) -> std::string {
      if (t == "char" || t == "int8") return le<int8_t>(int8_t(v));
      if (t == "uchar") return le<uint8_t>(uint8_t(v));
      if (t == "short") return le<int16_t>(int16_t(v));
      if (t == "ushort") return le<uint16_t>(uint16_t(v));
      if (t == "int") return le<int32_t>(int32_t(v));
      if (t == "uint") return le<uint32_t>(uint32_t(v));
      if (t == "float") return le<float>(float(v));
      return le<double>(v);
    };
    std::string s = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty " + t + " x\nproperty " + t +
                    " y\nproperty " + t + " z\nelement face 4\nproperty list " + (t == "float" || t == "double" || t == "float64" ? "uchar" : t) +
                    " " + (t == "float" || t == "double" || t == "float64" ? "int" : t) + " vertex_indices\nend_header\n";
    for (const auto& p : kTet) s += val(p[0]) + val(p[1]) + val(p[2]);
    for (const auto& f : kTetFaces) {
      if (t == "float" || t == "double" || t == "float64") {
        s += le<uint8_t>(3);
        for (int i : f) s += le<int32_t>(i);
      } else {
        s += val(3);
        for (int i : f) s += val(i);
      }
    }
    write_file(dir / "t.ply", s);
    expect_tet(read_mesh(dir / "t.ply"));
  }
}

TEST(Readers, PlyHugeDeclaredCountIsRefusedAtOnce) {
  TempDir dir;
  const std::string head = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\n"
                           "property float y\nproperty float z\nend_header\n";
  write_file(dir / "huge.ply", head + std::string(1024 - head.size(), '\0'));
  const auto t0 = std::chrono::steady_clock::now();
  const std::string e = error_of([&] { read_mesh(dir / "huge.ply"); });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(contains(e, "declares 1000000000 vertices but the file has only 1024 bytes")) << e;
  EXPECT_LT(seconds, 1.0);
  // The same in ASCII, and for faces, and for an element with a list.
  write_file(dir / "huge2.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                                "element face 99999999999\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n");
  EXPECT_TRUE(contains(error_of([&] { read_mesh(dir / "huge2.ply"); }), "declares 99999999999 faces")) << error_of([&] { read_mesh(dir / "huge2.ply"); });
  // Elements without properties take no bytes, whatever their count: nothing to loop over.
  write_file(dir / "empty_elem.ply", "ply\nformat ascii 1.0\nelement nothing 999999999999999999\n" + cube_ascii_ply("property list uchar int vertex_indices").substr(std::strlen("ply\nformat ascii 1.0\n")));
  expect_unit_cube(read_mesh(dir / "empty_elem.ply"));
}

TEST(Readers, PlyDamagedHeadersAreRefused) {
  TempDir dir;
  const std::string good = cube_ascii_ply("property list uchar int vertex_indices");
  struct Case {
    std::string from, to, message;
  };
  for (const Case& c : std::vector<Case>{{"end_header", "end_h", "unknown header keyword 'end_h'"},
                                         {"format ascii", "format ascii_x", "unknown format"},
                                         {"property float y", "property flt y", "unknown property type"},
                                         {"vertex_indices", "indices", "no vertex_indices list"},
                                         {"element vertex 8", "element vertex 9", "data ends early"},
                                         {"4 0 2 3 1", "4 0 2 3 100", "face index 100 out of range (8 vertices)"},
                                         {"ply\n", "plx\n", "does not start with 'ply'"}}) {
    SCOPED_TRACE(c.to);
    std::string bad = good;
    bad.replace(bad.find(c.from), c.from.size(), c.to);
    write_file(dir / "bad.ply", bad);
    const std::string e = error_of([&] { read_mesh(dir / "bad.ply"); });
    EXPECT_TRUE(contains(e, c.message)) << e;
    EXPECT_TRUE(contains(e, "bad.ply")) << e;
  }
  // A header cut short and no end_header at all.
  write_file(dir / "cut.ply", good.substr(0, good.find("end_header") + 5));
  EXPECT_FALSE(error_of([&] { read_mesh(dir / "cut.ply"); }).empty());
}

TEST(Readers, PlyWrittenByPicReadsBackExactly) {
  TempDir dir;
  TriMesh m;
  m.positions = {{0.1, 0.2, 0.3}, {1.0 / 3, 0, 0}, {0, 1e-300, 0}, {0, 0, 1}};
  for (const auto& f : kTetFaces) m.triangles.push_back({uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
  write_mesh(m, dir / "m.ply");
  const TriMesh back = read_mesh(dir / "m.ply");
  ASSERT_EQ(back.positions.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(back.positions[i], m.positions[i]);  // doubles, bit-exact
  EXPECT_EQ(back.triangles, m.triangles);
}

// ---------------------------------------------------------------------------------------
// Point clouds

std::string cloud_ply(bool normals, const std::string& faces) {
  std::string s = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n";
  if (normals) s += "property float nx\nproperty float ny\nproperty float nz\n";
  s += faces + "end_header\n";
  for (const auto& p : kTet) {
    s += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]);
    if (normals) s += " " + std::to_string(p[0] - 0.25) + " " + std::to_string(p[1] - 0.25) + " " + std::to_string(p[2] - 0.25);
    s += "\n";
  }
  return s;
}

TEST(Readers, PlyPointCloudWithNormals) {
  TempDir dir;
  for (const std::string faces : {"", "element face 0\nproperty list uchar int vertex_indices\n"}) {
    write_file(dir / "pc.ply", cloud_ply(true, faces));
    const Geometry g = read_geometry(dir / "pc.ply");
    ASSERT_TRUE(g.is_point_cloud());
    ASSERT_EQ(g.points.positions.size(), 4u);
    ASSERT_EQ(g.points.normals.size(), 4u);
    for (size_t i = 0; i < 4; ++i)
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(g.points.positions[i][k], kTet[i][k]);
        EXPECT_EQ(g.points.normals[i][k], kTet[i][k] - 0.25);
      }
    // read_mesh wants triangles.
    const std::string e = error_of([&] { read_mesh(dir / "pc.ply"); });
    EXPECT_TRUE(contains(e, "has no triangles")) << e;
    EXPECT_TRUE(contains(e, "point cloud of 4 points")) << e;
  }
}

TEST(Readers, PointCloudWithoutNormalsIsRefused) {
  TempDir dir;
  write_file(dir / "pc.ply", cloud_ply(false, ""));
  const std::string e = error_of([&] { read_geometry(dir / "pc.ply"); });
  EXPECT_TRUE(contains(e, "point cloud has no normals (nx ny nz): normals are needed to tell inside from outside")) << e;
  write_file(dir / "pc.xyz", "# x y z only\n0 0 0\n1 0 0\n");
  const std::string x = error_of([&] { read_geometry(dir / "pc.xyz"); });
  EXPECT_TRUE(contains(x, "line 2 has x y z but no normals")) << x;
}

TEST(Readers, XyzPointCloud) {
  TempDir dir;
  write_file(dir / "pc.xyz", "# scan\n\n0 0 0  -1 -1 -1\n1 0 0 1 0 0 # a comment\r\n0 1 0 0 1 0\n0 0 1 0 0 1");
  const Geometry g = read_geometry(dir / "pc.xyz");
  ASSERT_TRUE(g.is_point_cloud());
  ASSERT_EQ(g.points.positions.size(), 4u);
  EXPECT_EQ(g.points.positions[3], (Vec3{0, 0, 1}));
  EXPECT_EQ(g.points.normals[0], (Vec3{-1, -1, -1}));
  write_file(dir / "bad.xyz", "0 0 0 1 0\n");
  EXPECT_TRUE(contains(error_of([&] { read_geometry(dir / "bad.xyz"); }), "expected 6 numbers"));
  write_file(dir / "nan.xyz", "0 0 0 1 0 nan\n");
  EXPECT_TRUE(contains(error_of([&] { read_geometry(dir / "nan.xyz"); }), "non-finite"));
  // An .xyz file is not a mesh.
  EXPECT_THROW(read_mesh(dir / "pc.xyz"), IoError);
}

TEST(Readers, ReadGeometryOfAMeshGivesTheMesh) {
  TempDir dir;
  write_file(dir / "a.ply", cube_ascii_ply("property list uchar int vertex_indices"));
  const Geometry g = read_geometry(dir / "a.ply");
  EXPECT_FALSE(g.is_point_cloud());
  expect_unit_cube(g.mesh);
  EXPECT_TRUE(g.points.positions.empty());
}

// ---------------------------------------------------------------------------------------
// OFF, STL, OBJ

TEST(Readers, OffVariantsAndComments) {
  TempDir dir;
  std::string coff = "COFF # colors per vertex and face\n# counts next\n8 6 12\n";
  for (int c = 0; c < 8; ++c) coff += std::to_string(c & 1) + " " + std::to_string(c >> 1 & 1) + " " + std::to_string(c >> 2 & 1) + " 255 0 0 255\n";
  for (const auto& q : kCubeQuads) coff += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) + " " + std::to_string(q[3]) + " 0.5 0.5 0.5\n";
  write_file(dir / "c.off", coff);
  expect_unit_cube(read_mesh(dir / "c.off"));
  std::string noff = "NOFF 4 4 0\n";
  for (const auto& p : kTet) noff += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + " 0 0 1\n";
  for (const auto& f : kTetFaces) noff += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
  write_file(dir / "n.off", noff);
  expect_tet(read_mesh(dir / "n.off"));
  write_file(dir / "huge.off", "OFF\n1000000000 1 0\n0 0 0\n");
  EXPECT_TRUE(contains(error_of([&] { read_mesh(dir / "huge.off"); }), "declares 1000000000 vertices but the file has only"));
  write_file(dir / "bin.off", "OFF BINARY\n");
  EXPECT_TRUE(contains(error_of([&] { read_mesh(dir / "bin.off"); }), "binary OFF is not supported"));
  write_file(dir / "range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
  EXPECT_TRUE(contains(error_of([&] { read_mesh(dir / "range.off"); }), "vertex index 3 out of range (3 vertices)"));
}

std::string binary_stl(const std::string& header80_prefix, uint32_t declared, int facets) {
  std::string s = header80_prefix;
  s.resize(80, ' ');
  s += le<uint32_t>(declared);
  for (int f = 0; f < facets; ++f) {
    s += le<float>(0) + le<float>(0) + le<float>(0);
    for (int i : kTetFaces[f % 4])
      for (int k = 0; k < 3; ++k) s += le<float>(float(kTet[i][k]));
    s += std::string(2, '\0');
  }
  return s;
}

TEST(Readers, StlBinaryIsDetectedBySizeNotByTheWordSolid) {
  TempDir dir;
  write_file(dir / "b.stl", binary_stl("solid this header lies", 4, 4));
  expect_tet(read_mesh(dir / "b.stl"));
  write_file(dir / "short.stl", binary_stl("binary", 5, 4));  // declares one facet too many
  const std::string e = error_of([&] { read_mesh(dir / "short.stl"); });
  EXPECT_TRUE(contains(e, "declares 5 triangles (334 bytes) but the file has 284 bytes")) << e;
  write_file(dir / "huge.stl", binary_stl("binary", 4000000000u, 1));
  EXPECT_TRUE(contains(error_of([&] { read_mesh(dir / "huge.stl"); }), "declares 4000000000 triangles"));
}

TEST(Readers, StlAsciiQuadFacetsAndTruncation) {
  TempDir dir;
  std::string s = "solid cube\n";
  for (const auto& q : kCubeQuads) {
    s += "  facet normal 0 0 0\n    outer loop\n";
    for (int c : q) s += "      vertex " + std::to_string(c & 1) + " " + std::to_string(c >> 1 & 1) + " " + std::to_string(c >> 2 & 1) + "\n";
    s += "    endloop\n  endfacet\n";
  }
  s += "endsolid cube\n";
  write_file(dir / "c.stl", s);
  expect_unit_cube(read_mesh(dir / "c.stl"));
  write_file(dir / "cut.stl", s.substr(0, s.find("endloop", s.size() / 2)));
  EXPECT_TRUE(contains(error_of([&] { read_mesh(dir / "cut.stl"); }), "ends inside a facet"));
  write_file(dir / "junk.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 zero\n");
  EXPECT_TRUE(contains(error_of([&] { read_mesh(dir / "junk.stl"); }), "line 4: expected a number, found 'zero'"));
}

TEST(Readers, ObjCornerFormsAndNegativeIndices) {
  TempDir dir;
  std::string s = "mtllib x.mtl\no cube\n";
  for (int c = 0; c < 8; ++c) s += "v " + std::to_string(c & 1) + " " + std::to_string(c >> 1 & 1) + " " + std::to_string(c >> 2 & 1) + "\n";
  s += "vt 0 0\nvn 0 0 1\ng a\nusemtl m\ns 1\n";
  s += "f 1/1/1 3/1/1 4/1/1 2/1/1\n";  // i/t/n
  s += "f 5//1 6//1 8//1 7//1\n";      // i//n
  s += "f 1/1 2/1 6/1 5/1\n";          // i/t
  s += "f -6 -2 -1 -5 # 3 7 8 4\n";    // relative
  s += "f 1 5 7 3\nf 2 4 8 6\nl 1 2\np 3\n";
  write_file(dir / "c.obj", s);
  expect_unit_cube(read_mesh(dir / "c.obj"));
  write_file(dir / "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
  EXPECT_TRUE(contains(error_of([&] { read_mesh(dir / "zero.obj"); }), "line 4: vertex index 0"));
  write_file(dir / "rel.obj", "v 0 0 0\nf -1 -2 -3\n");
  EXPECT_TRUE(contains(error_of([&] { read_mesh(dir / "rel.obj"); }), "before the first vertex"));
}

// ---------------------------------------------------------------------------------------
// Regression inputs from fuzzing: tests/data/fuzz/<anything>.<ext>. Each must be refused with
// a library error by read_mesh, and by the CLI with exit 2 and one line "pic: error: ...",
// within a few seconds.

int run_cli(const std::string& args, std::string& err) {
  const fs::path e = fs::temp_directory_path() / ("pic_readers_err_" + std::to_string(::getpid()));
  const std::string cmd = "timeout 20 '" + std::string(PIC_CLI) + "' " + args + " 2> '" + e.string() + "' > /dev/null";
  const int status = std::system(cmd.c_str());
  std::ifstream in(e);
  err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  fs::remove(e);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Readers, FuzzRegressionInputsAreRefusedCleanly) {
  const fs::path root = fs::path(PIC_TESTS_DIR) / "data" / "fuzz";
  ASSERT_TRUE(fs::is_directory(root));
  TempDir dir;
  size_t n = 0;
  for (const auto& entry : fs::directory_iterator(root)) {
    if (!entry.is_regular_file() || entry.path().extension() == ".md") continue;
    const fs::path f = entry.path();
    SCOPED_TRACE(f.filename().string());
    ++n;
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_FALSE(error_of([&] { read_mesh(f); }).empty()) << "read_mesh accepted it";
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
    std::string err;
    const int code = run_cli("sample '" + f.string() + "' -o '" + (dir / "out.pic").string() + "'", err);
    EXPECT_EQ(code, 2) << err;
    EXPECT_EQ(err.rfind("pic: error: ", 0), 0u) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_FALSE(fs::exists(dir / "out.pic"));
  }
  EXPECT_GT(n, 0u);
}

TEST(Readers, CliRefusesAGiganticDepth) {
  TempDir dir;
  write_file(dir / "t.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  std::string err;
  EXPECT_EQ(run_cli("sample '" + (dir / "t.off").string() + "' --depth 1000000 -o '" + (dir / "o.pic").string() + "'", err), 2);
  EXPECT_EQ(err.rfind("pic: error: depth must be between 1 and", 0), 0u) << err;
}

}  // namespace
}  // namespace pic

namespace Assimp {
void aiAssertViolation(const char* expression, const char* file, int line);
}

namespace pic {
namespace {

// assimp's internal asserts call Assimp::aiAssertViolation through the dynamic linker; PIC's
// definition (src/io/assimp.cpp) must be the one the process resolves, and it must throw.
TEST(Readers, AssimpAssertsBecomeExceptions) {
  void* resolved = dlsym(RTLD_DEFAULT, "_ZN6Assimp17aiAssertViolationEPKcS1_i");
  ASSERT_NE(resolved, nullptr);
  EXPECT_EQ(resolved, reinterpret_cast<void*>(&Assimp::aiAssertViolation));
  EXPECT_THROW(Assimp::aiAssertViolation("numOut != pMesh->mNumFaces", "TriangulateProcess.cpp", 238), InvalidInput);
}

}  // namespace
}  // namespace pic
