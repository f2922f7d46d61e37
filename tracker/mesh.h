#pragma once
/// \file The explicit surface: a triangle mesh with full adjacency (paper §3.2).
///
/// Connectivity is stored as triangles (oriented vertex triples), edges (unordered vertex pairs),
/// vertex→triangles, vertex→edges, edge→triangles and triangle→edges. Deleted vertices,
/// triangles and edges are tombstoned: their indices stay valid (and dead) until `compact()`,
/// which moves live elements into the dead slots and tells the registered observers how indices
/// moved, so that per-vertex data kept outside the mesh (velocities, labels) follows;
/// `sort_spatially()` renumbers everything into an order that keeps neighbours close in memory.
///
/// Admissible meshes (checked by `validate_connectivity()` in mesh_validate.h, not enforced on
/// every mutation): each triangle has three distinct live vertices; no two triangles share the
/// same three vertices; every edge has an even number of incident triangles, half of them using
/// it in each direction (consistent orientation); on open surfaces (§4.4) boundary edges have
/// exactly one triangle.

#include "common/binary_io.h"
#include "tracker/periods.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <vector>

namespace meniscus::tracker {

using Vec3 = Eigen::Vector3d;
/// Vertex indices of a triangle, counter-clockwise seen from the side its normal points to.
using Triangle = std::array<int, 3>;
/// Vertex indices of an edge, smaller index first.
using Edge = std::array<int, 2>;

/// Marks "no such element" in index-returning queries.
constexpr int INVALID_INDEX = -1;

/// The two regions a triangle separates. `inside` is the region behind the triangle (opposite
/// to its normal), `outside` the region its normal points into. Region 0 is conventionally the
/// ambient phase (gas), 1 the first enclosed phase (liquid).
struct LabelPair {
    int inside = 1;
    int outside = 0;
    friend bool operator==(const LabelPair& a, const LabelPair& b) {
        return a.inside == b.inside && a.outside == b.outside;
    }
    friend bool operator!=(const LabelPair& a, const LabelPair& b) { return !(a == b); }
};

/// Receives notifications of mesh changes that per-vertex data outside the mesh must follow.
/// All methods default to doing nothing; override the ones you need.
class MeshObserver {
public:
    virtual ~MeshObserver() = default;
    /// A vertex `vi` was appended by `add_vertex` (with no parents).
    virtual void on_vertex_added(int vi) {}
    /// Edge (v0, v1) was split; the new vertex `new_vi` sits at parameter `s` from v0 (0..1),
    /// before any pseudo-motion moves it.
    virtual void on_edge_split(int v0, int v1, int new_vi, double s) {}
    /// Edge (kept_vi, removed_vi) was collapsed into `kept_vi`; `s` is the parameter of the new
    /// position along the old edge measured from kept_vi (0 keeps kept_vi's place).
    virtual void on_edge_collapse(int kept_vi, int removed_vi, double s) {}
    /// `copy_vi` was created as a duplicate of `original_vi` (separation of singular vertices).
    virtual void on_vertex_duplicated(int original_vi, int copy_vi) {}
    /// compact() or sort_spatially() renumbered vertices: `old_to_new[vi]` is the new index or
    /// INVALID_INDEX.
    virtual void on_compact(const std::vector<int>& old_to_new_vertex) {}
};

/// Triangle mesh with adjacency, tombstoned deletion and observer notifications.
///
/// Index ranges include dead elements: iterate `0..num_vertices()` and skip
/// `!vertex_alive(vi)`, or call `compact()` first. Mutations never reuse dead indices.
class SurfaceMesh {
public:
    SurfaceMesh() = default;
    /// Builds a mesh from positions and triangles (labels default to {1, 0}).
    /// Throws std::invalid_argument if a triangle refers to a vertex out of range or repeats a
    /// vertex, or if `labels` is non-empty and its size differs from the triangle count.
    SurfaceMesh(std::vector<Vec3> positions, const std::vector<Triangle>& triangles,
                const std::vector<LabelPair>& labels = {});

    SurfaceMesh(const SurfaceMesh&);
    SurfaceMesh& operator=(const SurfaceMesh&);
    SurfaceMesh(SurfaceMesh&&) noexcept = default;
    SurfaceMesh& operator=(SurfaceMesh&&) noexcept = default;

    // ---- sizes (including dead slots) and liveness -------------------------------------
    int num_vertices() const { return static_cast<int>(m_positions.size()); }
    int num_triangles() const { return static_cast<int>(m_triangles.size()); }
    int num_edges() const { return static_cast<int>(m_edges.size()); }
    int count_live_vertices() const;
    int count_live_triangles() const;
    int count_live_edges() const;
    bool vertex_alive(int vi) const { return m_vertex_alive[static_cast<size_t>(vi)] != 0; }
    bool triangle_alive(int ti) const { return m_triangles[static_cast<size_t>(ti)][0] >= 0; }
    bool edge_alive(int ei) const { return m_edges[static_cast<size_t>(ei)][0] >= 0; }
    /// True if the mesh has dead slots that `compact()` would remove.
    bool has_dead_elements() const;

