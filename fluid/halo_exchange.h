#pragma once
/// \file Moving a field's z-layers between the ranks of a distributed run (issue 40): filling a
/// rank's ghost layers from the ranks that own them after every phase that changed the field,
/// handing each rank its block of a field that one process holds whole, and assembling the whole
/// field from the owned layers (output). The layout is slab_decomposition.h's: a block of a
/// cell-centred field has decomposition.local_layers(rank) z-layers, a field on z-faces one more.

#include <cstddef>

#include "fluid/array3.h"
#include "fluid/rank_communicator.h"
#include "fluid/slab_decomposition.h"

namespace meniscus::fluid {

/// Where a field lives along z: at cell centres (or on x- and y-faces), or on z-faces.
enum class LayerKind { cells, z_faces };

/// z-layers of `rank`'s block of a field of `kind`.
int block_layers(const SlabDecomposition& decomposition, int rank, LayerKind kind);

/// Collective: fills every ghost layer of `block` (this rank's block of a field of `kind`) with
/// the owner's values of that layer. Owned layers are sent, never changed. Throws
/// std::invalid_argument when `block` does not have block_layers() z-layers.
/// `depth` > 0: only the ghost layers within `depth` layers of the rank's own (what a stencil of
/// that reach reads; the viscous CG refreshes 2 of 5 every iteration).
void exchange_halos(Array3<double>& block, const SlabDecomposition& decomposition,
                    const RankCommunicator& ranks, LayerKind kind, int depth = 0);
/// exchange_halos() on a block stored elsewhere: block_layers() contiguous z-layers of
/// `layer_size` values each from `block` (a component inside a longer vector).
void exchange_halo_layers(double* block, std::size_t layer_size,
                          const SlabDecomposition& decomposition, const RankCommunicator& ranks,
                          LayerKind kind, int depth = 0);

/// `rank`'s block of a field that is held whole (nz or nz + 1 z-layers): its layers, ghosts
/// included, wrapped around a periodic z.
Array3<double> extract_block(const Array3<double>& whole, const SlabDecomposition& decomposition,
                             int rank, LayerKind kind);

/// Collective: the whole field assembled from every rank's owned layers, on rank `root`; an empty
/// array on the others.
Array3<double> gather_field(const Array3<double>& block, const SlabDecomposition& decomposition,
                            const RankCommunicator& ranks, LayerKind kind, int root = 0);

}  // namespace meniscus::fluid
