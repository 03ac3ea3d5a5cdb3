// `pic`: the command-line tool, thin over the library; one file per subcommand. Every failure
// becomes one line on stderr and a non-zero exit: 1 usage, 2 bad input or I/O, 3 internal error,
// 4 an output written but not a valid solid (the line says which counts are off).
#include <tbb/parallel_for.h>

#include <iostream>
#include <thread>

#include "../common/allocator_settings.h"
#include "cli.h"

int main(int argc, char** argv) {
  pic::app::restart_with_allocator_settings(argv);
  // The thread pool starts while the arguments are parsed and the input is read, instead of
  // inside the first parallel stage.
  std::jthread warm([] { tbb::parallel_for(0, 2, [](int) {}); });
  CLI::App app{"pic: solid modeling with points with implicit connectivity (PIC)"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Help for every subcommand");
  using namespace pic::cli;
  for (auto add : {add_sample, add_mesh, add_info, add_csg, add_eval, add_prim, add_render, add_view, add_compare, add_volume})
    add(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const InvalidOutput& e) {
    std::cerr << "pic: error: " << e.what() << "\n";
    return 4;
  } catch (const pic::InvalidInput& e) {
    std::cerr << "pic: error: " << e.what() << "\n";
    return 2;
  } catch (const pic::IoError& e) {
    std::cerr << "pic: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "pic: internal error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
