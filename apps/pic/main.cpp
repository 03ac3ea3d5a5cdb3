// `pic`: the command-line tool, thin over the library; one file per subcommand. Every failure
// becomes one line on stderr and a non-zero exit: 1 usage, 2 bad input or I/O, 3 internal error,
// 4 an output written but not a valid solid (the line says which counts are off).
#include <unistd.h>

#include <cstdlib>
#include <iostream>

#include "cli.h"

namespace {
// PIC's phases allocate and free big buffers one after another, and a virtual machine pays
// dearly for every first touch of a fresh page. glibc's allocator, told to back its heap with
// transparent huge pages and to keep what is freed, takes half the time off `pic mesh` on spot
// and a third off sampling fandisk (docs/benchmarks.md). glibc reads these settings only at
// start-up, so the tool starts itself once more with them (not when the caller set any, or
// PIC_NO_TUNABLES is set).
void restart_with_allocator_settings(char** argv) {
  if (std::getenv("GLIBC_TUNABLES") || std::getenv("PIC_NO_TUNABLES")) return;
  setenv("GLIBC_TUNABLES",
         "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=1073741824", 1);
  execv("/proc/self/exe", argv);
  unsetenv("GLIBC_TUNABLES");  // could not restart: go on as we are
}
}  // namespace

int main(int argc, char** argv) {
  restart_with_allocator_settings(argv);
  CLI::App app{"pic: solid modeling with points with implicit connectivity (PIC)"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Help for every subcommand");
  using namespace pic::cli;
  for (auto add : {add_sample, add_mesh, add_info, add_csg, add_eval, add_prim, add_render, add_view, add_compare})
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
