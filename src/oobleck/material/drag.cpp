#include "oobleck/material/drag.hpp"

#include "oobleck/numerics/vector_math.hpp"

namespace oobleck::material {

void drag_coefficient_per_volume_block(const DragParams& p, const double* phi, const double* Re, double* C_V) {
  constexpr int N = numerics::kMathBlock;
  if (p.law != DragLaw::Beetstra || !p.use_reynolds) {
    for (int j = 0; j < N; ++j) C_V[j] = drag_coefficient_per_volume(p, phi[j], Re[j]);
    return;
  }
  double x[N], ln_Re[N], a1[N], a2[N], r1[N], r2[N];
  for (int j = 0; j < N; ++j) x[j] = Re[j] > 0.0 ? Re[j] : 1.0;  // (the powers are unused at Re <= 0)
  numerics::log_block(x, ln_Re);
  for (int j = 0; j < N; ++j) {
    a1[j] = beetstra_arg1(ln_Re[j]);
    a2[j] = beetstra_arg2(phi[j], ln_Re[j]);
  }
  numerics::exp_block(a1, r1);
  numerics::exp_block(a2, r2);
  for (int j = 0; j < N; ++j)  // as drag_coefficient_per_volume
    C_V[j] = drag_stokes_prefactor(p, phi[j]) * beetstra_F_with_powers(phi[j], Re[j], r1[j], r2[j]);
}

}  // namespace oobleck::material
