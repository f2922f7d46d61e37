#include "fluid/distributed_projection.h"

#include <stdexcept>
#include <string>

namespace meniscus::fluid {

ProjectionResult project_block(MacGrid& block, const InterfaceInput& interface,
                               const PhaseOptions& phases, FluidMode mode, double dt,
                               const PressureOptions& options, Array3<double>& pressure,
                               const BoundaryOptions& boundaries,
                               const SlabDecomposition& decomposition,
                               const RankCommunicator& ranks) {
    if (!decomposition.distributed())
        return project(block, interface, phases, mode, dt, options, pressure, boundaries);
    const int rank = ranks.rank();
    if (block.nz() != decomposition.local_layers(rank))
        throw std::invalid_argument("project_block: the block has " + std::to_string(block.nz()) +
                                    " z-layers, rank " + std::to_string(rank) + "'s " +
                                    std::to_string(decomposition.local_layers(rank)));
    const BoundaryOptions local = block_boundaries(boundaries, decomposition, rank);
    PhaseClock clock;
    PressureSystem system =
        build_pressure_system(block, interface, phases, mode, dt, options, local);
    // Pure Neumann as a whole only if no block has a Dirichlet face (an outflow end of the box
    // is in one block only; a gas face in free_surface mode in some).
    system.singular = ranks.all(system.singular);
    ProjectionResult result;
    result.build_time = clock.lap();
    const BlockContext blocks(decomposition, ranks);
    result.solve = PressureSystemSolver(system, options, blocks).solve(system.rhs, pressure);
    blocks.exchange(pressure);
    result.singular = system.singular;
    apply_pressure_gradient(block, interface, phases, mode, dt, options, pressure, local);
    blocks.exchange(block);
    result.max_divergence = ranks.max(max_fluid_divergence(block, interface, mode));
    result.solve.converged = ranks.all(result.solve.converged);
    result.solve.residual = ranks.max(result.solve.residual);
    result.solve_time = clock.lap();
    return result;
}

}  // namespace meniscus::fluid
