#include "oobleck/core/build_info.hpp"

#include <fmt/format.h>

namespace oobleck {

namespace {
#if defined(OOBLECK_NATIVE_BUILD)
constexpr const char* kLevelSuffix = ", -march=native";
#else
constexpr const char* kLevelSuffix = "";
#endif

/// The psABI level, tested by the macros each -march level defines (GCC and Clang).
constexpr const char* level() {
#if defined(__x86_64__)
#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512CD__) && defined(__AVX512DQ__) && \
    defined(__AVX512VL__)
  return "x86-64-v4";
#elif defined(__AVX2__) && defined(__FMA__) && defined(__BMI2__) && defined(__F16C__)
  return "x86-64-v3";
#elif defined(__SSE4_2__) && defined(__POPCNT__) && defined(__SSSE3__)
  return "x86-64-v2";
#else
  return "x86-64";
#endif
#else
  return "other";
#endif
}
}  // namespace

const char* library_instruction_set() {
  static const std::string name = std::string(level()) + kLevelSuffix;
  return name.c_str();
}

std::string version_string() {
  return fmt::format("oobleck {} (library: {})", OOBLECK_VERSION, library_instruction_set());
}

}  // namespace oobleck
