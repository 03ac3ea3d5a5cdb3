// The `pic` command-line tool, run as a real process in a temporary directory.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "pic/pic.h"
#include "pic/primitives.h"
#include "support/mesh_checks.h"

namespace pic {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void write_text_file(const fs::path& p, const std::string& s) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << s;
}
std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct CliRun {
  int code = -1;
  std::string out, err;
  size_t err_lines() const { return static_cast<size_t>(std::count(err.begin(), err.end(), '\n')); }
};

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("pic_cli_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path path(const std::string& name) const { return dir_ / name; }

  // Runs `pic ARGS` in the temp dir, stdout and stderr captured separately.
  CliRun pic(const std::string& args) const {
    const std::string cmd = "cd " + quote(dir_.string()) + " && " + quote(PIC_CLI) + " " + args + " > " +
                            quote((dir_ / ".stdout").string()) + " 2> " + quote((dir_ / ".stderr").string());
    const int status = std::system(cmd.c_str());
    CliRun r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    r.out = read_text(dir_ / ".stdout");
    r.err = read_text(dir_ / ".stderr");
    fs::remove(dir_ / ".stdout");
    fs::remove(dir_ / ".stderr");
    return r;
  }

  // A failing command: non-zero exit, one line on stderr, `guarded` left byte-identical.
  void expect_clean_failure(const std::string& args, const std::string& guarded, const std::string& err_part = "") {
    SCOPED_TRACE("pic " + args);
    const std::string before = read_text(path(guarded));
    ASSERT_FALSE(before.empty());
    const CliRun r = pic(args);
    EXPECT_NE(r.code, 0);
    EXPECT_LT(r.code, 128) << "killed by a signal";
    EXPECT_EQ(r.err_lines(), 1u) << "stderr: " << r.err;
    EXPECT_EQ(r.err.rfind("pic: ", 0), 0u) << "stderr: " << r.err;
    if (!err_part.empty()) EXPECT_NE(r.err.find(err_part), std::string::npos) << "stderr: " << r.err;
    EXPECT_EQ(read_text(path(guarded)), before) << guarded << " was modified";
  }

  fs::path dir_;
};

// Value of a numeric key in a flat-ish JSON object; NaN when absent.
double json_number(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\"\\s*:\\s*(-?[0-9.eE+-]+)");
  std::smatch m;
  if (!std::regex_search(json, m, re)) return std::nan("");
  return std::stod(m[1].str());
}
bool json_has(const std::string& json, const std::string& key) {
  return json.find("\"" + key + "\":") != std::string::npos;
}
// One line, braces balanced.
void expect_json_object(const std::string& out) {
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.front(), '{') << out;
  EXPECT_EQ(out.substr(out.size() - 2), "}\n") << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '{'), std::count(out.begin(), out.end(), '}')) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '['), std::count(out.begin(), out.end(), ']')) << out;
}

std::string fandisk() { return quote(std::string(PIC_DATA_DIR) + "/fandisk.obj"); }

// A mesh that is written but is not a valid solid never passes silently: the plain split of
// fandisk at depth 10 (`--plain`) keeps crossing triangles, which --json's exact check counts. The file is
// written, the JSON says which count is off, one stderr line says so, and the exit code is 4.
TEST_F(Cli, InvalidOutputIsReportedWithExitCode4) {
  ASSERT_EQ(pic("sample " + fandisk() + " --depth 10 -o f.pic").code, 0);
  const CliRun fast = pic("mesh f.pic -o fast.obj --plain --json");
  EXPECT_EQ(fast.code, 4) << fast.err;
  expect_json_object(fast.out);
  EXPECT_GT(json_number(fast.out, "self_intersections"), 0);
  EXPECT_EQ(fast.err_lines(), 1u) << fast.err;
  EXPECT_NE(fast.err.find("fast.obj was written but is not a valid solid"), std::string::npos) << fast.err;
  EXPECT_NE(fast.err.find("self-intersecting"), std::string::npos) << fast.err;
  EXPECT_FALSE(read_mesh(path("fast.obj")).triangles.empty());
  // The default contour of the same tree is valid: exit 0, nothing on stderr.
  const CliRun clean = pic("mesh f.pic -o clean.obj --json");
  EXPECT_EQ(clean.code, 0) << clean.err;
  EXPECT_EQ(json_number(clean.out, "self_intersections"), 0);
  EXPECT_TRUE(clean.err.empty()) << clean.err;
}

