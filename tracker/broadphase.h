#pragma once
/// \file Broad phase: which mesh elements may interact, from axis-aligned boxes (paper §4.5).
///
/// `LooseGrid` holds a static set of boxes for bulk queries and self joins; the dynamic
/// `SpatialHash` that remeshing keeps current is in spatial_hash.h.
///
/// `BroadPhase` holds one grid per element type (vertices, edges, triangles) for a mesh whose
/// vertices move linearly from x_t0 to x_t1 (swept boxes; static when x_t0 = x_t1) and
/// enumerates candidate pairs for CCD, proximity and intersection tests.
///
/// Periodic meshes (periods.h, issue 39): an element's box is built from its corners at their
/// images nearest its first corner at t0 (the same shift at t0 and at t1), the whole element
/// moved by whole periods so that that first corner lies in the fundamental box. A box within
/// E of a face of the fundamental box along a wrapping axis (E: the largest box extent along
/// that axis, padding included) is also stored at its image(s) shifted by ∓ the period (every
/// combination for two or three wrapping axes), so elements that meet across the box's faces
/// are paired. Pairs are reported once, by element index, never an element with its own image;
/// the caller reads each pair by the minimum image: the second element's vertices at their
/// images nearest the first element's first vertex at t0 (MeshPeriods::shift_towards), the
/// same shift at t0 and t1. The result equals the periodic brute force below (every pair
/// against the 3^k images of its second element). Non-periodic meshes take the path they
/// always took (one branch).

#include "tracker/mesh.h"
#include "tracker/spatial_hash.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

namespace meniscus::tracker {

/// A vertex and a triangle that does not contain it.
struct VertexTrianglePair {
    int vi, ti;
    friend bool operator==(const VertexTrianglePair& a, const VertexTrianglePair& b) {
        return a.vi == b.vi && a.ti == b.ti;
    }
    friend bool operator<(const VertexTrianglePair& a, const VertexTrianglePair& b) {
        return a.vi != b.vi ? a.vi < b.vi : a.ti < b.ti;
    }
};
/// Two edges without a common vertex, ei < ej.
struct EdgeEdgePair {
    int ei, ej;
    friend bool operator==(const EdgeEdgePair& a, const EdgeEdgePair& b) {
        return a.ei == b.ei && a.ej == b.ej;
    }
    friend bool operator<(const EdgeEdgePair& a, const EdgeEdgePair& b) {
        return a.ei != b.ei ? a.ei < b.ei : a.ej < b.ej;
    }
};
/// Two distinct triangles, ti < tj (they may share vertices).
struct TrianglePair {
    int ti, tj;
    friend bool operator==(const TrianglePair& a, const TrianglePair& b) {
        return a.ti == b.ti && a.tj == b.tj;
    }
    friend bool operator<(const TrianglePair& a, const TrianglePair& b) {
        return a.ti != b.ti ? a.ti < b.ti : a.tj < b.tj;
    }
};

/// Static loose grid for bulk queries: every element sits in exactly one cell (the one holding
/// its box's minimum corner), stored contiguously (CSR) and found through a flat hash of cell
/// keys; elements larger than a cell go to a list checked by every query. A query box looks at
/// the cells its box reaches extended by one cell towards −∞, which covers every element whose
/// box can overlap it. Built in O(n) by counting; queries are read-only and thread-safe.
class LooseGrid {
public:
    /// Builds over `boxes` (empty boxes are skipped); ids are the indices into `boxes`.
    explicit LooseGrid(const std::vector<Box3d>& boxes);  // keeps a reference to `boxes`
    LooseGrid(const LooseGrid&) = delete;
    LooseGrid& operator=(const LooseGrid&) = delete;
    /// Replaces `out` with the sorted ids whose boxes overlap `box` (closed boxes).
    void query(const Box3d& box, std::vector<int>& out) const;
    const Box3d& box(int id) const { return m_boxes[static_cast<size_t>(id)]; }
    bool contains(int id) const { return !m_boxes[static_cast<size_t>(id)].isEmpty(); }

