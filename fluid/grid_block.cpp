#include "fluid/grid_block.h"

#include <stdexcept>
#include <string>

namespace meniscus::fluid {

namespace {

LayerKind kind_of_component(int axis) {
    return axis == 2 ? LayerKind::z_faces : LayerKind::cells;
}

void check_shape(const MacGrid& whole, const SlabDecomposition& d, const char* what) {
    if (whole.nz() != d.layers())
        throw std::invalid_argument(std::string(what) + ": the grid has " +
                                    std::to_string(whole.nz()) + " z-layers, the decomposition " +
                                    std::to_string(d.layers()));
    if (d.periodic() != whole.periodic()[2])
        throw std::invalid_argument(std::string(what) +
                                    ": the decomposition and the grid disagree on a periodic z");
}

}  // namespace

MacGrid block_grid(const MacGrid& whole, const SlabDecomposition& d, int rank) {
    check_shape(whole, d, "block_grid");
    Eigen::Vector3d origin = whole.origin();
    origin.z() += whole.dx() * d.local_begin(rank);
    MacGrid block(whole.nx(), whole.ny(), d.local_layers(rank), whole.dx(), origin);
    Periodicity periodic = whole.periodic();
    if (d.distributed())
        periodic[2] = false;
    block.set_periodic(periodic);
    return block;
}

BoundaryOptions block_boundaries(const BoundaryOptions& whole, const SlabDecomposition& d,
                                 int rank) {
    if (!d.distributed())
        return whole;
    BoundaryOptions block = whole;
    const bool bottom = !d.periodic() && d.local_begin(rank) == 0;
    const bool top = !d.periodic() && d.local_end(rank) == d.layers();
    if (!bottom)
        block.z_min = FaceBoundary{};
    if (!top)
        block.z_max = FaceBoundary{};
    return block;
}

MacGrid extract_block_grid(const MacGrid& whole, const SlabDecomposition& d, int rank) {
    MacGrid block = block_grid(whole, d, rank);
    for (int axis = 0; axis < 3; ++axis)
        block.velocity(axis) =
            extract_block(whole.velocity(axis), d, rank, kind_of_component(axis));
    return block;
}

InterfaceInput extract_block_interface(const InterfaceInput& whole, const SlabDecomposition& d,
                                       int rank) {
    InterfaceInput block;
    block.phi = extract_block(whole.phi, d, rank, LayerKind::cells);
    for (int axis = 0; axis < 3; ++axis)
        block.kappa(axis) = extract_block(whole.kappa(axis), d, rank, kind_of_component(axis));
    return block;
}

void exchange_velocity_halos(MacGrid& block, const SlabDecomposition& d,
                             const RankCommunicator& ranks) {
    for (int axis = 0; axis < 3; ++axis)
        exchange_halos(block.velocity(axis), d, ranks, kind_of_component(axis));
}

void gather_velocities(const MacGrid& block, const SlabDecomposition& d,
                       const RankCommunicator& ranks, MacGrid& whole, int root) {
    for (int axis = 0; axis < 3; ++axis) {
        Array3<double> field =
            gather_field(block.velocity(axis), d, ranks, kind_of_component(axis), root);
        if (ranks.rank() == root)
            whole.velocity(axis) = std::move(field);
    }
}

}  // namespace meniscus::fluid