TEST_F(Cli, SampleMeshInfoPipelineJson) {
  const CliRun s = pic("sample " + fandisk() + " -o x.pic --json");
  ASSERT_EQ(s.code, 0) << s.err;
  expect_json_object(s.out);
  for (const char* k : {"pics", "seconds", "depth", "error"}) EXPECT_TRUE(json_has(s.out, k)) << k << " in " << s.out;
  const double pics = json_number(s.out, "pics");
  EXPECT_GT(pics, 1000);
  EXPECT_EQ(json_number(s.out, "depth"), 12);
  EXPECT_DOUBLE_EQ(json_number(s.out, "error"), 1e-8);
  EXPECT_GE(json_number(s.out, "seconds"), 0);
  EXPECT_TRUE(s.err.empty()) << s.err;
  ASSERT_TRUE(fs::exists(path("x.pic")));
  EXPECT_EQ(load(path("x.pic")).vertices.size(), static_cast<size_t>(pics));

  const CliRun m = pic("mesh x.pic -o y.obj --json");
  ASSERT_EQ(m.code, 0) << m.err;
  expect_json_object(m.out);
  for (const char* k : {"vertices", "triangles", "seconds"}) EXPECT_TRUE(json_has(m.out, k)) << k << " in " << m.out;
  const TriMesh y = read_mesh(path("y.obj"));
  EXPECT_EQ(json_number(m.out, "vertices"), double(y.positions.size()));
  EXPECT_EQ(json_number(m.out, "triangles"), double(y.triangles.size()));
  EXPECT_TRUE(test::IsClosedManifold(y));
  EXPECT_NE(m.out.find("\"manifold\": true"), std::string::npos) << m.out;

  const CliRun i = pic("info x.pic --json");
  ASSERT_EQ(i.code, 0) << i.err;
  expect_json_object(i.out);
  for (const char* k : {"pics", "levels", "file_bytes"}) EXPECT_TRUE(json_has(i.out, k)) << k << " in " << i.out;
  EXPECT_EQ(json_number(i.out, "pics"), pics);
  EXPECT_EQ(json_number(i.out, "file_bytes"), double(fs::file_size(path("x.pic"))));

  // Human-readable forms succeed too.
  const CliRun t = pic("info x.pic");
  EXPECT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.out.find("PICs"), std::string::npos) << t.out;
}

TEST_F(Cli, HelpExitsZeroForEverySubcommand) {
  for (const char* sub : {"", "sample", "mesh", "info", "csg", "prim", "render", "view"}) {
    SCOPED_TRACE(sub);
    const CliRun r = pic(std::string(sub) + " --help");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(r.out.empty());
  }
}

TEST_F(Cli, UsageErrorsExitNonZero) {
  EXPECT_NE(pic("").code, 0);
  EXPECT_NE(pic("frobnicate").code, 0);
  EXPECT_NE(pic("sample").code, 0);                 // missing input and output
  EXPECT_NE(pic("sample " + fandisk()).code, 0);    // missing -o
  EXPECT_FALSE(fs::exists(path("x.pic")));
}

