#include "fluid/slab_decomposition.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace meniscus::fluid {

SlabDecomposition::SlabDecomposition(int layers) : SlabDecomposition(layers, 1, 0, false) {}

SlabDecomposition::SlabDecomposition(int layers, int ranks, int ghost_layers, bool periodic)
    : m_layers(layers), m_ghosts(ghost_layers), m_periodic(periodic) {
    if (layers < 1)
        throw std::invalid_argument("SlabDecomposition: layers must be >= 1, got " +
                                    std::to_string(layers));
    if (ranks < 1)
        throw std::invalid_argument("SlabDecomposition: ranks must be >= 1, got " +
                                    std::to_string(ranks));
    if (ghost_layers < 0)
        throw std::invalid_argument("SlabDecomposition: ghost_layers must be >= 0, got " +
                                    std::to_string(ghost_layers));
    const int smallest = layers / ranks;
    if (smallest < 1 || (ranks > 1 && smallest < ghost_layers))
        throw std::invalid_argument(
            "SlabDecomposition: " + std::to_string(layers) + " z-layers over " +
            std::to_string(ranks) + " ranks leave " + std::to_string(smallest) +
            " layers to a rank, fewer than " +
            (smallest < 1 ? std::string("one")
                          : "the " + std::to_string(ghost_layers) + " ghost layers") +
            ": use fewer ranks or more cells");
    if (ranks == 1)
        m_ghosts = 0;
    m_begin.resize(static_cast<size_t>(ranks) + 1);
    const int extra = layers % ranks;
    m_begin[0] = 0;
    for (int r = 0; r < ranks; ++r)
        m_begin[static_cast<size_t>(r) + 1] =
            m_begin[static_cast<size_t>(r)] + smallest + (r < extra ? 1 : 0);
}

int SlabDecomposition::owned_begin(int rank) const {
    if (rank < 0 || rank >= ranks())
        throw std::out_of_range("SlabDecomposition: rank " + std::to_string(rank) +
                                " out of range");
    return m_begin[static_cast<size_t>(rank)];
}

int SlabDecomposition::owned_end(int rank) const {
    owned_begin(rank);  // checks the rank
    return m_begin[static_cast<size_t>(rank) + 1];
}

int SlabDecomposition::local_begin(int rank) const {
    const int begin = owned_begin(rank) - m_ghosts;
    return m_periodic ? begin : std::max(begin, 0);
}

int SlabDecomposition::local_end(int rank) const {
    const int end = owned_end(rank) + m_ghosts;
    return m_periodic ? end : std::min(end, m_layers);
}

int SlabDecomposition::wrap(int layer) const {
    if (m_periodic)
        return ((layer % m_layers) + m_layers) % m_layers;
    if (layer < 0 || layer >= m_layers)
        throw std::out_of_range("SlabDecomposition: layer " + std::to_string(layer) +
                                " outside the grid's " + std::to_string(m_layers));
    return layer;
}

int SlabDecomposition::owner(int layer) const {
    const int g = wrap(layer);
    // The last rank whose first layer is ≤ g.
    const auto it = std::upper_bound(m_begin.begin(), m_begin.end() - 1, g);
    return static_cast<int>(it - m_begin.begin()) - 1;
}

int SlabDecomposition::face_owner(int face) const {
    if (!m_periodic && face == m_layers)
        return ranks() - 1;
    return owner(face);
}

}  // namespace meniscus::fluid