    // ---- geometry ----------------------------------------------------------------------
    const Vec3& position(int vi) const { return m_positions[static_cast<size_t>(vi)]; }
    void set_position(int vi, const Vec3& p) { m_positions[static_cast<size_t>(vi)] = p; }
    /// All vertex positions, dead slots included (their values are meaningless).
    const std::vector<Vec3>& positions() const { return m_positions; }
    /// Replaces all positions at once; `p.size()` must equal num_vertices() (else throws).
    void set_positions(const std::vector<Vec3>& p);

    // ---- periodic meshes (periods.h) -----------------------------------------------------
    /// The box the mesh wraps around; no axis wraps by default.
    const MeshPeriods& periods() const { return m_periods; }
    bool periodic() const { return m_periodic; }
    /// Sets the periods (validated, else throws std::invalid_argument) and moves every live
    /// vertex into the fundamental box. Elements are read by the minimum image from then on.
    void set_periods(const MeshPeriods& periods);
    /// Moves every live vertex into the fundamental box (after a motion; no-op if not periodic).
    void wrap_positions();
    /// Vertex vi's position at its image nearest `reference` (its position if not periodic).
    Vec3 position_near(int vi, const Vec3& reference) const {
        return m_periodic ? m_periods.nearest_image(position(vi), reference) : position(vi);
    }
    /// Triangle ti's corners, each at its image nearest the first corner.
    std::array<Vec3, 3> triangle_positions(int ti) const;
    /// Edge ei's ends, the second at its image nearest the first.
    std::array<Vec3, 2> edge_positions(int ei) const;

    // ---- connectivity ------------------------------------------------------------------
    const Triangle& triangle(int ti) const { return m_triangles[static_cast<size_t>(ti)]; }
    const LabelPair& labels(int ti) const { return m_labels[static_cast<size_t>(ti)]; }
    void set_labels(int ti, const LabelPair& l) { m_labels[static_cast<size_t>(ti)] = l; }
    const Edge& edge(int ei) const { return m_edges[static_cast<size_t>(ei)]; }
    /// Edge k of triangle ti joins triangle(ti)[k] and triangle(ti)[(k+1)%3].
    const std::array<int, 3>& triangle_edges(int ti) const {
        return m_triangle_edges[static_cast<size_t>(ti)];
    }
    const std::vector<int>& edge_triangles(int ei) const {
        return m_edge_triangles[static_cast<size_t>(ei)];
    }
    const std::vector<int>& vertex_triangles(int vi) const {
        return m_vertex_triangles[static_cast<size_t>(vi)];
    }
    const std::vector<int>& vertex_edges(int vi) const {
        return m_vertex_edges[static_cast<size_t>(vi)];
    }
    /// The live edge joining v0 and v1 (either order), or INVALID_INDEX.
    int find_edge(int v0, int v1) const;
    /// A live triangle on exactly these three vertices (any order), or INVALID_INDEX.
    int find_triangle(int v0, int v1, int v2) const;
    /// The vertex of triangle ti that is not on edge ei (ei must be an edge of ti).
    int opposite_vertex(int ti, int ei) const;
    /// +1 if triangle ti traverses edge ei from edge(ei)[0] to edge(ei)[1], −1 otherwise.
    int edge_orientation_in_triangle(int ti, int ei) const;
    /// True if edge ei has exactly one incident triangle (open surface boundary).
    bool is_boundary_edge(int ei) const { return edge_triangles(ei).size() == 1; }
    /// True if edge ei has more than two incident triangles.
    bool is_nonmanifold_edge(int ei) const { return edge_triangles(ei).size() > 2; }
    /// True if vertex vi touches a boundary edge.
    bool is_boundary_vertex(int vi) const;
    /// The other endpoint of edge ei seen from vertex vi.
    int other_vertex(int ei, int vi) const;

    // ---- primitive mutations (no geometric checks: callers decide safety) ---------------
    /// Appends a vertex; returns its index.
    int add_vertex(const Vec3& p);
    /// Appends a triangle (creating missing edges); returns its index.
    /// Throws std::invalid_argument on out-of-range/dead or repeated vertices.
    int add_triangle(const Triangle& t, const LabelPair& labels = {});
    /// Tombstones a triangle and drops edges left with no triangle.
    void remove_triangle(int ti);
    /// Tombstones a vertex; it must have no incident triangles (else throws).
    void remove_vertex(int vi);
    /// Splits edge ei at a new vertex placed at `position`, replacing each incident triangle
    /// (a, b, c) with (a, m, c) and (m, b, c). Labels are inherited. Returns the new vertex.
    /// `s` is the parameter of the split point measured from edge(ei)[0], reported to observers.
    int split_edge(int ei, const Vec3& position, double s = 0.5);
    /// Replaces the two triangles t0, t1 on edge ei (which must use the edge in opposite
    /// directions) by the two triangles on the other diagonal. Returns the new edge index.
    /// Throws std::invalid_argument if the triangles do not form such a pair.
    int flip_edge(int ei, int t0, int t1);
    /// Collapses edge ei: `removed_vi` (an endpoint) merges into `kept_vi` (the other), which
    /// moves to `position`. Triangles on the edge are deleted; the others are rewired. Does not
    /// remove duplicate triangles or degenerate tetrahedra that may result (see separation).
    /// `s` is the parameter of `position` along the edge from kept_vi, reported to observers.
    void collapse_edge(int ei, int kept_vi, const Vec3& position, double s);
    /// Replaces vertex `vi` by a new copy in the given triangles (each must contain vi).
    /// Returns the copy's index. Used to separate singular vertices.
    int duplicate_vertex(int vi, const std::vector<int>& triangles, const Vec3& copy_position);