    /// Every unordered pair of stored elements whose boxes overlap, each visited exactly once,
    /// grouped into `num_tasks()` independent tasks (for parallel loops): `visit(task, f)` calls
    /// f(i, j) for the pairs of task `task`. Cell by cell with a half stencil — each cell
    /// against itself and 13 of its 26 neighbours — so a pair is found once instead of twice
    /// and the hash is probed once per cell instead of once per element.
    size_t num_tasks() const { return m_cells.size() + m_oversized.size(); }
    template <typename F>
    void visit(size_t task, F&& f) const;

private:
    struct Cell {
        Eigen::Array3i coords;
        int begin, end;  // [begin, end) into m_ids
    };
    std::int64_t cell_key(const Eigen::Array3i& c) const;
    /// Index into m_cells of the cell at `coords`, −1 when no element lies there.
    int find_cell(const Eigen::Array3i& coords) const;
    /// The flat hash's slot of `key`: where it is stored, or the empty slot where it would go.
    size_t hash_slot(std::int64_t key) const;
    /// The dense table's entry of the cell at `coords` (which must lie in the table's block).
    size_t dense_slot(const Eigen::Array3i& coords) const;
    const std::vector<Box3d>& m_boxes;
    double m_cell = 1.0;
    std::vector<int> m_ids;                         // ids grouped by cell
    std::vector<Box3d> m_cell_boxes;                // their boxes, same order (sequential reads)
    std::vector<std::int64_t> m_slot_key;           // flat hash: key per slot (−1 = empty)
    std::vector<int> m_slot_cell;                   // index into m_cells per slot (−1 = empty)
    // Where the occupied cells fill a small enough block, a dense table over it replaces the
    // hash (index into m_cells or −1; empty when the hash is used).
    std::vector<int> m_dense;
    Eigen::Array3i m_dense_lo = Eigen::Array3i::Zero(), m_dense_size = Eigen::Array3i::Zero();
    std::vector<Cell> m_cells;                      // occupied cells, first-appearance order
    std::vector<Box3d> m_cell_union;                // per cell: the union of its elements' boxes
    std::vector<int> m_oversized;
};

/// Candidate pairs of a mesh moving linearly from x_t0 to x_t1.
class BroadPhase {
public:
    /// Builds boxes of all live vertices, edges and triangles swept from x_t0 to x_t1 (both
    /// sized mesh.num_vertices()), padded by `padding` ≥ 0 metres on every side.
    /// Throws std::invalid_argument on size mismatch or negative padding.
    BroadPhase(const SurfaceMesh& mesh, const std::vector<Vec3>& x_t0,
               const std::vector<Vec3>& x_t1, double padding);
    /// Static variant: x_t0 = x_t1 = the mesh's positions.
    BroadPhase(const SurfaceMesh& mesh, double padding);
    // The grids refer to the box arrays of this object: not copyable or movable.
    BroadPhase(const BroadPhase&) = delete;
    BroadPhase& operator=(const BroadPhase&) = delete;

    /// Vertex–triangle pairs with overlapping boxes, the vertex not in the triangle; sorted.
    std::vector<VertexTrianglePair> vertex_triangle_pairs() const;
    /// Edge–edge pairs with overlapping boxes and no shared vertex; sorted.
    std::vector<EdgeEdgePair> edge_edge_pairs() const;
    /// Triangle pairs with overlapping boxes (including neighbours); sorted.
    std::vector<TrianglePair> triangle_pairs() const;

private:
    /// Element of entry `id` of m_edge_boxes / m_triangle_boxes (an image maps to its element).
    int edge_of(int id) const {
        return id < m_num_edges ? id : m_edge_image_of[static_cast<size_t>(id - m_num_edges)];
    }
    int triangle_of(int id) const {
        return id < m_num_triangles
                   ? id
                   : m_triangle_image_of[static_cast<size_t>(id - m_num_triangles)];
    }

    const SurfaceMesh& m_mesh;
    // Boxes by element index; for a periodic mesh the images follow: entry num_edges() + k is
    // an image of edge m_edge_image_of[k] (likewise for triangles).
    std::vector<Box3d> m_vertex_boxes, m_edge_boxes, m_triangle_boxes;
    std::vector<int> m_edge_image_of, m_triangle_image_of;
    int m_num_edges = 0, m_num_triangles = 0;
    std::optional<LooseGrid> m_edges, m_triangles;  // built in the constructor's body
};

/// Edge–edge pairs of the mesh at rest (no shared vertex, ei < ej, sorted) whose boxes, padded
/// by `padding` ≥ 0, overlap and which `keep(ei, ej)` accepts — for callers that test every
/// candidate at once (merging): only edge boxes are built, and the test runs inside the
/// parallel join instead of on a list of every overlapping pair. `keep` may be called from
/// several threads at once. Throws std::invalid_argument on negative padding.
///
/// Periodic meshes: the boxes' images are paired as in BroadPhase; `keep` gets element indices
/// and must read the pair by the minimum image itself (ej's ends at their images nearest ei's
/// first end: mesh.position_near(v, mesh.position(mesh.edge(ei)[0]))). It may then be called
/// more than once for the same pair (found through two images); each pair is returned once.
std::vector<EdgeEdgePair> static_edge_edge_pairs(const SurfaceMesh& mesh, double padding,
                                                 const std::function<bool(int, int)>& keep);

/// Box of points moving linearly from p_t0[i] to p_t1[i], padded by `padding`.
Box3d swept_box(std::initializer_list<const Vec3*> p_t0, std::initializer_list<const Vec3*> p_t1,
                double padding);

/// Brute-force references (O(n²)) for tests: the same pairs the broad phase must include. For a
/// periodic mesh, each pair's first element's box against the boxes of the 3^k images of the
/// second (k wrapping axes; boxes as BroadPhase builds them).
std::vector<VertexTrianglePair> brute_force_vertex_triangle_pairs(const SurfaceMesh& mesh,
                                                                  const std::vector<Vec3>& x_t0,
                                                                  const std::vector<Vec3>& x_t1,
                                                                  double padding);
std::vector<EdgeEdgePair> brute_force_edge_edge_pairs(const SurfaceMesh& mesh,
                                                      const std::vector<Vec3>& x_t0,
                                                      const std::vector<Vec3>& x_t1,
                                                      double padding);
/// Triangle pairs (ti < tj) whose static boxes at the mesh's positions, padded, overlap.
std::vector<TrianglePair> brute_force_triangle_pairs(const SurfaceMesh& mesh, double padding);

}  // namespace meniscus::tracker
