// libFuzzer entry of the scene target (tests/fuzz/targets.hpp).
#include "targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return oobleck::fuzz::scene(data, size);
}
