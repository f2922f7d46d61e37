#pragma once
/// \file Continuous collision detection (paper §3.4) for linear vertex trajectories over the
/// normalized step t in [0, 1]: x(t) = x_t0 + t (x_t1 - x_t0).
///
/// Guarantee: never a false negative. If the primitives touch (distance exactly zero) at some
/// t in [0, 1] — including at t = 0 or t = 1, while coplanar for the whole step, for parallel
/// edges, or several times in one step — the answer is `true`. False positives are possible
/// when the primitives come within a tiny fraction (CcdOptions::tolerance_fraction) of the
/// query's length scale, or when the subdivision budget is exhausted.
///
/// Method: inclusion-based bisection in the parameter box (t, u, v) in the spirit of Tight
/// Inclusion (Wang et al. 2021). The gap function F(t, u, v) between the two moving points of
/// contact is multilinear on every box, so its range on a box lies in the convex hull of its 8
/// corner values; corners are evaluated in floating point with a certified per-axis rounding
/// error bound, and a box is discarded only when some coordinate of F provably keeps one strict
/// sign on it. The triangle is parametrized with a collapsed square (Duffy map)
/// q = a + u (b - a) + v (1 - u) (c - a), (u, v) in [0, 1]^2, which covers exactly the triangle.
/// Vertices are put in a canonical order first, so the result does not depend on the order of
/// the triangle's vertices, of an edge's endpoints, or of the two edges.
///
/// Before the search, the step is cleared where a plane separates the two primitives' convex
/// hulls: first over the whole step, then on dyadic time intervals (down to 1/64) along the
/// closest-point direction at their ends. This settles the near misses the box search can only
/// settle with a huge number of boxes (a point passing along a sliver triangle, nearly parallel
/// edges a tiny distance apart for the whole step); the search then covers only the time range
/// left uncleared.

#include <Eigen/Core>

#include <array>

namespace meniscus::tracker {

/// Tuning of the inclusion-based CCD. Defaults are written here and nowhere else.
struct CcdOptions {
    /// Contact tolerance as a fraction of the query's length scale (the largest coordinate
    /// magnitude of the relative position vectors over the step). A box whose image is at most
    /// this wide on every axis (and cannot be discarded) is reported as a possible contact.
    double tolerance_fraction = 1e-9;
    /// Maximum number of parameter boxes evaluated per query; reaching it reports a possible
    /// contact (conservative).
    int max_boxes = 20000;
    /// Detailed queries only: boxes that may still be evaluated after the first possible
    /// contact is found, to tighten toi_lower (the earliest start among unresolved boxes is
    /// returned when they run out, which is still a lower bound).
    int max_refinement_boxes = 4096;
    /// Throws std::invalid_argument naming the field when a value is out of range
    /// (tolerance_fraction must be finite and in [0, 1), max_boxes >= 1,
    /// max_refinement_boxes >= 0).
    void validate() const;
};

/// Outcome of a detailed CCD query, with what §3.8 collision impulses need.
struct CcdResult {
    /// False only when the primitives provably never touch during the step.
    bool may_collide = false;
    /// True when `may_collide` was forced by the box budget or the parameter precision limit
    /// rather than by a box that shrank to the contact tolerance.
    bool inconclusive = false;
    /// Number of parameter boxes evaluated.
    int boxes_checked = 0;
    /// Conservative lower bound of the earliest contact time in [0, 1] (no contact happens
    /// before it). 1 when !may_collide.
    double toi_lower = 1.0;
    /// The fields below are filled only when may_collide, from the proximity query at the
    /// positions of time toi_lower (see distance.h for the conventions).
    /// Distance between the primitives at toi_lower.
    double distance_at_toi = 0.0;
    /// ā: point–triangle (p, a, b, c) = (1, -α, -β, -γ); edge–edge (ea0, ea1, eb0, eb1) =
    /// (1 - s, s, -(1 - u), -u). Σ āᵢ = 0; these are the contact's barycentric parameters.
    std::array<double, 4> weights{0.0, 0.0, 0.0, 0.0};
    /// Unit collision normal from the triangle (edge b) towards the point (edge a). When the
    /// primitives already touch at toi_lower it is oriented by their separation at t = 0, or
    /// against their relative displacement when they also touch at t = 0.
    Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
    /// n · Σ āᵢ (xᵢ_t1 - xᵢ_t0): relative displacement over the step along the normal
    /// (negative when approaching). The §3.8 impulse uses δ = -relative_normal_displacement/Δt.
    double relative_normal_displacement = 0.0;
};

/// True when point p may touch triangle (a, b, c) at some t in [0, 1]. Never a false negative.
/// Throws std::invalid_argument on non-finite input.
bool point_triangle_ccd(const Eigen::Vector3d& p_t0, const Eigen::Vector3d& a_t0,
                        const Eigen::Vector3d& b_t0, const Eigen::Vector3d& c_t0,
                        const Eigen::Vector3d& p_t1, const Eigen::Vector3d& a_t1,
                        const Eigen::Vector3d& b_t1, const Eigen::Vector3d& c_t1);

/// True when segment [ea0, ea1] may touch segment [eb0, eb1] at some t in [0, 1]. Never a
/// false negative. Throws std::invalid_argument on non-finite input.
bool edge_edge_ccd(const Eigen::Vector3d& ea0_t0, const Eigen::Vector3d& ea1_t0,
                   const Eigen::Vector3d& eb0_t0, const Eigen::Vector3d& eb1_t0,
                   const Eigen::Vector3d& ea0_t1, const Eigen::Vector3d& ea1_t1,
                   const Eigen::Vector3d& eb0_t1, const Eigen::Vector3d& eb1_t1);

/// point_triangle_ccd with options and the data for a collision response. `may_collide` is
/// the same answer point_triangle_ccd gives with default options. Throws std::invalid_argument
/// on non-finite input or invalid options.
CcdResult point_triangle_ccd_detailed(const Eigen::Vector3d& p_t0, const Eigen::Vector3d& a_t0,
                                      const Eigen::Vector3d& b_t0, const Eigen::Vector3d& c_t0,
                                      const Eigen::Vector3d& p_t1, const Eigen::Vector3d& a_t1,
                                      const Eigen::Vector3d& b_t1, const Eigen::Vector3d& c_t1,
                                      const CcdOptions& options = {});

/// edge_edge_ccd with options and the data for a collision response. `may_collide` is the same
/// answer edge_edge_ccd gives with default options. Throws std::invalid_argument on non-finite
/// input or invalid options.
CcdResult edge_edge_ccd_detailed(const Eigen::Vector3d& ea0_t0, const Eigen::Vector3d& ea1_t0,
                                 const Eigen::Vector3d& eb0_t0, const Eigen::Vector3d& eb1_t0,
                                 const Eigen::Vector3d& ea0_t1, const Eigen::Vector3d& ea1_t1,
                                 const Eigen::Vector3d& eb0_t1, const Eigen::Vector3d& eb1_t1,
                                 const CcdOptions& options = {});

}  // namespace meniscus::tracker
