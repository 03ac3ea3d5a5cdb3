// The OpenVDB pipeline as a peer of PIC's CSG, on the same OBJ inputs:
//   mesh -> narrow-band level set (meshToLevelSet) -> csgUnion/csgDifference/csgIntersection
//   -> volumeToMesh, evaluated left to right.
//
//   pic_vdb_peer --voxel H [--half-width W] [--adaptivity A] [--out OUT.obj]
//                [--reference REF.obj] A.obj union B.obj difference C.obj ...
//
// H may be a fraction ("1/1024"). Prints one JSON object: per-stage seconds (reading the OBJ
// files is reported but not counted in total_seconds), active voxels, output triangles (quads
// count as two), peak RSS after the pipeline, and with --reference the two-sided Hausdorff
// distance of the result to REF (measured after the peak RSS is taken).
#include <openvdb/openvdb.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "bench_mesh.h"

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double parse_fraction(const std::string& s) {
  const auto slash = s.find('/');
  if (slash == std::string::npos) return std::stod(s);
  return std::stod(s.substr(0, slash)) / std::stod(s.substr(slash + 1));
}

int usage() {
  std::cerr << "usage: pic_vdb_peer --voxel H [--half-width W] [--adaptivity A] [--out OUT.obj] "
               "[--reference REF.obj] A.obj (union|difference|intersection) B.obj ...\n";
  return 1;
}
}  // namespace

int main(int argc, char** argv) {
  double voxel = 0, half_width = 3, adaptivity = 0;
  std::string out, reference, voxel_text;
  std::vector<std::string> chain;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    try {
      if (a == "--voxel") voxel = parse_fraction(voxel_text = next());
      else if (a == "--half-width") half_width = std::stod(next());
      else if (a == "--adaptivity") adaptivity = std::stod(next());
      else if (a == "--out") out = next();
      else if (a == "--reference") reference = next();
      else chain.push_back(a);
    } catch (const std::exception& e) {
      std::cerr << "pic_vdb_peer: " << e.what() << "\n";
      return usage();
    }
  }
  if (!(voxel > 0) || chain.empty() || chain.size() % 2 == 0) return usage();
  for (size_t k = 1; k < chain.size(); k += 2)
    if (chain[k] != "union" && chain[k] != "difference" && chain[k] != "intersection") return usage();

  try {
    openvdb::initialize();
    const auto xform = openvdb::math::Transform::createLinearTransform(voxel);

    // Read every input first: file parsing is not part of the pipeline.
    const auto t_read = Clock::now();
    std::vector<bench::Mesh> inputs;
    size_t tris_in = 0;
    for (size_t k = 0; k < chain.size(); k += 2) {
      inputs.push_back(bench::read_obj(chain[k]));
      tris_in += inputs.back().t.size();
    }
    const double read_s = since(t_read);

    const auto t_all = Clock::now();
    double levelset_s = 0, csg_s = 0;
    std::string stages = "[";
    openvdb::FloatGrid::Ptr acc;
    for (size_t k = 0; k < inputs.size(); ++k) {
      const auto t0 = Clock::now();
      std::vector<openvdb::Vec3s> pts;
      std::vector<openvdb::Vec3I> tris;
      std::vector<openvdb::Vec4I> quads;
      pts.reserve(inputs[k].p.size());
      for (const auto& p : inputs[k].p) pts.emplace_back(float(p[0]), float(p[1]), float(p[2]));
      tris.reserve(inputs[k].t.size());
      for (const auto& t : inputs[k].t) tris.emplace_back(t[0], t[1], t[2]);
      auto grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, pts, tris, quads, float(half_width));
      const double ls = since(t0);
      levelset_s += ls;
      double op_s = 0;
      std::string op = "input";
      if (k == 0) {
        acc = grid;
      } else {
        op = chain[2 * k - 1];
        const auto t1 = Clock::now();
        if (op == "union") openvdb::tools::csgUnion(*acc, *grid);
        else if (op == "difference") openvdb::tools::csgDifference(*acc, *grid);
        else openvdb::tools::csgIntersection(*acc, *grid);
        op_s = since(t1);
        csg_s += op_s;
      }
      stages += std::string(k ? ", " : "") + "{\"input\": \"" + chain[2 * k] + "\", \"op\": \"" + op +
                "\", \"levelset_seconds\": " + bench::fmt(ls) + ", \"csg_seconds\": " + bench::fmt(op_s) + "}";
    }
    stages += "]";

    const auto t_mesh = Clock::now();
    std::vector<openvdb::Vec3s> opts;
    std::vector<openvdb::Vec3I> otris;
    std::vector<openvdb::Vec4I> oquads;
    openvdb::tools::volumeToMesh(*acc, opts, otris, oquads, 0.0, adaptivity);
    const double mesh_s = since(t_mesh);
    const double total_s = since(t_all);
    const size_t voxels = acc->activeVoxelCount();
    const size_t mem_grid = acc->memUsage();
    const size_t peak = bench::peak_rss_bytes();

    // volumeToMesh's polygons face inward for a level set (negative inside): flip them.
    bench::Mesh result;
    result.p.reserve(opts.size());
    for (const auto& p : opts) result.p.push_back({p.x(), p.y(), p.z()});
    result.t.reserve(otris.size() + 2 * oquads.size());
    for (const auto& t : otris) result.t.push_back({t[2], t[1], t[0]});
    for (const auto& q : oquads) {
      result.t.push_back({q[2], q[1], q[0]});
      result.t.push_back({q[3], q[2], q[0]});
    }
    acc.reset();

    std::string extra;
    if (!out.empty()) {
      const auto t0 = Clock::now();
      bench::write_obj(result, out);
      extra += ", \"write_seconds\": " + bench::fmt(since(t0)) + ", \"out\": \"" + out + "\"";
    }
    if (!reference.empty()) {
      const auto t0 = Clock::now();
      const bench::Mesh ref = bench::read_obj(reference);
      const auto h = bench::hausdorff(result, ref);
      extra += ", \"distance_to_reference\": " + bench::hausdorff_json(h) + ", \"hausdorff\": " +
               bench::fmt(h.two_sided()) + ", \"distance_seconds\": " + bench::fmt(since(t0));
    }
    std::cout << "{\"system\": \"openvdb\", \"openvdb_version\": \"" << openvdb::getLibraryAbiVersionString()
              << "\", \"voxel\": " << bench::fmt(voxel) << ", \"voxel_text\": \"" << voxel_text
              << "\", \"half_width\": " << bench::fmt(half_width) << ", \"adaptivity\": " << bench::fmt(adaptivity)
              << ", \"triangles_in\": " << tris_in << ", \"read_seconds\": " << bench::fmt(read_s)
              << ", \"levelset_seconds\": " << bench::fmt(levelset_s) << ", \"csg_seconds\": " << bench::fmt(csg_s)
              << ", \"mesh_seconds\": " << bench::fmt(mesh_s) << ", \"total_seconds\": " << bench::fmt(total_s)
              << ", \"active_voxels\": " << voxels << ", \"grid_bytes\": " << mem_grid
              << ", \"vertices\": " << result.p.size() << ", \"triangles\": " << result.t.size()
              << ", \"peak_rss_bytes\": " << peak << ", \"stages\": " << stages << extra << "}\n";
  } catch (const std::exception& e) {
    std::cerr << "pic_vdb_peer: error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
