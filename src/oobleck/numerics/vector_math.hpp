#pragma once
// exp and log over fixed-size blocks of values, several lanes at a time, through glibc's vector
// math library (libmvec) where the build has it (vector_math.cpp). The hot loops of a step take
// one exp or log per point or node (G2P's volume update, the fluid's E26–E27, E8's powers in the
// granular law, E29's drag); called one at a time, each is a libm call of ~11 ns on the
// benchmark host, in blocks ~4 ns per value.
//
// Every value of a block goes through the same function, so a point's result does not depend on
// its position in a block or on the thread count. The results are those of libmvec, whose stated
// accuracy is 4 ulp: not necessarily the bits of libm's scalar exp and log (tests/numerics checks
// the blocks within 4 ulp of them).
namespace oobleck::numerics {

/// Values per block: a multiple of every vector width (2 for SSE2, 4 for AVX2, 8 for AVX-512), so
/// that no value of a block falls into a scalar remainder loop (GCC 12, -O1 to -O3).
inline constexpr int kMathBlock = 32;

/// y[i] = exp(x[i]) for i < kMathBlock (x and y must not overlap).
void exp_block(const double* x, double* y);

/// y[i] = log(x[i]) for i < kMathBlock (x and y must not overlap).
void log_block(const double* x, double* y);

}  // namespace oobleck::numerics
