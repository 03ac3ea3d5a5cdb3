// pic info: cells per level, PIC count, bytes, bounding box, and the contour's validity.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli.h"

namespace pic::cli {

namespace {
struct InfoArgs {
  std::string in;
  bool json = false, no_check = false;
};

void run(const InfoArgs& a) {
  const Octree tree = load(a.in);
  const size_t bytes = std::filesystem::file_size(a.in);
  const TriMesh surface = unsplit_contour(tree);
  const auto topo = analyze_topology(surface);
  if (a.json) {
    std::string j = info_json(tree, bytes);
    j.insert(j.size() - 1, ", \"contour\": " + topology_json(topo));
    // The contour's validity, also at the top level.
    Json v;
    const std::string vs = add_validity(v, check_validity(surface, !a.no_check)).str();
    j.insert(j.size() - 1, ", " + vs.substr(1, vs.size() - 2));
    std::cout << j << "\n";
  } else {
    print_info_table(tree, bytes);
    std::printf("contour: %s (%zu boundary edges, %zu non-manifold edges, %zu non-manifold vertices)\n",
                topology_words(topo).c_str(), topo.boundary_edges, topo.nonmanifold_edges, topo.nonmanifold_vertices);
  }
}
}  // namespace

void add_info(CLI::App& app) {
  auto a = std::make_shared<InfoArgs>();
  auto* c = app.add_subcommand("info", "Cells per level, PIC count, bytes, bounding box");
  c->add_option("input", a->in, "Input .pic file")->required();
  c->add_flag("--json", a->json, "Print one JSON object on stdout");
  c->add_flag("--no-check", a->no_check, "Skip the exact self-intersection test of the contour (huge meshes)");
  c->callback([a] { run(*a); });
}

}  // namespace pic::cli
