// libFuzzer entry of the params target (tests/fuzz/targets.hpp).
#include "targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return oobleck::fuzz::params(data, size);
}
