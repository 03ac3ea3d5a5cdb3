// Mesh files: write/read round trips for every format, welding, errors, degenerate input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

// A fresh directory per test, removed afterwards.
struct TempDir : test::TempDir {
  TempDir() : test::TempDir("pic_meshio") {}
};

void write_file(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
}

// A closed mesh with some non-trivial coordinates (sphere, offset and scaled).
TriMesh test_mesh() { return make_sphere({1.5, -2.25, 0.75}, 1.25, 24); }

// Same connectivity up to vertex order, positions within `tol`.
void expect_same_mesh(const TriMesh& a, const TriMesh& b, double tol) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  EXPECT_TRUE(IsClosedManifold(b));
  EXPECT_NEAR(volume(b), volume(a), 1e-5 * std::abs(volume(a)));
  // Every vertex of b is near a vertex of a and vice versa.
  double worst = 0;
  for (const Vec3& p : b.positions) worst = std::max(worst, test::nearest_vertex_distance(a, p));
  for (const Vec3& p : a.positions) worst = std::max(worst, test::nearest_vertex_distance(b, p));
  EXPECT_LE(worst, tol);
}

class MeshIoRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(MeshIoRoundTrip, WriteThenReadGivesTheSameMesh) {
  TempDir dir;
  const TriMesh m = test_mesh();
  const fs::path p = dir / ("m" + GetParam());
  write_mesh(m, p);
  ASSERT_TRUE(fs::exists(p));
  EXPECT_EQ(dir.entries().size(), 1u) << "no temporary or side files";
  const TriMesh back = read_mesh(p);
  // Readers go through single precision: ~1e-7 relative to the coordinates (~3).
  expect_same_mesh(m, back, 2e-6);
}

INSTANTIATE_TEST_SUITE_P(MeshIo, MeshIoRoundTrip, ::testing::Values(".obj", ".stl", ".ply", ".off", ".glb"),
                         [](const auto& info) { return info.param.substr(1); });

TEST(MeshIo, UppercaseExtensionsWork) {
  TempDir dir;
  write_mesh(test_mesh(), dir / "UP.OBJ");
  expect_same_mesh(test_mesh(), read_mesh(dir / "UP.OBJ"), 2e-6);
}

TEST(MeshIo, FandiskReadsClosedAndManifold) {
  const TriMesh m = read_mesh(std::string(PIC_DATA_DIR) + "/fandisk.obj");
  EXPECT_EQ(m.positions.size(), 6475u);
  EXPECT_EQ(m.triangles.size(), 12946u);
  EXPECT_TRUE(IsClosedManifold(m));
  EXPECT_GT(volume(m), 0);
}

TEST(MeshIo, PerFaceObjBoxIsWeldedToEightVertices) {
  TempDir dir;
  // Each face of the unit cube with its own four vertices: 24 vertices, 6 quads.
  std::string obj = "# per-face box\n";
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  int next = 1;
  std::string faces;
  for (const auto& q : quads) {
    for (int k = 0; k < 4; ++k) {
      const int c = q[k];
      obj += "v " + std::to_string(c & 1) + " " + std::to_string((c >> 1) & 1) + " " + std::to_string((c >> 2) & 1) + "\n";
    }
    faces += "f " + std::to_string(next) + " " + std::to_string(next + 1) + " " + std::to_string(next + 2) + " " +
             std::to_string(next + 3) + "\n";
    next += 4;
  }
  write_file(dir / "box.obj", obj + faces);
  const TriMesh m = read_mesh(dir / "box.obj");
  EXPECT_EQ(m.positions.size(), 8u);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_TRUE(IsClosedManifold(m));
  EXPECT_NEAR(volume(m), 1.0, 1e-12);
}

