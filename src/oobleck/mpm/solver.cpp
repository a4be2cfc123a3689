// Explicit instantiations: compile (and warning-check) the solver for every implemented geometry.
#include "oobleck/mpm/solver.hpp"

#include "oobleck/mpm/laws.hpp"

namespace oobleck::mpm {
template class Solver<PlaneStrain>;
template class Solver<ThreeD>;
template class Solver<Axisymmetric>;
template class LinearElasticLaw<PlaneStrain>;
template class LinearElasticLaw<ThreeD>;
template class LinearElasticLaw<Axisymmetric>;
template class FluidLaw<PlaneStrain>;
template class FluidLaw<Axisymmetric>;
template class FluidLaw<ThreeD>;
}  // namespace oobleck::mpm
