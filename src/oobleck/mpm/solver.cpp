// Explicit instantiations: compile (and warning-check) the solver for every implemented geometry.
#include "oobleck/mpm/solver.hpp"

#include "oobleck/mpm/laws.hpp"

namespace oobleck::mpm {
template class Solver<PlaneStrain>;
template class Solver<ThreeD>;
template class LinearElasticLaw<PlaneStrain>;
template class LinearElasticLaw<ThreeD>;
}  // namespace oobleck::mpm