TEST_F(Cli, SampleFailuresLeaveTheOutputUntouched) {
  write_text_file(path("out.pic"), "precious bytes\n");
  // Missing input.
  expect_clean_failure("sample missing.obj -o out.pic", "out.pic", "missing.obj");
  // Open mesh: a box OBJ with one face removed.
  write_text_file(path("open.obj"),
                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                  "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\n");
  expect_clean_failure("sample open.obj -o out.pic --inside parity", "out.pic", "boundary edges");
  // A single open sheet encloses no solid, whichever classifier.
  write_text_file(path("sheet.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  expect_clean_failure("sample sheet.obj -o out.pic", "out.pic", "no solid");
  // A point cloud without normals.
  write_text_file(path("cloud.xyz"), "0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
  expect_clean_failure("sample cloud.xyz -o out.pic", "out.pic", "need normals");
  expect_clean_failure("sample open.obj -o out.pic --inside sideways", "out.pic", "--inside");
  // NaN coordinate.
  write_text_file(path("nan.obj"), "v 0 0 0\nv 1 0 0\nv 0 nan 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  expect_clean_failure("sample nan.obj -o out.pic", "out.pic", "non-finite");
  // Bad options.
  expect_clean_failure("sample " + fandisk() + " -o out.pic --depth 0", "out.pic", "depth");
  expect_clean_failure("sample " + fandisk() + " -o out.pic --depth 21", "out.pic", "depth");
  expect_clean_failure("sample " + fandisk() + " -o out.pic --error -1", "out.pic");
  expect_clean_failure("sample " + fandisk() + " -o out.pic --cube 0,0,0,nan", "out.pic");
  // Output directory missing: nothing is created.
  const CliRun r = pic("sample " + fandisk() + " -o nodir/x.pic --depth 6");
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(r.err_lines(), 1u) << r.err;
  EXPECT_FALSE(fs::exists(path("nodir")));
}

TEST_F(Cli, CorruptedPicFailsCleanly) {
  ASSERT_EQ(pic("prim sphere --radius 0.5 --segments 32 --depth 7 -o good.pic").code, 0);
  std::string bytes = read_text(path("good.pic"));
  ASSERT_GT(bytes.size(), 200u);
  bytes[bytes.size() / 2] ^= 0x5a;
  write_text_file(path("bad.pic"), bytes);
  write_text_file(path("out.obj"), "# precious mesh\n");
  expect_clean_failure("mesh bad.pic -o out.obj", "out.obj", "bad.pic");
  expect_clean_failure("mesh missing.pic -o out.obj", "out.obj", "missing.pic");
  expect_clean_failure("info bad.pic", "out.obj", "bad.pic");
  // A truncated file and an OBJ posing as .pic.
  write_text_file(path("short.pic"), bytes.substr(0, 70));
  expect_clean_failure("info short.pic", "out.obj", "short.pic");
  fs::copy_file(std::string(PIC_DATA_DIR) + "/fandisk.obj", path("fake.pic"));
  expect_clean_failure("mesh fake.pic -o out.obj", "out.obj", "not a .pic file");
  // csg with a corrupted operand keeps an existing output.
  write_text_file(path("acc.pic"), "precious\n");
  expect_clean_failure("csg good.pic union bad.pic -o acc.pic", "acc.pic", "bad.pic");
}

TEST_F(Cli, PrimBoxWorks) {
  const CliRun r = pic("prim box --size 1,1,1 -o b.pic");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  const Octree t = load(path("b.pic"));
  const TriMesh m = unsplit_contour(t);
  EXPECT_TRUE(test::IsClosedManifold(m));
  EXPECT_NEAR(volume(m), 1.0, 1e-6);
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner{(c & 1) ? 0.5 : -0.5, (c & 2) ? 0.5 : -0.5, (c & 4) ? 0.5 : -0.5};
    EXPECT_LE(test::nearest_vertex_distance(m, corner), 1e-6 * t.cube.size);
  }
  // Bad primitive arguments fail cleanly.
  write_text_file(path("keep.pic"), "keep\n");
  expect_clean_failure("prim box --size 1,0,1 -o keep.pic", "keep.pic");
  expect_clean_failure("prim box --size 1,x,1 -o keep.pic", "keep.pic");
  expect_clean_failure("prim blob -o keep.pic", "keep.pic", "blob");
}

TEST_F(Cli, PrimThenCsgThenMesh) {
  ASSERT_EQ(pic("prim box --size 1,1,1 --depth 7 --cube -1,-1,-1,2 -o a.pic").code, 0);
  ASSERT_EQ(pic("prim sphere --radius 0.6 --segments 32 --depth 7 --cube -1,-1,-1,2 -o b.pic").code, 0);
  const CliRun r = pic("csg a.pic subtract b.pic -o c.pic --mesh c.obj --json");
  ASSERT_EQ(r.code, 0) << r.err;
  expect_json_object(r.out);
  // The JSON contract other tools read: pics, seconds, and per operation its time and cells.
  for (const char* key : {"pics", "seconds", "ops", "op", "cells_visited", "cells_stamped"})
    EXPECT_TRUE(json_has(r.out, key)) << key << " missing in " << r.out;
  // Chained operations, left to right, and the result reloads.
  ASSERT_EQ(pic("prim cylinder --radius 0.2 --height 1.8 --axis x --depth 7 --cube -1,-1,-1,2 -o d.pic").code, 0);
  const CliRun chain = pic("csg a.pic subtract b.pic union d.pic -o e.pic --json");
  ASSERT_EQ(chain.code, 0) << chain.err;
  EXPECT_NE(chain.out.find("\"subtract\""), std::string::npos) << chain.out;
  EXPECT_NE(chain.out.find("\"union\""), std::string::npos) << chain.out;
  EXPECT_EQ(pic("info e.pic --json").code, 0);
  const TriMesh c = read_mesh(path("c.obj"));
  EXPECT_TRUE(test::IsClosedManifold(c));
  const double sphere_in_box = 4.0 / 3 * 3.14159265358979 * 0.216;  // the sphere pokes out a bit
  EXPECT_LT(volume(c), 1.0);
  EXPECT_GT(volume(c), 1.0 - sphere_in_box);
}

}  // namespace
}  // namespace pic