TEST(MeshIo, HandWrittenAsciiStlIsWelded) {
  TempDir dir;
  // A tetrahedron, each facet listing its own vertices; -0 must weld with 0.
  const char* stl =
      "solid tet\n"
      "facet normal 0 0 -1\n outer loop\n  vertex 0 0 0\n  vertex 0 1 0\n  vertex 1 0 0\n endloop\nendfacet\n"
      "facet normal 0 -1 0\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 0 1\n endloop\nendfacet\n"
      "facet normal -1 0 0\n outer loop\n  vertex -0 0 0\n  vertex 0 0 1\n  vertex 0 1 0\n endloop\nendfacet\n"
      "facet normal 1 1 1\n outer loop\n  vertex 1 0 0\n  vertex 0 1 0\n  vertex 0 0 1\n endloop\nendfacet\n"
      "endsolid tet\n";
  write_file(dir / "tet.stl", stl);
  const TriMesh m = read_mesh(dir / "tet.stl");
  EXPECT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.triangles.size(), 4u);
  EXPECT_TRUE(IsClosedManifold(m));
  EXPECT_NEAR(volume(m), 1.0 / 6, 1e-7);
  // And it samples.
  SampleOptions o;
  o.depth = 6;
  const TriMesh c = unsplit_contour(sample(m, o));
  EXPECT_TRUE(IsClosedManifold(c));
  EXPECT_NEAR(volume(c), 1.0 / 6, 1e-3);
}

TEST(MeshIo, HandWrittenAsciiPlyAndOff) {
  TempDir dir;
  const std::string verts = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  write_file(dir / "t.off", "OFF\n4 4 0\n" + verts + "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  write_file(dir / "t.ply",
             "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 4\nproperty list uchar int vertex_indices\nend_header\n" +
                 verts + "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  for (const char* name : {"t.off", "t.ply"}) {
    SCOPED_TRACE(name);
    const TriMesh m = read_mesh(dir / name);
    EXPECT_EQ(m.positions.size(), 4u);
    EXPECT_EQ(m.triangles.size(), 4u);
    EXPECT_TRUE(IsClosedManifold(m));
    EXPECT_NEAR(volume(m), 1.0 / 6, 1e-7);
  }
}

// ---------------------------------------------------------------------------------------
// Errors

// Runs `f`, expecting IoError or InvalidInput whose message contains `part`.
template <class F>
void expect_input_error(F f, const std::string& part, const std::string& what) {
  try {
    f();
    ADD_FAILURE() << what << ": no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << what << ": " << e.what();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << what << ": " << e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": wrong exception type: " << e.what();
  }
}

TEST(MeshIo, MissingFileIsAnIoError) {
  TempDir dir;
  EXPECT_THROW(read_mesh(dir / "nope.obj"), IoError);
  expect_input_error([&] { read_mesh(dir / "nope.obj"); }, "nope.obj", "missing file");
}

TEST(MeshIo, UnknownExtensionIsAnIoError) {
  TempDir dir;
  write_file(dir / "notes.xyz", "hello, this is not a mesh\n");
  EXPECT_THROW(read_mesh(dir / "notes.xyz"), IoError);
  expect_input_error([&] { read_mesh(dir / "notes.xyz"); }, "unknown or unsupported mesh format '.xyz'", "unknown extension");
  // Unknown extension, but the content looks like a (too small) OBJ: assimp sniffs the
  // content, so either error type is acceptable as long as the file is named.
  write_file(dir / "box.xyz", "v 0 0 0\n");
  expect_input_error([&] { read_mesh(dir / "box.xyz"); }, "box.xyz", "unknown extension, OBJ-like content");
  EXPECT_THROW(write_mesh(test_mesh(), dir / "out.xyz"), IoError);
  EXPECT_THROW(write_mesh(test_mesh(), dir / "noext"), IoError);
  EXPECT_FALSE(fs::exists(dir / "out.xyz"));
  EXPECT_EQ(dir.entries().size(), 2u);
}

TEST(MeshIo, EmptyFileIsRejected) {
  TempDir dir;
  write_file(dir / "empty.obj", "");
  expect_input_error([&] { read_mesh(dir / "empty.obj"); }, "empty", "empty file");
  write_file(dir / "empty.stl", "");
  expect_input_error([&] { read_mesh(dir / "empty.stl"); }, "empty", "empty stl");
}

