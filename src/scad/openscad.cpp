// `pic eval model.scad`: OpenSCAD exports the model's CSG tree, which evaluate.cpp evaluates.
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "pic/scad.h"
#include "geometry/stopwatch.h"
#include "io/file_util.h"
#include "scad/lower.h"


namespace pic {

namespace {
using detail::Clock;
using detail::since;

bool on_path(const std::string& prog) {
  const char* p = std::getenv("PATH");
  std::stringstream ss(p ? p : "");
  std::string dir;
  while (std::getline(ss, dir, ':'))
    if (!dir.empty() && ::access((std::filesystem::path(dir) / prog).c_str(), X_OK) == 0) return true;
  return false;
}
std::string shell_quote(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return o + "'";
}
}  // namespace

namespace {
// The model's CSG tree as text: a .csg file as it is, a .scad file through `openscad -o
// x.csg` (a temporary file). Sets the directory imports are relative to, and OpenSCAD's time.
std::string csg_text(const std::filesystem::path& path, EvalOptions& o, double& openscad_seconds) {
  const std::string ext = detail::lower_extension(path);
  if (ext != ".scad" && ext != ".csg") throw InvalidInput(path.string() + ": expected a .scad or .csg file");
  if (o.base_dir.empty()) o.base_dir = std::filesystem::absolute(path).parent_path();
  openscad_seconds = 0;
  if (ext == ".csg") {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw IoError("cannot read " + path.string());
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  if (!std::filesystem::exists(path)) throw IoError("cannot read " + path.string());
  if (!on_path("openscad"))
    throw InvalidInput("the 'openscad' program is needed for .scad input: install it (Debian: apt-get install "
                       "openscad, or scripts/setup.sh) or pass a .csg file exported by OpenSCAD");
  const auto t0 = Clock::now();
  // OpenSCAD resolves a relative output path against the input's directory: give it an
  // absolute temporary path.
  char tmpl[] = "/tmp/pic-scad-XXXXXX";
  const char* dir = ::mkdtemp(tmpl);
  if (!dir) throw IoError("cannot create a temporary directory");
  const std::filesystem::path tmp_dir = dir, csg = tmp_dir / "model.csg", log = tmp_dir / "openscad.log";
  // OpenSCAD exports the preview tree by default ($preview true); `openscad -o x.stl` renders
  // with $preview false, and that is the solid a user means.
  const std::string cmd = "openscad -D '$preview=false' -o " + shell_quote(csg.string()) + " " +
                          shell_quote(std::filesystem::absolute(path).string()) + " >" +
                          shell_quote(log.string()) + " 2>&1";
  const int rc = std::system(cmd.c_str());
  openscad_seconds = since(t0);
  if (rc != 0 || !std::filesystem::exists(csg)) {
    std::string msg;
    std::ifstream l(log);
    for (std::string line; std::getline(l, line);)
      if (line.find("ERROR") != std::string::npos) {
        msg = line;
        break;
      }
    std::filesystem::remove_all(tmp_dir);
    throw InvalidInput("openscad could not export " + path.string() + (msg.empty() ? "" : ": " + msg));
  }
  std::ifstream in(csg, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  std::filesystem::remove_all(tmp_dir);
  return ss.str();
}
}  // namespace

Octree eval_scad(const std::filesystem::path& path, const EvalOptions& options, EvalStats* stats) {
  EvalOptions o = options;
  double openscad_seconds = 0;
  const std::string text = csg_text(path, o, openscad_seconds);
  Octree t = eval_csg(text, o, stats, path.string());
  if (stats) {
    stats->openscad_seconds = openscad_seconds;
    stats->seconds += openscad_seconds;
  }
  return t;
}

std::optional<Outline> eval_outline(const std::filesystem::path& path, const EvalOptions& options, EvalStats* stats) {
  EvalOptions o = options;
  double openscad_seconds = 0;
  const std::string text = csg_text(path, o, openscad_seconds);
  std::optional<Outline> out = eval_csg_outline(text, o, stats, path.string());
  if (out && stats) {
    stats->openscad_seconds = openscad_seconds;
    stats->seconds += openscad_seconds;
  }
  return out;
}

}  // namespace pic