    // ---- connectivity marks (what separate() has to look at again) ----------------------
    /// True if vertex vi was created, or a triangle was attached to it or detached from it,
    /// since clear_vertex_mark(vi). Whether a vertex is one manifold fan depends on nothing
    /// else, so an unmarked vertex found regular once is still regular. A mesh that is built
    /// or loaded (load_state) starts with every mark set; a copy keeps the original's marks.
    bool vertex_marked(int vi) const { return m_vertex_marked[static_cast<size_t>(vi)] != 0; }
    void clear_vertex_mark(int vi) { m_vertex_marked[static_cast<size_t>(vi)] = 0; }
    /// True if triangle ti was added since clear_triangle_marks() (every triangle of a mesh
    /// that is built or loaded starts marked).
    bool triangle_marked(int ti) const { return m_triangle_marked[static_cast<size_t>(ti)] != 0; }
    void clear_triangle_marks();

    /// Removes dead slots. Of each kind of element (vertices, triangles, edges), those below the
    /// live count keep their index and those above it move into the dead slots below it, in
    /// increasing order; adjacency lists keep their order. The cost follows the number of dead
    /// slots, not the mesh size. Observers receive the vertex map. Returns the vertex map.
    std::vector<int> compact();
    /// Renumbers a mesh without dead slots (else throws std::logic_error) so that vertices follow
    /// a Morton (Z-order) curve over the box of their positions, triangles their smallest vertex
    /// and edges their vertex pair; adjacency lists keep their order. Neighbours end up close in
    /// memory, which every pass over the mesh gains from. Observers receive the vertex map
    /// (on_compact). Returns the vertex map.
    std::vector<int> sort_spatially();
    /// Fraction of the live edges whose two vertex indices differ by more than
    /// max(64, live vertices / 32): a measure of how far the numbering is from keeping
    /// neighbours together (about 0.07–0.14 right after sort_spatially(), 0.6–0.8 for a mesher's
    /// or a long run's order). 0 for a mesh without edges.
    double far_edge_fraction() const;

    // ---- exact state (checkpoints) ---------------------------------------------------------
    /// Writes every array, dead slots and adjacency order included, so that load_state()
    /// rebuilds a mesh on which every later operation does exactly what it would have done here.
    void save_state(BinaryWriter& out) const;
    /// Replaces this mesh's contents by a state save_state() wrote, keeping its observers (they
    /// are not told: the caller restores their state too) and its periods (set by whoever built
    /// the mesh, as its observers are). Throws FormatError if the data is
    /// truncated or inconsistent (sizes that disagree, an index out of range), leaving the mesh
    /// unchanged.
    void load_state(BinaryReader& in);

    // ---- observers ---------------------------------------------------------------------
    /// Registers an observer (not owned; must outlive its registration).
    void add_observer(MeshObserver* observer);
    void remove_observer(MeshObserver* observer);

private:
    /// Appends a live, marked vertex without triangles (observers are not told); returns it.
    int append_vertex_slot(const Vec3& p);
    int add_edge(int v0, int v1);
    void remove_edge(int ei);
    void attach_triangle(int ti);
    void detach_triangle(int ti);

    std::vector<Vec3> m_positions;
    std::vector<std::uint8_t> m_vertex_alive;
    std::vector<std::uint8_t> m_vertex_marked;    // connectivity changed (see vertex_marked)
    std::vector<std::uint8_t> m_triangle_marked;  // added since the marks were cleared
    std::vector<Triangle> m_triangles;  // dead: {-1, -1, -1}
    std::vector<LabelPair> m_labels;
    std::vector<std::array<int, 3>> m_triangle_edges;
    std::vector<Edge> m_edges;  // dead: {-1, -1}
    std::vector<std::vector<int>> m_edge_triangles;
    std::vector<std::vector<int>> m_vertex_triangles;
    std::vector<std::vector<int>> m_vertex_edges;
    std::vector<MeshObserver*> m_observers;  // copies of a mesh start with none
    MeshPeriods m_periods;
    bool m_periodic = false;  // m_periods.any(), cached for the accessors
};

}  // namespace meniscus::tracker
