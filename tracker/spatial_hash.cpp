#include "tracker/spatial_hash.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace meniscus::tracker {

SpatialHash::SpatialHash(double cell_size) : m_cell(cell_size) {
    if (!(cell_size > 0.0) || !std::isfinite(cell_size))
        throw std::invalid_argument("SpatialHash: cell_size must be a finite number > 0");
}

namespace {

/// SpatialHash table: initial slot count (a power of two) and maximum load before growing.
constexpr size_t SPATIAL_HASH_INITIAL_SLOTS = 1024;
constexpr double SPATIAL_HASH_MAX_LOAD = 0.5;
/// Cell coordinates are packed 21 bits per axis; beyond ±2²⁰ cells they alias, which only merges
/// lists (the exact box filter removes the extras).
constexpr std::int64_t CELL_BITS_MASK = (1 << 21) - 1;
constexpr std::int64_t CELL_OFFSET = 1 << 20;

}  // namespace

std::uint64_t SpatialHash::mix_key(std::int64_t key) {
    std::uint64_t x = static_cast<std::uint64_t>(key);
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    return x;
}

std::int64_t SpatialHash::key(int i, int j, int k) {
    return ((static_cast<std::int64_t>(i) + CELL_OFFSET) & CELL_BITS_MASK) |
           (((static_cast<std::int64_t>(j) + CELL_OFFSET) & CELL_BITS_MASK) << 21) |
           (((static_cast<std::int64_t>(k) + CELL_OFFSET) & CELL_BITS_MASK) << 42);
}

size_t SpatialHash::probe(std::int64_t key) const {
    const size_t mask = m_slot_key.size() - 1;
    size_t slot = mix_key(key) & mask;
    while (m_slot_key[slot] != -1 && m_slot_key[slot] != key)
        slot = (slot + 1) & mask;
    return slot;
}

int SpatialHash::find_slot(std::int64_t key) const {
    if (m_slot_key.empty())
        return -1;
    const size_t slot = probe(key);
    return m_slot_key[slot] == key ? static_cast<int>(slot) : -1;
}

void SpatialHash::grow() {
    const size_t slots = m_slot_key.empty() ? SPATIAL_HASH_INITIAL_SLOTS : 2 * m_slot_key.size();
    std::vector<std::int64_t> old_key(slots, -1);
    std::vector<int> old_head(slots, -1);
    old_key.swap(m_slot_key);
    old_head.swap(m_slot_head);
    for (size_t i = 0; i < old_key.size(); ++i) {
        if (old_key[i] == -1)
            continue;
        const size_t slot = probe(old_key[i]);  // keys are distinct: a free slot
        m_slot_key[slot] = old_key[i];
        m_slot_head[slot] = old_head[i];
    }
}

int SpatialHash::find_or_add_slot(std::int64_t key) {
    if (static_cast<double>(m_used_slots + 1) >
        SPATIAL_HASH_MAX_LOAD * static_cast<double>(m_slot_key.size()))
        grow();
    const size_t slot = probe(key);
    if (m_slot_key[slot] == key)
        return static_cast<int>(slot);
    m_slot_key[slot] = key;
    m_slot_head[slot] = -1;
    ++m_used_slots;
    return static_cast<int>(slot);
}

SpatialHash::CellRange SpatialHash::cells_of(const Box3d& box) const {
    CellRange r;
    const Eigen::Array3d lo = (box.min().array() / m_cell).floor();
    const Eigen::Array3d hi = (box.max().array() / m_cell).floor();
    const double limit = std::numeric_limits<int>::max() / 2;
    if ((lo.abs() > limit).any() || (hi.abs() > limit).any() || !lo.allFinite() ||
        !hi.allFinite()) {
        r.oversized = true;
        return r;
    }
    r.lo = lo.cast<int>();
    r.hi = hi.cast<int>();
    const Eigen::Array3d span = (hi - lo) + 1.0;
    r.oversized = span.prod() > static_cast<double>(SpatialHash::MAX_CELLS_PER_BOX);
    return r;
}