TEST(MeshIo, ObjWithoutTrianglesIsRejected) {
  TempDir dir;
  write_file(dir / "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  expect_input_error([&] { read_mesh(dir / "points.obj"); }, "points.obj", "vertices only");
  write_file(dir / "comments.obj", "# nothing here\n\n");
  expect_input_error([&] { read_mesh(dir / "comments.obj"); }, "comments.obj", "comments only");
}

TEST(MeshIo, MalformedObjIsRejected) {
  TempDir dir;
  write_file(dir / "badindex.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n");
  expect_input_error([&] { read_mesh(dir / "badindex.obj"); }, "badindex.obj", "face index out of range");
  const char garbage[] = "\x01\x02\x03\xff\xfe garbage \x00 more";  // with its NUL inside
  write_file(dir / "garbage.obj", std::string(garbage, sizeof garbage - 1));
  expect_input_error([&] { read_mesh(dir / "garbage.obj"); }, "garbage.obj", "binary garbage");
}

TEST(MeshIo, NonFiniteCoordinatesAreRejected) {
  TempDir dir;
  const std::string faces = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  for (const char* bad : {"nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1e999"}) {
    SCOPED_TRACE(bad);
    write_file(dir / "bad.obj", std::string("v 0 0 0\nv 1 0 0\nv 0 ") + bad + " 0\nv 0 0 1\n" + faces);
    expect_input_error([&] { read_mesh(dir / "bad.obj"); }, "non-finite", bad);
  }
  // Binary STL with a NaN coordinate.
  TriMesh m = make_box({0, 0, 0}, {1, 1, 1});
  m.positions[2][0] = std::nan("");
  write_mesh(m, dir / "nan.stl");
  expect_input_error([&] { read_mesh(dir / "nan.stl"); }, "non-finite", "binary stl");
  // Binary PLY (doubles) with an infinity.
  m.positions[2][0] = INFINITY;
  write_mesh(m, dir / "inf.ply");
  expect_input_error([&] { read_mesh(dir / "inf.ply"); }, "non-finite", "binary ply");
}

TEST(MeshIo, WriteIntoMissingDirectoryThrowsAndLeavesNothing) {
  TempDir dir;
  for (const char* ext : {".obj", ".stl", ".ply", ".off", ".glb"}) {
    SCOPED_TRACE(ext);
    EXPECT_THROW(write_mesh(test_mesh(), dir / (std::string("missing/m") + ext)), IoError);
  }
  EXPECT_EQ(dir.entries().size(), 0u);
}

TEST(MeshIo, WriteReplacesAnExistingFile) {
  TempDir dir;
  write_file(dir / "m.obj", "old contents\n");
  write_mesh(make_box({0, 0, 0}, {2, 1, 1}), dir / "m.obj");
  const TriMesh back = read_mesh(dir / "m.obj");
  EXPECT_EQ(back.positions.size(), 8u);
  EXPECT_NEAR(volume(back), 2.0, 1e-9);
  EXPECT_EQ(dir.entries().size(), 1u);
}

// ---------------------------------------------------------------------------------------
// Degenerate triangles on a closed box: tolerated by sampling.

TEST(MeshIo, DegenerateTrianglesAreToleratedBySampling) {
  TriMesh box = make_box({0.2, 0.3, 0.25}, {0.8, 0.7, 0.75});
  const double v = 0.6 * 0.4 * 0.5;
  // Repeated indices.
  box.triangles.push_back({0, 0, 1});
  box.triangles.push_back({5, 5, 5});
  // A zero-area sliver along the edge 0-1 and its reverse (keeps every edge paired).
  box.positions.push_back({0.5, 0.3, 0.25});
  const auto mid = static_cast<uint32_t>(box.positions.size() - 1);
  box.triangles.push_back({0, mid, 1});
  box.triangles.push_back({1, mid, 0});
  SampleOptions o;
  o.depth = 8;
  o.cube = Cube{{0, 0, 0}, 1};
  SampleStats st;
  const TriMesh c = unsplit_contour(sample(box, o, &st));
  ASSERT_TRUE(IsClosedManifold(c));
  EXPECT_NEAR(volume(c), v, 1e-6 * v);
  EXPECT_EQ(st.capped, 0u);
  for (const Vec3& p : c.positions) EXPECT_LE(test::box_surface_distance(p, {0.2, 0.3, 0.25}, {0.8, 0.7, 0.75}), 1e-6);
}

TEST(MeshIo, DegenerateFacesInAFileAreTolerated) {
  TempDir dir;
  write_mesh(make_box({0, 0, 0}, {1, 1, 1}), dir / "box.obj");
  {
    std::ofstream out(dir / "box.obj", std::ios::app);
    out << "f 1 1 2\nf 3 3 3\n";
  }
  const TriMesh m = read_mesh(dir / "box.obj");
  SampleOptions o;
  o.depth = 7;
  const TriMesh c = unsplit_contour(sample(m, o));
  ASSERT_TRUE(IsClosedManifold(c));
  EXPECT_NEAR(volume(c), 1.0, 1e-6);
}

}  // namespace
}  // namespace pic
