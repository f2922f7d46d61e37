#pragma once
/// \file Proximity queries (paper §3.4): closest points between a point and a triangle and
/// between two segments, with the paper's scaled barycentric weights and a collision normal.
///
/// Weights convention (§3.4): for the four vertices of a query, ā has the element's own
/// barycentric coordinates, negated for the triangle (point–triangle) or for the second edge
/// (edge–edge). Hence Σ āᵢ = 0 and Σ āᵢ xᵢ is the vector from the closest point on the triangle
/// (second edge) to the point (closest point on the first edge); its length is the distance.
/// The collision normal n points the same way: an impulse along +n applied with the weights ā
/// (§3.8: uᵢ += J āᵢ n / mᵢ) moves the elements apart.
///
/// Distances are computed in floating point (not exact); all thresholds are relative to the
/// query's own length scale. Degenerate inputs (zero-length edges, zero-area triangles,
/// coincident points) are valid and give well-defined results.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>

namespace meniscus::tracker {

/// Closest points between a point p and the closed triangle (a, b, c).
struct PointTriangleProximity {
    /// |p - q| >= 0 where q is the closest point of the triangle (length units of the input).
    double distance = 0.0;
    /// (α, β, γ): q = α a + β b + γ c, each in [0, 1], summing to 1.
    std::array<double, 3> barycentric{1.0, 0.0, 0.0};
    /// ā for (p, a, b, c) = (1, -α, -β, -γ): Σ āᵢ xᵢ = p - q.
    std::array<double, 4> weights{1.0, -1.0, 0.0, 0.0};
    /// Unit collision normal pointing from the triangle towards p (see point_triangle_proximity).
    Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
};

/// Closest points between the closed segments [ea0, ea1] and [eb0, eb1].
struct EdgeEdgeProximity {
    /// |xa - xb| >= 0 between the closest points xa on edge a and xb on edge b.
    double distance = 0.0;
    /// xa = ea0 + s (ea1 - ea0), s in [0, 1].
    double s = 0.0;
    /// xb = eb0 + u (eb1 - eb0), u in [0, 1].
    double u = 0.0;
    /// ā for (ea0, ea1, eb0, eb1) = (1 - s, s, -(1 - u), -u): Σ āᵢ xᵢ = xa - xb.
    std::array<double, 4> weights{1.0, 0.0, -1.0, 0.0};
    /// Unit collision normal pointing from edge b towards edge a (see edge_edge_proximity).
    Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
};

/// Closest point of the closed triangle (a, b, c) to p.
///
/// Normal: (p - q)/|p - q| when the distance is resolvable, i.e. larger than a small fraction
/// (1e-10) of the query's length scale (largest distance from a to the other points). Otherwise
/// (p touches the triangle) the triangle normal (b - a) × (c - a), normalized, oriented so that
/// it has a non-negative component along p - q, or when that is zero along `fallback_direction`.
/// For a degenerate (zero-area, up to a relative 1e-10 sine) triangle: (p - q)/|p - q| when
/// p - q != 0; when p lies exactly on it, `fallback_direction` made orthogonal to the
/// triangle's longest edge, else any unit vector orthogonal to that edge; if every point
/// coincides: `fallback_direction` normalized, else +x. Never throws; non-finite inputs give
/// non-finite results.
PointTriangleProximity point_triangle_proximity(
    const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
    const Eigen::Vector3d& c, const Eigen::Vector3d& fallback_direction = Eigen::Vector3d::Zero());

/// Closest points of the closed segments [ea0, ea1] and [eb0, eb1].
///
/// For parallel segments the closest pair is not unique; the one at the middle of the overlap
/// of their projections is returned (or the nearest endpoints when they do not overlap).
/// Normal: (xa - xb)/|xa - xb| when the distance is resolvable (above 1e-10 of the query's
/// length scale); otherwise the normalized cross product of the edge directions, oriented to
/// have a non-negative component along xa - xb, else along `fallback_direction`; for parallel
/// edges (relative sine below 1e-10): (xa - xb)/|xa - xb| when nonzero, else
/// `fallback_direction` made orthogonal to the longer edge, else any unit vector orthogonal
/// to it; if all points coincide: `fallback_direction` normalized,
/// else +x. Zero-length edges are points. Never throws.
EdgeEdgeProximity edge_edge_proximity(
    const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1, const Eigen::Vector3d& eb0,
    const Eigen::Vector3d& eb1,
    const Eigen::Vector3d& fallback_direction = Eigen::Vector3d::Zero());

}  // namespace meniscus::tracker
