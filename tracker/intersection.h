#pragma once
/// \file Exact static intersection tests (paper §3.4), built only on the exact predicates of
/// predicates.h: segment–triangle with contact classification, point-in-tetrahedron, and
/// triangle–triangle for mesh triangles that may share vertices. Every answer is exact for
/// all finite double inputs; degenerate inputs (zero-length segments, zero-area triangles,
/// flat tetrahedra) are valid. Non-finite inputs throw std::invalid_argument (from the
/// predicates).

#include <Eigen/Core>

#include <array>

namespace meniscus::tracker {

/// How a closed segment meets a closed triangle.
enum class SegmentTriangleContact {
    none,                  ///< no common point
    proper,                ///< the segment crosses the triangle's plane at an interior point of
                           ///< both (endpoints strictly on opposite sides)
    through_edge,          ///< crosses the plane (endpoints strictly on opposite sides) through
                           ///< the relative interior of a triangle edge
    through_vertex,        ///< crosses the plane (endpoints strictly on opposite sides) through
                           ///< a triangle vertex
    endpoint_on_triangle,  ///< exactly one endpoint lies in the plane, and on the closed triangle
    coplanar,              ///< segment and triangle are coplanar (always the case for a
                           ///< zero-area triangle) and share at least one point
};

/// Where on the triangle (a, b, c) the contact lies, for the non-coplanar contacts.
enum class TriangleFeature {
    none,
    interior,
    edge_ab,
    edge_bc,
    edge_ca,
    vertex_a,
    vertex_b,
    vertex_c
};

/// Result of segment_triangle_intersection.
struct SegmentTriangleIntersection {
    SegmentTriangleContact kind = SegmentTriangleContact::none;
    /// Triangle feature hit; `none` for kinds none and coplanar.
    TriangleFeature feature = TriangleFeature::none;
    /// 0 or 1 for endpoint_on_triangle (which endpoint), -1 otherwise.
    int segment_endpoint = -1;
    /// True for every kind but none.
    bool intersects() const { return kind != SegmentTriangleContact::none; }
};

/// Exact classification of closed segment [s0, s1] against closed triangle (a, b, c).
SegmentTriangleIntersection segment_triangle_intersection(const Eigen::Vector3d& s0,
                                                          const Eigen::Vector3d& s1,
                                                          const Eigen::Vector3d& a,
                                                          const Eigen::Vector3d& b,
                                                          const Eigen::Vector3d& c);

/// True when p lies in the closed tetrahedron (a, b, c, d) — interior or boundary — i.e. in the
/// convex hull of the four points (also when they are coplanar or collinear). Exact.
bool point_in_tetrahedron(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                          const Eigen::Vector3d& d);

/// True when p lies on the closed triangle (a, b, c) (any triangle, also zero-area). Exact.
bool point_in_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c);

/// True when closed segments [p0, p1] and [q0, q1] share a point (zero-length segments are
/// points). Exact.
bool segments_intersect(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                        const Eigen::Vector3d& q0, const Eigen::Vector3d& q1);

/// Exact intersection test for two mesh triangles, given their positions and vertex indices;
/// what the static whole-mesh intersection check calls per candidate pair. Shared vertices are
/// recognized by index, not by position. With T1, T2 the closed triangles and S the closed
/// shared face (the shared vertex or edge):
/// - no shared vertex: true iff T1 ∩ T2 ≠ ∅ (touching counts);
/// - one shared vertex s: true iff T1 ∩ T2 ≠ {s}: an edge opposite s crosses or touches the
///   other triangle, or an edge incident to s runs into the other triangle from s (coplanar
///   overlap at s); meeting at s only is not an intersection;
/// - a shared edge e: true iff T1 ∩ T2 ≠ e: the two triangles are coplanar with their third
///   vertices on the same side of e (folded flat onto each other); two non-degenerate triangles
///   on a common edge never intersect otherwise, because their planes meet only along e's line;
/// - three shared vertices (a duplicated triangle): false — that is a topological defect that
///   separation (§3.6) removes, not an intersection.
/// Degenerate (zero-area) triangles follow the same set definitions, with one conservative
/// exception: with one shared vertex s, a zero-area triangle whose opposite edge passes
/// through s is reported as intersecting when that edge touches the other triangle at s only.
bool triangles_intersect(const std::array<Eigen::Vector3d, 3>& t1,
                         const std::array<int, 3>& t1_vertices,
                         const std::array<Eigen::Vector3d, 3>& t2,
                         const std::array<int, 3>& t2_vertices);

}  // namespace meniscus::tracker
