#pragma once
/// \file The MAC grid split over the ranks of a distributed run (issue 40): whole z-layers of
/// cells, a contiguous slab per rank, each rank holding its slab plus `ghost_layers` layers of its
/// neighbours' cells on either side (its *block*). Pure arithmetic: no MPI here (halo_exchange.h
/// moves the data).
///
/// z is split because it is the slowest index of Array3 (flat index i + ni·(j + nj·k)): a z-layer
/// of any field is one contiguous run of memory, so a halo is sent without packing.
///
/// Layers are numbered globally 0 … nz−1. A rank's block is the global layers
/// [local_begin, local_end): its own [owned_begin, owned_end) widened by the ghost layers, clipped
/// at a wall (non-periodic z) and wrapped around a periodic z (local_begin may then be < 0 and
/// local_end > nz: layer g of the block is global layer wrap(g)). One rank owns every layer and
/// has no ghosts, periodic or not (its block is the whole grid and keeps the periodic seam).
///
/// Faces along z (the w velocity, κ on z-faces) have one layer more: face g lies below cell g.
/// Face g belongs to the owner of cell g; the top face nz of a non-periodic grid to the last rank;
/// on a periodic grid face nz is face 0.

#include <vector>

namespace meniscus::fluid {

/// See the file comment.
class SlabDecomposition {
public:
    /// One rank owning all `layers` (nz) layers: no ghosts.
    explicit SlabDecomposition(int layers = 1);
    /// `layers` z-layers (nz ≥ 1) over `ranks` ranks (≥ 1) as evenly as whole layers allow (the
    /// first nz mod ranks ranks hold one more), with `ghost_layers` (≥ 0) on either side of each
    /// slab; `periodic`: z is periodic. Throws std::invalid_argument naming the argument when a
    /// rank would hold fewer layers than `ghost_layers` (its ghosts would then reach past its
    /// neighbours) or fewer than one.
    SlabDecomposition(int layers, int ranks, int ghost_layers, bool periodic);

    int layers() const { return m_layers; }
    int ranks() const { return static_cast<int>(m_begin.size()) - 1; }
    int ghost_layers() const { return m_ghosts; }
    bool periodic() const { return m_periodic; }
    /// True when more than one rank holds the grid.
    bool distributed() const { return ranks() > 1; }

    /// The layers `rank` owns: [owned_begin, owned_end).
    int owned_begin(int rank) const;
    int owned_end(int rank) const;
    /// Its block: [local_begin, local_end) (see the file comment; may lie beyond [0, nz) only on a
    /// periodic grid).
    int local_begin(int rank) const;
    int local_end(int rank) const;
    /// Cells of the block along z.
    int local_layers(int rank) const { return local_end(rank) - local_begin(rank); }

    /// The global layer index g ∈ [0, nz) of a possibly wrapped index (periodic z; on a
    /// non-periodic grid `layer` must already be in range). Throws std::out_of_range otherwise.
    int wrap(int layer) const;
    /// The rank owning cell layer `layer` (wrapped first on a periodic grid).
    int owner(int layer) const;
    /// The rank owning face layer `face` (0 … nz; wrapped on a periodic grid, where face nz is
    /// face 0).
    int face_owner(int face) const;

private:
    int m_layers = 1;
    int m_ghosts = 0;
    bool m_periodic = false;
    std::vector<int> m_begin;  ///< per rank its first layer, then nz
};

}  // namespace meniscus::fluid
