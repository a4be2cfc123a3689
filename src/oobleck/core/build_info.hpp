#pragma once
// What this copy of the library was compiled for. With the default `release` build the library
// exists in several variants (baseline x86-64 and glibc-hwcaps/x86-64-v3, see CMakeLists.txt and
// docs/mpm.md "Performance"); the dynamic loader picks the best one the CPU supports, and these
// functions, compiled into each variant, say which one runs.
#include <string>

namespace oobleck {

/// Instruction-set level of the running library: "x86-64" (baseline), "x86-64-v2", "x86-64-v3"
/// (AVX2 + FMA), "x86-64-v4" (AVX-512), or "other" on non-x86 targets; with ", -march=native"
/// appended for the `native` preset's build.
const char* library_instruction_set();

/// "oobleck 0.1.0 (library: x86-64-v3)".
std::string version_string();

}  // namespace oobleck
