// libFuzzer harness for stl input (the body is shared with the replay tool: harness.h).
#include "harness.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return pic::fuzz::run_harness("stl", data, size);
}
