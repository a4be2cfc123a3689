#include "oobleck/numerics/vector_math.hpp"

#include <cmath>

// glibc declares the vector variants of exp and log (libmvec, part of libc6 on x86-64, linked
// through libm) only under -ffast-math (bits/math-vector.h), which oobleck does not use: it would
// license reassociation everywhere. The same declarations here, without fast-math, let GCC call
// _ZGVbN2v_exp (SSE2: the portable library) or _ZGVdN4v_exp (AVX2: the x86-64-v3 variant) in the
// `omp simd` loops below. Other compilers, C libraries or processors get plain loops.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__GLIBC__) && \
    !defined(__FAST_MATH__)
#define OOBLECK_LIBMVEC 1
extern "C" {
__attribute__((__simd__("notinbranch"))) double exp(double) noexcept;
__attribute__((__simd__("notinbranch"))) double log(double) noexcept;
}
#else
#define OOBLECK_LIBMVEC 0
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

bool vector_math_uses_libmvec() { return OOBLECK_LIBMVEC != 0; }

}  // namespace oobleck::numerics
