#pragma once
/// \file The broad phase of one step's collision handling (collision_resolution.h): the pairs of
/// elements whose boxes may overlap during the motion x0 → x0 + d, built once with a slack and
/// reused by the repulsion and the CCD sweeps while the displacements stay within it.
///
/// A candidate set built for displacements d_ref with boxes padded by p is a superset of the
/// pairs whose unpadded swept boxes overlap for any d with ‖d − d_ref‖∞ ≤ p/2 (minus the rounding
/// of the box corners; covers()). Each query then keeps only the candidates whose boxes overlap
/// exactly for its own motion, so the pairs it tests are the ones a fresh broad phase gives, in
/// the same (sorted) order.
///
/// Periodic meshes (issue 39): every pair is read by the minimum image — the pair's vertices v
/// (v[0] the first vertex of its first element) at their images nearest x0(v[0]), the same shift
/// at both times (pair_positions()).

#include "tracker/broadphase.h"
#include "tracker/mesh.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace meniscus::tracker {

/// The positions at t0 and t1 of a pair's four vertices `v` (a vertex and a triangle's corners, or
/// two edges' ends): on a periodic mesh vertex k at x0(v[k]) + s_k and x1(v[k]) + s_k with
/// s_k = shift_towards(x0(v[k]), x0(v[0])); the plain positions otherwise.
void pair_positions(const SurfaceMesh& mesh, const std::vector<Vec3>& x0,
                    const std::vector<Vec3>& x1, const std::array<int, 4>& v,
                    std::array<Vec3, 4>& p0, std::array<Vec3, 4>& p1);

/// Do two axis-aligned boxes overlap (closed boxes: touching counts)?
inline bool boxes_overlap(const Box3d& a, const Box3d& b) {
    return (a.min().array() <= b.max().array()).all() &&
           (b.min().array() <= a.max().array()).all();
}

/// The candidate pairs of one step's collision handling for a mesh at x0 (see the file comment).
/// Keeps references to `mesh` and `x0`, which must outlive it.
class CollisionCandidates {
public:
    /// `proximity_epsilon`: the repulsion distance ε_p (> 0), the unit of the slack.
    CollisionCandidates(const SurfaceMesh& mesh, const std::vector<Vec3>& x0,
                        double proximity_epsilon);

    /// Builds the candidates of the motion x0 → x0 + d with boxes padded by `padding` plus the
    /// default slack (a few ε_p): repulsion's static boxes padded by `padding` and the first CCD
    /// sweep's swept boxes both lie inside them.
    void build(const std::vector<Vec3>& d, double padding);

    /// Keeps the candidates when they cover d, else rebuilds them around d with a slack grown to
    /// a few times how far d left them (capped by the motion and the mesh's edge length; at least
    /// the default). Returns true when it rebuilt them.
    bool cover(const std::vector<Vec3>& d);

    /// True when every unpadded box of the motion x0 → x0 + d lies inside the one the candidates
    /// were built from. `moved_out` (optional) receives max |d − d_ref|∞ (0 when the sizes
    /// differ).
    bool covers(const std::vector<Vec3>& d, double* moved_out = nullptr) const;

    const std::vector<VertexTrianglePair>& vertex_triangle() const { return m_vertex_triangle; }
    const std::vector<EdgeEdgePair>& edge_edge() const { return m_edge_edge; }

    /// The four vertices of candidate i of the list vertex_triangle() then edge_edge() (vertex
    /// and triangle corners, or the two edges' ends) and how many belong to the first element
    /// (1 or 2).
    std::array<int, 4> vertices(std::size_t i, std::size_t* split = nullptr) const;

    /// Do the pair's static boxes at t0, each padded by `padding`, overlap (by the minimum image
    /// on a periodic mesh)? `p0` receives the positions the test read (pair_positions() at t0).
    bool static_boxes_overlap(const std::array<int, 4>& v, std::size_t split, double padding,
                              std::array<Vec3, 4>& p0) const;

    /// The candidates with a vertex flagged in `changed` (all when it is empty) whose unpadded
    /// swept boxes for x0 → x1 overlap: with every vertex changed, exactly what
    /// BroadPhase(x0, x1, 0) returns, in the same (sorted) order.
    std::vector<VertexTrianglePair> moving_vertex_triangle(
        const std::vector<Vec3>& x1, const std::vector<std::uint8_t>& changed) const;
    std::vector<EdgeEdgePair> moving_edge_edge(const std::vector<Vec3>& x1,
                                               const std::vector<std::uint8_t>& changed) const;

private:
    void build_padded(const std::vector<Vec3>& d, double padding);
    /// Mean length of the live edges at t0 (computed once).
    double mean_edge_length();
    const Vec3& x0(int vi) const { return m_x0[static_cast<std::size_t>(vi)]; }
    Box3d static_box(std::initializer_list<int> vertices, double padding) const;
    Box3d moving_box(std::initializer_list<int> vertices, const std::vector<Vec3>& x1) const;
    bool swept_boxes_overlap(const std::array<int, 4>& v, std::size_t split,
                             const std::vector<Vec3>& x1) const;

    const SurfaceMesh& m_mesh;
    const std::vector<Vec3>& m_x0;
    double m_epsilon;
    std::vector<VertexTrianglePair> m_vertex_triangle;
    std::vector<EdgeEdgePair> m_edge_edge;
    std::vector<Vec3> m_d_ref;  ///< the displacements they were built for (empty: none yet)
    double m_padding = 0.0;
    double m_mean_edge_length = -1.0;  ///< < 0: not computed yet
};

/// Does any of v's vertices have its flag set in `changed` (true when `changed` is empty)?
inline bool any_changed(const std::vector<std::uint8_t>& changed, const std::array<int, 4>& v) {
    return changed.empty() || changed[static_cast<std::size_t>(v[0])] ||
           changed[static_cast<std::size_t>(v[1])] || changed[static_cast<std::size_t>(v[2])] ||
           changed[static_cast<std::size_t>(v[3])];
}

}  // namespace meniscus::tracker
