// libFuzzer's entry point for one target of fuzz_targets.h; fuzz/CMakeLists.txt compiles this
// file once per target with DRIFTLAB_FUZZ_FUNCTION set to the target's function.
#include <cstddef>
#include <cstdint>

#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  driftlab::fuzz::DRIFTLAB_FUZZ_FUNCTION(data, size);
  return 0;
}
