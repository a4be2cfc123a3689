// Explicit instantiations: compile (and warning-check) the solver for every implemented geometry.
#include "oobleck/mpm/solver.hpp"

#include "oobleck/mpm/initial_state.hpp"
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
template void set_hydrostatic_bed<PlaneStrain>(const HydrostaticBed&, Body<PlaneStrain>*, Body<PlaneStrain>*);
template void set_hydrostatic_bed<Axisymmetric>(const HydrostaticBed&, Body<Axisymmetric>*, Body<Axisymmetric>*);
template void set_hydrostatic_bed<ThreeD>(const HydrostaticBed&, Body<ThreeD>*, Body<ThreeD>*);
}  // namespace oobleck::mpm
