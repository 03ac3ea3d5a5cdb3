// pic csg: Booleans left to right over .pic files and meshes (csg_chain).
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli.h"

namespace pic::cli {

namespace {
struct CsgArgs {
  std::vector<std::string> args;
  std::string out, mesh;
  bool json = false, no_split = false, no_check = false, raw = false;
  double error = 1e-8;
  double simplify = kCompactSimplify;  // finest cells
  int depth = 12;
};

void run(const CsgArgs& a) {
  if (a.args.size() < 3 || a.args.size() % 2 == 0) throw InvalidInput("csg needs A.pic OP B.pic [OP C.pic ...]");
  const auto t0 = Clock::now();
  std::vector<CsgOperand> operands;
  std::vector<CsgOp> ops;
  for (size_t k = 0; k < a.args.size(); ++k) {
    if (k % 2 == 1) {
      const auto op = parse_csg_op(a.args[k]);
      if (!op) throw InvalidInput("unknown operation '" + a.args[k] + "' (union, intersect, subtract)");
      ops.push_back(*op);
      continue;
    }
    CsgOperand x;
    x.name = a.args[k];
    if (is_pic_path(x.name)) x.tree = load(x.name);
    else x.mesh = read_mesh(x.name);
    operands.push_back(std::move(x));
  }
  CsgChainOptions opt;
  opt.sampling.depth = a.depth;
  opt.sampling.error = a.error;
  opt.csg.error = a.error;
  opt.progress = progress;
  std::string steps = "[";
  opt.on_step = [&](size_t k, const CsgStats& st) {
    const std::string& name = a.args[2 * k];
    const CsgOp op = ops[k - 1];
    steps += (k > 1 ? ", " : "") + Json().add("op", to_string(op)).add("operand", name).fields(st).str();
    if (!a.json)
      std::printf("%-9s %-24s %8.2f ms  %zu cells visited, %zu stamped\n", to_string(op).c_str(), name.c_str(),
                  st.seconds * 1e3, st.cells_visited, st.cells_stamped);
  };
  const Octree result = csg_chain(std::move(operands), ops, opt);
  steps += "]";
  Json j;
  const size_t pics = analyze(result).pics;
  j.add("pics", pics).add("seconds", since(t0)).raw("ops", steps);
  ContourOptions co;
  co.split_sheets = !a.no_split;
  co.simplify = a.raw ? 0 : a.simplify;
  std::vector<WrittenMesh> written;
  auto write = [&](const std::string& path, bool with_volume) {
    ContourFile f = write_contour(result, path, co);
    j.add("triangles", f.mesh.triangles.size())
        .add("split_vertices", f.stats.split_vertices)
        .add("simplified_away", f.stats.simplified_away);
    if (with_volume) j.add("volume", volume(f.mesh));
    j.raw("topology", topology_json(f.written.topology));
    written.push_back(f.written);
    return f;
  };
  if (is_mesh_path(a.out)) write(a.out, true);
  else save(result, a.out);
  if (!a.mesh.empty()) {
    const ContourFile f = write(a.mesh, false);
    if (a.json) {
      const MeshValidity v = check_validity(f.mesh, !a.no_check);
      if (v.checked) written.back().self_intersections = v.self_intersections;
      add_validity(j, v);
    }
  }
  if (a.json) std::cout << j.str() << "\n";
  else std::printf("%zu PICs -> %s\n", pics, a.out.c_str());
  for (const WrittenMesh& w : written) require_valid(w);
}
}  // namespace

void add_csg(CLI::App& app) {
  auto a = std::make_shared<CsgArgs>();
  auto* c = app.add_subcommand("csg", "Booleans on PIC objects, left to right: A union|intersect|subtract B ...");
  c->add_option("args", a->args, "A OP B [OP C ...]; operands are .pic files or meshes")->required();
  c->add_option("-o,--output", a->out, "Output .pic file, or a mesh (.obj, .stl, .ply, .off, .glb)")->required();
  c->add_option("--depth", a->depth, "Sampling depth for mesh operands (one shared cube around them)")
      ->capture_default_str();
  c->add_option("--mesh", a->mesh, "Also contour the result to this mesh file");
  c->add_flag("--no-split", a->no_split,
              "With --mesh: write the dual contouring mesh as is (it may touch itself at a few edges or vertices)");
  c->add_option("--error", a->error, "QEF residual threshold for new vertices")->capture_default_str();
  c->add_option("--simplify", a->simplify,
                "Mesh output: merge flat regions and straight creases, staying within about TOL finest cells of the raw contour")
      ->capture_default_str();
  c->add_flag("--raw", a->raw, "Mesh output: the contour as it is, a vertex per gray cell (no --simplify)");
  c->add_flag("--json", a->json, "Print one JSON object on stdout");
  c->add_flag("--no-check", a->no_check, "With --mesh --json: skip the exact self-intersection test (huge meshes)");
  c->callback([a] { run(*a); });
}

}  // namespace pic::cli
