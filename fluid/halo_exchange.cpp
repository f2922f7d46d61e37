#include "fluid/halo_exchange.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace meniscus::fluid {

namespace {

/// The layers of a field of `kind` along z (nz cells or nz + 1 faces).
int whole_layers(const SlabDecomposition& d, LayerKind kind) {
    return d.layers() + (kind == LayerKind::z_faces ? 1 : 0);
}

/// The global layer (wrapped into [0, whole_layers) on a periodic grid, where face nz is face 0)
/// at unwrapped position `g`.
int wrapped(const SlabDecomposition& d, int g, LayerKind kind) {
    if (kind == LayerKind::z_faces && !d.periodic())
        return g;
    return d.wrap(g);
}

/// The owner of the layer at unwrapped position `g`.
int owner_of(const SlabDecomposition& d, int g, LayerKind kind) {
    return kind == LayerKind::z_faces ? d.face_owner(wrapped(d, g, kind)) : d.owner(g);
}

/// True when `rank` owns the layer at unwrapped position `g` of its block (its own slab; the last
/// rank also the top face of a non-periodic grid).
bool owns(const SlabDecomposition& d, int rank, int g, LayerKind kind) {
    if (g >= d.owned_begin(rank) && g < d.owned_end(rank))
        return true;
    return kind == LayerKind::z_faces && !d.periodic() && rank == d.ranks() - 1 && g == d.layers();
}

/// True when the ghost layer at unwrapped position `g` of `rank`'s block lies within `depth`
/// layers of its own (depth ≤ 0: every ghost layer).
bool within(const SlabDecomposition& d, int rank, int g, int depth) {
    if (depth <= 0)
        return true;
    const int distance =
        g < d.owned_begin(rank) ? d.owned_begin(rank) - g : g - d.owned_end(rank) + 1;
    return distance <= depth;
}

/// The layer of `rank`'s block holding the owned copy of global layer `w` (wrapped).
int owned_position(const SlabDecomposition& d, int rank, int w) {
    return w - d.local_begin(rank);
}

std::size_t layer_size(const Array3<double>& a) {
    return static_cast<std::size_t>(a.ni()) * static_cast<std::size_t>(a.nj());
}

void check_block(const Array3<double>& block, const SlabDecomposition& d, int rank, LayerKind kind,
                 const char* what) {
    if (block.nk() != block_layers(d, rank, kind))
        throw std::invalid_argument(std::string(what) + ": rank " + std::to_string(rank) +
                                    "'s block has " + std::to_string(block.nk()) +
                                    " z-layers, its decomposition " +
                                    std::to_string(block_layers(d, rank, kind)));
}

}  // namespace

int block_layers(const SlabDecomposition& decomposition, int rank, LayerKind kind) {
    return decomposition.local_layers(rank) + (kind == LayerKind::z_faces ? 1 : 0);
}

void exchange_halos(Array3<double>& block, const SlabDecomposition& d,
                    const RankCommunicator& ranks, LayerKind kind, int depth) {
    check_block(block, d, ranks.rank(), kind, "exchange_halos");
    exchange_halo_layers(block.data(), layer_size(block), d, ranks, kind, depth);
}

void exchange_halo_layers(double* block, std::size_t size, const SlabDecomposition& d,
                          const RankCommunicator& ranks, LayerKind kind, int depth) {
    const int me = ranks.rank();
    if (d.ranks() != ranks.size())
        throw std::invalid_argument("exchange_halos: a decomposition over " +
                                    std::to_string(d.ranks()) + " ranks on " +
                                    std::to_string(ranks.size()));
    if (!d.distributed())
        return;
    // What every rank needs from this one, in the order of its block's layers.
    std::vector<std::vector<double>> sends(static_cast<std::size_t>(d.ranks()));
    for (int r = 0; r < d.ranks(); ++r)
        for (int layer = 0; layer < block_layers(d, r, kind); ++layer) {
            const int g = d.local_begin(r) + layer;
            if (owns(d, r, g, kind) || owner_of(d, g, kind) != me || !within(d, r, g, depth))
                continue;
            const double* from =
                block + size * static_cast<std::size_t>(owned_position(d, me, wrapped(d, g, kind)));
            std::vector<double>& to = sends[static_cast<std::size_t>(r)];
            to.insert(to.end(), from, from + size);
        }
    const std::vector<std::vector<double>> received = ranks.exchange(sends);
    std::vector<std::size_t> read(received.size(), 0);
    for (int layer = 0; layer < block_layers(d, me, kind); ++layer) {
        const int g = d.local_begin(me) + layer;
        if (owns(d, me, g, kind) || !within(d, me, g, depth))
            continue;
        const std::size_t from = static_cast<std::size_t>(owner_of(d, g, kind));
        if (read[from] + size > received[from].size())
            throw std::runtime_error("exchange_halos: rank " + std::to_string(from) +
                                     " sent fewer layers than expected");
        std::copy_n(received[from].begin() + static_cast<std::ptrdiff_t>(read[from]), size,
                    block + size * static_cast<std::size_t>(layer));
        read[from] += size;
    }
}

Array3<double> extract_block(const Array3<double>& whole, const SlabDecomposition& d, int rank,
                             LayerKind kind) {
    if (whole.nk() != whole_layers(d, kind))
        throw std::invalid_argument("extract_block: the field has " + std::to_string(whole.nk()) +
                                    " z-layers, the grid " + std::to_string(whole_layers(d, kind)));
    Array3<double> block(whole.ni(), whole.nj(), block_layers(d, rank, kind));
    const std::size_t size = layer_size(whole);
    for (int layer = 0; layer < block.nk(); ++layer) {
        const int w = wrapped(d, d.local_begin(rank) + layer, kind);
        std::copy_n(whole.data() + size * static_cast<std::size_t>(w), size,
                    block.data() + size * static_cast<std::size_t>(layer));
    }
    return block;
}

Array3<double> gather_field(const Array3<double>& block, const SlabDecomposition& d,
                            const RankCommunicator& ranks, LayerKind kind, int root) {
    const int me = ranks.rank();
    check_block(block, d, me, kind, "gather_field");
    const std::size_t size = layer_size(block);
    std::vector<std::vector<double>> sends(static_cast<std::size_t>(d.ranks()));
    std::vector<double>& mine = sends[static_cast<std::size_t>(root)];
    for (int layer = 0; layer < block.nk(); ++layer)
        if (owns(d, me, d.local_begin(me) + layer, kind))
            mine.insert(mine.end(), block.data() + size * static_cast<std::size_t>(layer),
                        block.data() + size * static_cast<std::size_t>(layer + 1));
    const std::vector<std::vector<double>> received = ranks.exchange(sends);
    if (me != root)
        return {};
    Array3<double> whole(block.ni(), block.nj(), whole_layers(d, kind));
    for (int r = 0; r < d.ranks(); ++r) {
        std::size_t read = 0;
        const std::vector<double>& from = received[static_cast<std::size_t>(r)];
        for (int layer = 0; layer < block_layers(d, r, kind); ++layer) {
            const int g = d.local_begin(r) + layer;
            if (!owns(d, r, g, kind))
                continue;
            std::copy_n(from.begin() + static_cast<std::ptrdiff_t>(read), size,
                        whole.data() + size * static_cast<std::size_t>(g));
            read += size;
        }
    }
    if (kind == LayerKind::z_faces && d.periodic())
        std::copy_n(whole.data(), size, whole.data() + size * static_cast<std::size_t>(d.layers()));
    return whole;
}

}  // namespace meniscus::fluid
