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

namespace meniscus::fluid {

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
