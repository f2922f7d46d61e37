#pragma once
/// \file The ghost-fluid pressure projection (pressure.h) of a grid split over ranks (issue 40):
/// each rank assembles the system on its block (grid_block.h), whose rows for its own cells are
/// exactly the whole system's; hypre solves the whole system with every rank holding its rows
/// (hypre_struct_solver.h); the pressure's ghost layers are exchanged, each rank applies the
/// gradient on its block and the velocities' ghost layers are exchanged. The result equals
/// project() on the whole grid to the solver's tolerance.

#include "fluid/grid_block.h"
#include "fluid/pressure.h"

namespace meniscus::fluid {

/// Collective over `ranks`: project() of the whole grid, on `rank`'s block. `block` and
/// `interface` are the rank's block (ghost layers filled), `boundaries` the whole box's,
/// `pressure` receives the block's pressure (ghost layers filled). With more than one rank the
/// system is solved by hypre (options.solver is used on one rank only). The returned result is
/// the same on every rank: converged on all, the largest residual and divergence, singular as a
/// whole. Throws std::invalid_argument when the block does not fit the decomposition.
ProjectionResult project_block(MacGrid& block, const InterfaceInput& interface,
                               const PhaseOptions& phases, FluidMode mode, double dt,
                               const PressureOptions& options, Array3<double>& pressure,
                               const BoundaryOptions& boundaries,
                               const SlabDecomposition& decomposition,
                               const RankCommunicator& ranks);

}  // namespace meniscus::fluid
