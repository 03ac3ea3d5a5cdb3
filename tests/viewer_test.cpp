// Tests of the HTML viewer page. The browser test runs tests/viewer_check.mjs (Node +
// playwright-core + headless Chromium) when those are available, and is skipped otherwise.
#include "pic/viewer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "support/shapes.h"

#ifndef PIC_VIEWER_CHECK_SCRIPT  // tests/viewer_check.mjs
#define PIC_VIEWER_CHECK_SCRIPT ""
#endif
#ifndef PIC_NODE_MODULES_DIR  // directory holding node_modules/playwright-core
#define PIC_NODE_MODULES_DIR ""
#endif
#ifndef PIC_NODE_EXECUTABLE
#define PIC_NODE_EXECUTABLE "node"
#endif

namespace pic {
namespace {

namespace fs = std::filesystem;

/// The string value of `"key":"..."` in the page's data block (no escapes expected).
std::string json_field(const std::string& html, const std::string& key) {
  std::string open = "\"" + key + "\":\"";
  size_t a = html.find(open);
  if (a == std::string::npos) return {};
  a += open.size();
  return html.substr(a, html.find('"', a) - a);
}

std::vector<uint8_t> base64_decode(const std::string& s) {
  std::vector<uint8_t> out;
  uint32_t acc = 0;
  int bits = 0;
  for (char c : s) {
    const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const char* p = c ? std::strchr(digits, c) : nullptr;
    if (!p) break;  // '=' padding
    acc = acc << 6 | uint32_t(p - digits);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(uint8_t(acc >> bits));
    }
  }
  return out;
}

/// The root's lower four children gray, over the cube [0,2]^3.
Octree make_tree() {
  Octree t;
  t.cube = {{0, 0, 0}, 2.0};
  t.nodes.assign(9, Node{});
  t.nodes[0].kind = CellKind::Internal;
  t.nodes[0].index = 1;
  for (int c = 0; c < 4; ++c) {
    t.nodes[1 + c].kind = CellKind::Gray;
    t.nodes[1 + c].index = uint32_t(t.vertices.size());
    t.vertices.push_back({0.5f, 0.5f, 0.5f});
  }
  return t;
}

TEST(ViewHtml, SelfContainedPageWithData) {
  TriMesh box = make_box({0, 0, 0}, {2, 2, 1});
  Octree tree = make_tree();
  std::string html = view_html(box, &tree, R"({"name": "</script><b>x</b>", "pics": 4})");
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("<script id=\"pic-data\" type=\"application/json\">"), std::string::npos);
  // No external resources: everything is inline.
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  // The info text cannot close the data element early.
  EXPECT_EQ(html.find("</script><b>"), std::string::npos);
  EXPECT_GT(html.size(), 100000u) << "three.js bundle missing?";

  // Geometry round trip: 8 box vertices relative to the centre (1, 1, 0.5), 12 triangles.
  std::vector<uint8_t> pos = base64_decode(json_field(html, "positions"));
  ASSERT_EQ(pos.size(), 8u * 3 * sizeof(float));
  std::vector<float> xyz(24);
  std::memcpy(xyz.data(), pos.data(), pos.size());
  for (size_t v = 0; v < 8; ++v)
    for (int i = 0; i < 3; ++i)
      EXPECT_FLOAT_EQ(xyz[v * 3 + i], float(box.positions[v][i] - (i < 2 ? 1.0 : 0.5)));
  std::vector<uint8_t> idx = base64_decode(json_field(html, "indices"));
  ASSERT_EQ(idx.size(), 12u * 3 * sizeof(uint32_t));
  uint32_t first[3];
  std::memcpy(first, idx.data(), sizeof first);
  EXPECT_EQ(first[0], box.triangles[0][0]);
  EXPECT_EQ(first[2], box.triangles[0][2]);
  EXPECT_EQ(base64_decode(json_field(html, "cells")).size(), 4u * 4 * sizeof(float));
  EXPECT_EQ(base64_decode(json_field(html, "points")).size(), 4u * 3 * sizeof(float));

  // Without a tree the vertex toggle shows the mesh vertices.
  std::string plain = view_html(box, nullptr, "");
  EXPECT_EQ(json_field(plain, "cells"), "");
  EXPECT_EQ(base64_decode(json_field(plain, "points")).size(), 8u * 3 * sizeof(float));

  TriMesh bad = box;
  bad.triangles.push_back({0, 1, 8});
  EXPECT_THROW(view_html(bad, nullptr, "{}"), InvalidInput);
}

TEST(ViewHtml, OpensInHeadlessChromium) {
  const fs::path chromium = "/usr/bin/chromium";
  if (!fs::exists(chromium)) GTEST_SKIP() << "no /usr/bin/chromium (apt-get install chromium)";
  const fs::path script = PIC_VIEWER_CHECK_SCRIPT;
  const fs::path modules = PIC_NODE_MODULES_DIR;
  if (std::string(PIC_NODE_EXECUTABLE).empty()) GTEST_SKIP() << "node was not found by the build";
  if (script.empty() || !fs::exists(script))
    GTEST_SKIP() << "PIC_VIEWER_CHECK_SCRIPT not set by the build";
  if (modules.empty() || !fs::exists(modules / "node_modules" / "playwright-core"))
    GTEST_SKIP() << "playwright-core is not installed in " << modules
                 << " (npm ci in tests/ or build the pic_test_npm target)";

  std::string templ = (fs::temp_directory_path() / "pic-viewer-XXXXXX").string();
  ASSERT_NE(mkdtemp(templ.data()), nullptr);
  const fs::path dir = templ;
  const fs::path page = dir / "box.html", shot = dir / "box.png", log = dir / "check.log";
  {
    Octree tree = make_tree();
    std::ofstream(page) << view_html(make_box({0, 0, 0}, {2, 2, 1}), &tree,
                                     R"({"triangles": 12, "note": "viewer test"})");
  }
  std::string cmd = "PIC_NODE_MODULES_DIR='" + modules.string() + "' '" PIC_NODE_EXECUTABLE "' '" +
                    script.string() + "' '" + page.string() + "' '" + shot.string() + "' > '" +
                    log.string() + "' 2>&1";
  int rc = std::system(cmd.c_str());
  std::stringstream out;
  out << std::ifstream(log).rdbuf();
  EXPECT_EQ(rc, 0) << out.str();
  EXPECT_TRUE(fs::exists(shot));
  std::printf("%s", out.str().c_str());
  if (rc == 0) fs::remove_all(dir);
}

}  // namespace
}  // namespace pic
