#pragma once
/// \file A rank's block of the MAC grid in a distributed run (issue 40): the grid, the boundary
/// conditions and the interface on its slab of z-layers plus ghost layers (slab_decomposition.h),
/// and the whole grid's velocities assembled from the blocks.
///
/// A block is an ordinary MacGrid whose origin is the whole box's raised by local_begin·Δx, so
/// every operator of fluid/ runs on it unchanged; what those operators compute in its ghost
/// layers next to its ends is wrong (they see a wall there) and is replaced by the owners' values
/// through exchange_halos() after each phase. Along a distributed periodic z the block does not
/// wrap (its ghost layers hold the other side of the seam); x and y wrap as the whole grid does.

#include "fluid/boundary.h"
#include "fluid/halo_exchange.h"
#include "fluid/interface_input.h"
#include "fluid/mac_grid.h"

#include <vector>

namespace meniscus::fluid {

/// A rank's place in a distributed run: how the grid is split, the ranks, and the collective
/// operations the fluid step needs on its block. The default is one process, on which every
/// operation is local (exchanges do nothing, sums are plain sums).
class BlockContext {
public:
    BlockContext() = default;
    /// Throws std::invalid_argument when the decomposition is not over ranks.size() ranks.
    BlockContext(const SlabDecomposition& decomposition, const RankCommunicator& ranks);

    bool distributed() const { return m_decomposition.distributed(); }
    const SlabDecomposition& decomposition() const { return m_decomposition; }
    const RankCommunicator& ranks() const { return m_ranks; }
    int rank() const { return m_ranks.rank(); }

    /// Collective: fills the ghost layers of a block's cell field, or of its three velocity
    /// components.
    void exchange(Array3<double>& cells) const;
    void exchange(MacGrid& block) const;
    /// Σ a_c b_c over the cells this rank owns, summed over the ranks; a and b are block cell
    /// vectors with `layer` cells per z-layer (one process: over every cell).
    double dot_cells(const std::vector<double>& a, const std::vector<double>& b,
                     std::size_t layer) const;
    /// max |a_c| over the cells this rank owns, over the ranks.
    double max_abs_cells(const std::vector<double>& a, std::size_t layer) const;
    /// The range [begin, end) of the flat indices of the owned cells of a block cell vector.
    std::size_t owned_cells_begin(std::size_t layer) const;
    std::size_t owned_cells_end(std::size_t layer) const;
    /// Collective: the whole field of `kind` assembled from every rank's owned layers on rank 0
    /// (an empty array on the others); one process: a copy of `block`.
    Array3<double> gather_whole(const Array3<double>& block, LayerKind kind) const;
    /// This rank's block (ghost layers included) of a field of `kind` held whole; one process: a
    /// copy. Throws std::invalid_argument when `whole` does not have the decomposition's layers.
    Array3<double> block_of(const Array3<double>& whole, LayerKind kind) const;
    /// z-layers of the whole field of `kind` (the decomposition's, one more for z-faces).
    int whole_layers(LayerKind kind) const {
        return m_decomposition.layers() + (kind == LayerKind::z_faces ? 1 : 0);
    }
    double sum(double value) const { return m_ranks.sum(value); }
    double max(double value) const { return m_ranks.max(value); }
    double min(double value) const { return m_ranks.min(value); }
    bool all(bool value) const { return m_ranks.all(value); }

private:
    SlabDecomposition m_decomposition;
    RankCommunicator m_ranks = RankCommunicator::self();
};

/// The block of `rank` of a whole grid shaped like `whole` (its velocities are not copied), with
/// zero velocity.
MacGrid block_grid(const MacGrid& whole, const SlabDecomposition& decomposition, int rank);

/// The boundary conditions of `rank`'s block: the whole box's, except that a z face of the block
/// that is not a z face of the box (an end inside the grid, or any end of a block of a
/// distributed periodic z) is a free-slip wall (it only shapes the ghost layers' values, which
/// the owners' replace).
BoundaryOptions block_boundaries(const BoundaryOptions& whole,
                                 const SlabDecomposition& decomposition, int rank);

/// `rank`'s block of the velocities of `whole` (every rank holds the whole grid: tests, a run's
/// start).
MacGrid extract_block_grid(const MacGrid& whole, const SlabDecomposition& decomposition, int rank);

/// `rank`'s block of an interface given on the whole grid (φ and κ; not the surface viscosity).
InterfaceInput extract_block_interface(const InterfaceInput& whole,
                                       const SlabDecomposition& decomposition, int rank);

/// Collective: fills the ghost layers of the three velocity components of `block`.
void exchange_velocity_halos(MacGrid& block, const SlabDecomposition& decomposition,
                             const RankCommunicator& ranks);

/// Collective: the whole grid's velocities assembled from every rank's owned layers into
/// `whole` (shaped like the whole grid) on rank `root`; `whole` is left alone on the others.
void gather_velocities(const MacGrid& block, const SlabDecomposition& decomposition,
                       const RankCommunicator& ranks, MacGrid& whole, int root = 0);

}  // namespace meniscus::fluid