void SpatialHash::insert(int id, const Box3d& box) {
    if (id < 0)
        throw std::invalid_argument("SpatialHash::insert: negative id");
    remove(id);
    const auto i = static_cast<size_t>(id);
    if (m_boxes.size() <= i) {
        m_boxes.resize(i + 1);
        m_ranges.resize(i + 1);
        m_present.resize(i + 1, 0);
    }
    m_boxes[i] = box;
    m_ranges[i] = cells_of(box);
    m_present[i] = 1;
    const CellRange& r = m_ranges[i];
    if (r.oversized) {
        m_oversized.push_back(id);
        return;
    }
    for (int z = r.lo.z(); z <= r.hi.z(); ++z)
        for (int y = r.lo.y(); y <= r.hi.y(); ++y)
            for (int x = r.lo.x(); x <= r.hi.x(); ++x) {
                const auto slot = static_cast<size_t>(find_or_add_slot(key(x, y, z)));
                int entry = m_free_entry;
                if (entry >= 0) {
                    m_free_entry = m_entry_next[static_cast<size_t>(entry)];
                } else {
                    entry = static_cast<int>(m_entry_id.size());
                    m_entry_id.push_back(id);
                    m_entry_next.push_back(-1);
                }
                m_entry_id[static_cast<size_t>(entry)] = id;
                m_entry_next[static_cast<size_t>(entry)] = m_slot_head[slot];
                m_slot_head[slot] = entry;
            }
}

void SpatialHash::remove(int id) {
    if (!contains(id))
        return;
    const auto i = static_cast<size_t>(id);
    const CellRange& r = m_ranges[i];
    if (r.oversized) {
        auto it = std::find(m_oversized.begin(), m_oversized.end(), id);
        if (it != m_oversized.end()) {
            *it = m_oversized.back();
            m_oversized.pop_back();
        }
    } else {
        for (int z = r.lo.z(); z <= r.hi.z(); ++z)
            for (int y = r.lo.y(); y <= r.hi.y(); ++y)
                for (int x = r.lo.x(); x <= r.hi.x(); ++x) {
                    const int slot = find_slot(key(x, y, z));
                    if (slot < 0)
                        continue;
                    // Unlink one entry of `id` from the cell's list.
                    int* link = &m_slot_head[static_cast<size_t>(slot)];
                    while (*link >= 0 && m_entry_id[static_cast<size_t>(*link)] != id)
                        link = &m_entry_next[static_cast<size_t>(*link)];
                    if (*link < 0)
                        continue;
                    const int entry = *link;
                    *link = m_entry_next[static_cast<size_t>(entry)];
                    m_entry_next[static_cast<size_t>(entry)] = m_free_entry;
                    m_free_entry = entry;
                }
    }
    m_present[i] = 0;
}

bool SpatialHash::contains(int id) const {
    return id >= 0 && static_cast<size_t>(id) < m_present.size() &&
           m_present[static_cast<size_t>(id)];
}

void SpatialHash::query(const Box3d& box, std::vector<int>& out) const {
    out.clear();
    const CellRange r = cells_of(box);
    if (r.oversized) {
        for (size_t i = 0; i < m_present.size(); ++i)
            if (m_present[i] && closed_boxes_overlap(m_boxes[i], box))
                out.push_back(static_cast<int>(i));
        return;
    }
    for (int z = r.lo.z(); z <= r.hi.z(); ++z)
        for (int y = r.lo.y(); y <= r.hi.y(); ++y)
            for (int x = r.lo.x(); x <= r.hi.x(); ++x) {
                const int slot = find_slot(key(x, y, z));
                if (slot < 0)
                    continue;
                for (int entry = m_slot_head[static_cast<size_t>(slot)]; entry >= 0;
                     entry = m_entry_next[static_cast<size_t>(entry)]) {
                    const int id = m_entry_id[static_cast<size_t>(entry)];
                    if (closed_boxes_overlap(m_boxes[static_cast<size_t>(id)], box))
                        out.push_back(id);
                }
            }
    for (int id : m_oversized)
        if (closed_boxes_overlap(m_boxes[static_cast<size_t>(id)], box))
            out.push_back(id);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
}

void SpatialHash::clear() {
    m_slot_key.clear();
    m_slot_head.clear();
    m_used_slots = 0;
    m_entry_id.clear();
    m_entry_next.clear();
    m_free_entry = -1;
    m_oversized.clear();
    m_boxes.clear();
    m_ranges.clear();
    m_present.clear();
}

}  // namespace meniscus::tracker
