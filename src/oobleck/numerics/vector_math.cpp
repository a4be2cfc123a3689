#include "oobleck/numerics/vector_math.hpp"

#include <cmath>

// glibc declares the vector variants of exp and log (libmvec, in libc6 on x86-64 since glibc
// 2.22, linked through libm's linker script) only under -ffast-math (bits/math-vector.h), which
// oobleck does not use: it would license reassociation everywhere. The same declarations here,
// without fast-math, let GCC call _ZGVbN2v_exp (SSE2: the portable library), _ZGVdN4v_exp (AVX2:
// the x86-64-v3 variant) or _ZGVeN8v_exp (AVX-512: an x86-64-v4 variant) in the `omp simd` loops
// below when it optimises. Other compilers, C libraries or processors get plain loops. (Under
// -ffast-math glibc's own declarations do the same; repeating them is harmless.)
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__GLIBC__)
#if __GLIBC_PREREQ(2, 22)
extern "C" {
__attribute__((__simd__("notinbranch"))) double exp(double) noexcept;
__attribute__((__simd__("notinbranch"))) double log(double) noexcept;
}
#endif
#endif

namespace oobleck::numerics {

void exp_block(const double* __restrict x, double* __restrict y) {
#pragma omp simd
  for (int i = 0; i < kMathBlock; ++i) y[i] = std::exp(x[i]);
}

void log_block(const double* __restrict x, double* __restrict y) {
#pragma omp simd
  for (int i = 0; i < kMathBlock; ++i) y[i] = std::log(x[i]);
}

}  // namespace oobleck::numerics
