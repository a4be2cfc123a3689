// The axisymmetric G2P (docs/mpm.md: "The step" phase 6, "Geometry modes"), instantiated here alone so that CMake can
// compile this unit with 128-bit auto-vectorisation (-mprefer-vector-width=128; AVX2 and FMA are
// kept where the build or its glibc-hwcaps variant has them).
//
// Why (measured, docs/mpm.md "Performance"): with the compiler's 256-bit loops this kernel took
// the same time on one and on two threads of an Intel benchmark host (the intruder set-up's G2P,
// 0.49 → 0.50 s per 1000 steps), while its 128-bit form scaled 1.7–1.9× (0.55 → 0.29–0.33 s).
// The plane-strain and 3D kernels scale at 256 bits and are faster there, so only this one is
// narrowed. The solver's update_points asserts that every K it uses is listed here.
#include "oobleck/mpm/transfer.hpp"

namespace oobleck::mpm {
OOBLECK_AXISYMMETRIC_G2P(, 4)
OOBLECK_AXISYMMETRIC_G2P(, 9)
OOBLECK_AXISYMMETRIC_G2P(, 16)
}  // namespace oobleck::mpm
