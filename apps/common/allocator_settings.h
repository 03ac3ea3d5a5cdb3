// Process start-up shared by the command-line tool and the benchmarks, so both measure the
// same allocator.
#pragma once

#include <unistd.h>

#include <cstdlib>

namespace pic::app {

// PIC's phases allocate and free big buffers one after another, and a virtual machine pays
// dearly for every first touch of a fresh page. glibc's allocator, told to keep what is freed
// (no trimming, big blocks from the heap rather than their own mappings), hands the next phase
// pages already touched. The heap grows 64 MiB of address space at a time (pages are touched
// only when used). Transparent huge pages are not asked for: on a VM whose balloon takes free
// 2 MiB blocks back from the guest, each huge page is a cold 2 MiB the host must supply and the
// guest zero -- an offset of a 50 K-triangle mesh spent 0.5 s of system time on them, a third
// of its wall time, when run after a pause (docs/benchmarks.md). glibc reads these settings
// only at start-up, so the program starts itself once more with them (not when the caller set
// any, or PIC_NO_TUNABLES is set).
inline void restart_with_allocator_settings(char** argv) {
  if (std::getenv("GLIBC_TUNABLES") || std::getenv("PIC_NO_TUNABLES")) return;
  setenv("GLIBC_TUNABLES",
         "glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=1073741824:glibc.malloc.top_pad=67108864",
         1);
  execv("/proc/self/exe", argv);
  unsetenv("GLIBC_TUNABLES");  // could not restart: go on as we are
}

}  // namespace pic::app
