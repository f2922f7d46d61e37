#include "fluid/grid_block.h"

#include "fluid/poisson_matrix.h"

#include <algorithm>
#include <cmath>
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

BlockContext::BlockContext(const SlabDecomposition& decomposition, const RankCommunicator& ranks)
    : m_decomposition(decomposition), m_ranks(ranks) {
    if (decomposition.ranks() != ranks.size())
        throw std::invalid_argument("BlockContext: a decomposition over " +
                                    std::to_string(decomposition.ranks()) + " ranks on " +
                                    std::to_string(ranks.size()));
}

void BlockContext::exchange(Array3<double>& cells) const {
    if (distributed())
        exchange_halos(cells, m_decomposition, m_ranks, LayerKind::cells);
}

void BlockContext::exchange(MacGrid& block) const {
    if (distributed())
        exchange_velocity_halos(block, m_decomposition, m_ranks);
}

Array3<double> BlockContext::gather_whole(const Array3<double>& block, LayerKind kind) const {
    if (!distributed())
        return block;
    return gather_field(block, m_decomposition, m_ranks, kind, 0);
}

Array3<double> BlockContext::block_of(const Array3<double>& whole, LayerKind kind) const {
    if (!distributed())
        return whole;
    if (whole.nk() != whole_layers(kind))
        throw std::invalid_argument("BlockContext::block_of: a field of " +
                                    std::to_string(whole.nk()) + " z-layers, the grid has " +
                                    std::to_string(whole_layers(kind)));
    return extract_block(whole, m_decomposition, rank(), kind);
}

std::size_t BlockContext::owned_cells_begin(std::size_t layer) const {
    if (!distributed())
        return 0;
    const int r = rank();
    return layer * static_cast<std::size_t>(m_decomposition.owned_begin(r) -
                                            m_decomposition.local_begin(r));
}

std::size_t BlockContext::owned_cells_end(std::size_t layer) const {
    const int r = rank();
    if (!distributed())
        return layer * static_cast<std::size_t>(m_decomposition.layers());
    return layer *
           static_cast<std::size_t>(m_decomposition.owned_end(r) - m_decomposition.local_begin(r));
}

double BlockContext::dot_cells(const std::vector<double>& a, const std::vector<double>& b,
                               std::size_t layer) const {
    if (!distributed())
        return dot(a, b);  // poisson_matrix.h's, as the one-process solvers use
    double sum = 0.0;
    for (std::size_t c = owned_cells_begin(layer); c < owned_cells_end(layer); ++c)
        sum += a[c] * b[c];
    return m_ranks.sum(sum);
}

double BlockContext::max_abs_cells(const std::vector<double>& a, std::size_t layer) const {
    const std::size_t begin = distributed() ? owned_cells_begin(layer) : 0;
    const std::size_t end = distributed() ? owned_cells_end(layer) : a.size();
    double largest = 0.0;
    for (std::size_t c = begin; c < end; ++c)
        largest = std::max(largest, std::abs(a[c]));
    return m_ranks.max(largest);
}

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
