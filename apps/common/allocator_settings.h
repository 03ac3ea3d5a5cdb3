// Process start-up shared by the command-line tool and the benchmarks, so both measure the
// same allocator.
#pragma once

#include <unistd.h>

#include <cstdlib>

namespace pic::app {

// PIC's phases allocate and free big buffers one after another, and a virtual machine pays
// dearly for every first touch of a fresh page. glibc's allocator, told to back its heap with
// transparent huge pages and to keep what is freed, takes half the time off `pic mesh` on spot
// and a third off sampling fandisk (docs/benchmarks.md). The heap also grows 64 MiB of
// address space at a time: grown in small steps, its new pages were not aligned for huge
// pages and each was faulted in alone (about a tenth off a fresh fandisk sampling and off the
// CAD tool's Booleans). glibc reads these settings only at start-up, so the program starts
// itself once more with them (not when the caller set any, or PIC_NO_TUNABLES is set).
inline void restart_with_allocator_settings(char** argv) {
  if (std::getenv("GLIBC_TUNABLES") || std::getenv("PIC_NO_TUNABLES")) return;
  setenv("GLIBC_TUNABLES",
         "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=1073741824:"
         "glibc.malloc.top_pad=67108864",
         1);
  execv("/proc/self/exe", argv);
  unsetenv("GLIBC_TUNABLES");  // could not restart: go on as we are
}

}  // namespace pic::app
