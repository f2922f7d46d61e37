#pragma once
/// \file A dynamic uniform-grid hash of axis-aligned boxes (paper §4.5's broad phase, for
/// structures that change while they are queried: remeshing's ElementHash, the mesher's crease
/// points). A box query returns every stored element whose box overlaps it — exactly the brute
/// force answer (every pair of overlapping boxes shares at least one cell, and the final filter
/// is an exact box-overlap test).

#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

namespace meniscus::tracker {

using Box3d = Eigen::AlignedBox3d;

/// Dynamic uniform-grid hash of boxes keyed by element index. Flat storage: an open-addressing
/// table of cells whose lists are linked entries in one pool.
class SpatialHash {
public:
    /// Boxes covering more cells than this are kept in a list checked on every query instead.
    static constexpr long long MAX_CELLS_PER_BOX = 512;
    /// `cell_size` (> 0, metres) should be near the typical box extent. Throws otherwise.
    explicit SpatialHash(double cell_size = 1.0);
    /// Inserts or replaces element `id`'s box (id ≥ 0).
    void insert(int id, const Box3d& box);
    /// Removes element `id` (no-op if absent).
    void remove(int id);
    /// Replaces `out` with every element whose box overlaps `box` (closed boxes), each once,
    /// sorted. Safe to call from several threads at once (no mutation).
    void query(const Box3d& box, std::vector<int>& out) const;
    bool contains(int id) const;
    const Box3d& box(int id) const { return m_boxes[static_cast<size_t>(id)]; }
    double cell_size() const { return m_cell; }
    void clear();

    /// The key of cell (i, j, k): 21 bits per axis, offset into the non-negative range (cells
    /// more than about a million apart may alias, which only merges lists: a superset). Also the
    /// static broad phase's cell key (LooseGrid).
    static std::int64_t key(int i, int j, int k);
    /// The hash of a cell key that picks its first slot in an open-addressing table.
    static std::uint64_t mix_key(std::int64_t key);

private:
    struct CellRange {
        Eigen::Array3i lo, hi;
        bool oversized = false;
    };
    CellRange cells_of(const Box3d& box) const;
    /// The slot holding `key`, or the free slot where linear probing from its hash ends (the
    /// table must not be empty).
    size_t probe(std::int64_t key) const;
    /// Slot of `key` in the open-addressing table, or −1 when absent.
    int find_slot(std::int64_t key) const;
    /// Slot of `key`, added (with an empty list) when absent; may grow the table.
    int find_or_add_slot(std::int64_t key);
    void grow();

    double m_cell;
    // Flat hash of cells (open addressing, linear probing; keys stay once added, with possibly
    // empty lists, until clear()): per slot the cell key (−1 = free) and the head of its list.
    std::vector<std::int64_t> m_slot_key;
    std::vector<int> m_slot_head;
    size_t m_used_slots = 0;
    // Cell lists as singly linked entries in one pool, with a free list (no allocation per
    // cell or per insert once the pool has grown).
    std::vector<int> m_entry_id, m_entry_next;
    int m_free_entry = -1;
    std::vector<int> m_oversized;  // boxes spanning too many cells, checked on every query
    std::vector<Box3d> m_boxes;
    std::vector<CellRange> m_ranges;
    std::vector<std::uint8_t> m_present;
};

/// True when the closed boxes a and b overlap (touching counts).
inline bool closed_boxes_overlap(const Box3d& a, const Box3d& b) {
    return (a.min().array() <= b.max().array()).all() && (b.min().array() <= a.max().array()).all();
}

}  // namespace meniscus::tracker
