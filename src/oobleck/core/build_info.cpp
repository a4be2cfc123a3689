#include "oobleck/core/build_info.hpp"

#include <fmt/format.h>

namespace oobleck {

const char* library_instruction_set() {
  // The psABI levels, tested by the macros each -march level defines (GCC and Clang).
#if defined(OOBLECK_NATIVE_BUILD)
#define OOBLECK_ISA_SUFFIX ", -march=native"
#else
#define OOBLECK_ISA_SUFFIX ""
#endif
#if defined(__x86_64__)
#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512CD__) && defined(__AVX512DQ__) && \
    defined(__AVX512VL__)
  return "x86-64-v4" OOBLECK_ISA_SUFFIX;
#elif defined(__AVX2__) && defined(__FMA__) && defined(__BMI2__) && defined(__F16C__)
  return "x86-64-v3" OOBLECK_ISA_SUFFIX;
#elif defined(__SSE4_2__) && defined(__POPCNT__) && defined(__SSSE3__)
  return "x86-64-v2" OOBLECK_ISA_SUFFIX;
#else
  return "x86-64" OOBLECK_ISA_SUFFIX;
#endif
#else
  return "other" OOBLECK_ISA_SUFFIX;
#endif
}

std::string version_string() {
  return fmt::format("oobleck {} (library: {})", OOBLECK_VERSION, library_instruction_set());
}

}  // namespace oobleck
