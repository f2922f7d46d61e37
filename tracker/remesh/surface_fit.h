#pragma once
/// \file Local quadratic (cubic, quartic) height-field fit of a smooth mesh patch, for placing
/// vertices on the smooth surface the mesh samples rather than on its chords, and for its
/// curvature.
///
/// Over a tangent frame (o; u, v, n) the patch's vertices are fitted in the least-squares sense
/// by h(s, t) = c₀ + c₁s + c₂t + c₃s² + c₄st + c₅t² (+ c₆s³ + c₇s²t + c₈st² + c₉t³ for
/// degree 3, + c₁₀s⁴ + c₁₁s³t + c₁₂s²t² + c₁₃st³ + c₁₄t⁴ for degree 4),
/// (s, t) = ((x − o)·u, (x − o)·v), and a point x is placed at o + s u + t v + h(s, t) n. The vertices sample the smooth surface to within
/// the remesher's own error, so a fitted point is off by O(ℓ³) for edge length ℓ, where an edge
/// midpoint sits ℓ²κ/8 inside a surface of normal curvature κ (1.5e-3 for a 0.06 edge on a
/// sphere of radius 0.3) and a butterfly point, whose weights assume valence-6 neighbours, was
/// measured 5e-4 inside on average on A1's growing spheres (irregular stencils next to fresh
/// splits).
///
/// The fit is refused where the patch is not a graph over the frame (a triangle normal more
/// than `max_normal_angle_degrees` from n), is too small or degenerate (no more vertices than
/// the quadratic has unknowns, or a rank-deficient design matrix), does not fit (a residual
/// above `max_residual_fraction` of the patch size), or where the fitted point moves further
/// than `max_offset_fraction` of the patch's size from the point it replaces: features
/// (creases, corners) are left to the callers' sharp rules.
///
/// Periodic meshes (issue 39): a patch is read at the minimum image of its origin (the vertex,
/// or the edge's first vertex), and the points returned for an edge or a vertex are near that
/// vertex, not wrapped: callers wrap a point before storing it as a vertex position.

#include "tracker/mesh.h"
#include "tracker/quadric.h"

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace meniscus::tracker {

/// Options of fit_surface_patch().
struct SurfaceFitOptions {
    /// Largest angle (degrees, in (0, 90)) between a patch triangle's normal and the frame
    /// normal n for the patch to count as a height field.
    double max_normal_angle_degrees = 45.0;
    /// A placed point may move at most this fraction of the patch radius (largest |(s, t)| of
    /// the fitted vertices) away from the point it replaces, in (0, 1].
    double max_offset_fraction = 0.25;
    /// The fit is refused where a fitted vertex is further than this fraction of the patch
    /// radius from the fitted surface, in (0, 1]: a crease or an under-resolved fillet (a
    /// rarefaction fan right after a concave crease starts moving inward) is no quadratic, while
    /// a sphere patch of radius ρ and curvature κ misses one by about ρ³κ³/8 (1e-5 of ρ at
    /// ρκ = 0.4).
    double max_residual_fraction = 1e-2;
    /// Degree of the height field, 2 or 3. A quadratic fitted to a surface whose curvature
    /// varies takes the cubic part into its slope: over a stencil of radius ρ the slope at the
    /// centre is off by a stencil-dependent fraction of ρ²·h‴ (about a tenth on a regular
    /// two-ring), along the direction the curvature grows in, even for a symmetric stencil. A point
    /// moved by d along the fit then leaves the surface by that slope error times d, an error first
    /// order in d that does not average out when vertices keep drifting the same way (the A2
    /// dumbbell at ξ = 0.02 drifted 2.2e-4 outward with fitted smoothing). The cubic moves that
    /// error to the quartic part. A degree is fitted only where more vertices than its unknowns
    /// constrain it (an interpolant has no residual to refuse a crease by, and swings with every
    /// vertex): the cubic needs 11 vertices (10 besides the origin when through_origin); a
    /// patch with fewer, or a rank-deficient cubic design, falls back to the quadratic (7, or 6
    /// besides the origin). The quartic (16, or 15 besides the origin; else the cubic) also
    /// fits the quartic part of the surface, which quadratic and cubic fits take into their
    /// second derivatives: their curvature at the centre of a two-ring is off by a fraction of
    /// order (ρκ)² (+2.6 % to +4.4 % on a spheroid of semi-axes 0.12, 0.076 at edge length
    /// 0.0125, every sign the same), the quartic's by at most 6.6e-3 there and 6.3e-4 at half
    /// the edge length (SurfacePatch::mean_curvature()).
    int degree = 2;
    /// Fix c₀ = 0: the fitted surface passes through the frame origin. For a patch around a
    /// vertex known to lie on the surface, whose curvature is wanted (mean-curvature flow):
    /// one unknown fewer, and on a spheroid of semi-axes 0.12, 0.076 at edge length 0.0125 the
    /// quartic's largest relative κ error falls from 6.6e-3 to 3.4e-3 (6.3e-4 to 3.4e-4 at
    /// half the edge length).
    bool through_origin = false;
    /// Fit twice: the second time the surface h = p(s, t) + c·h² with c = −κ/4 from the first
    /// fit's κ, the polynomial p to the heights' h − c·h² (same frame, same vertices).
    /// A sphere of curvature κ (sum of the principal curvatures, the frame normal pointing out)
    /// is exactly h = −(s² + t²)/(2R) − h²/(2R), i.e. c = −κ/4 with a quadratic p, so the refit
    /// takes out the truncation error of the sphere's terms above the fitted degree, which
    /// makes a quartic's κ one-signed: too small, by a fraction of order (ρκ)⁴ over a patch of
    /// radius ρ. Largest relative κ error of a quartic through the vertex over its two-ring,
    /// single fit → refit: sphere R = 0.1 at edge length 0.04 4.8e-2 → 2.3e-3, at 0.02
    /// 2.7e-3 → 7.3e-6; spheroid (0.12, 0.076) at 0.0128 3.7e-3 → 1.3e-3, at 0.0064 3.8e-4 →
    /// 1.3e-4. A free c would be one more unknown, nearly collinear with the quartic terms
    /// (h² is quartic to leading order), whose noise we measured at ±1–5 % of κ.
    bool sphere_refit = false;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// A fitted height field over a tangent frame.
struct SurfacePatch {
    Vec3 origin = Vec3::Zero();
    Vec3 u = Vec3::UnitX(), v = Vec3::UnitY(), normal = Vec3::UnitZ();  ///< orthonormal frame
    double radius = 0.0;  ///< largest |(s, t)| of the fitted vertices (m)
    int degree = 2;       ///< degree actually fitted (≤ SurfaceFitOptions::degree)
    /// c₀ … c₁₄ of the file comment; the terms above `degree` are 0.
    Eigen::Matrix<double, 15, 1> coefficients = Eigen::Matrix<double, 15, 1>::Zero();
    /// c of SurfaceFitOptions::sphere_refit (0 without): the surface is h = p + c·h², p the
    /// polynomial of `coefficients`.
    double height_squared = 0.0;
    /// The point of the fitted surface above (or below) x along the frame normal.
    Vec3 point_above(const Vec3& x) const;
    /// Mean curvature (sum of the principal curvatures, 1/m) of the fitted surface at its point
    /// above the origin: positive where it bends away from `normal` (a sphere with the normal
    /// pointing out: 2/R).
    double mean_curvature() const;
    /// Unit normal of the fitted surface at its point above the origin (on `normal`'s side).
    Vec3 surface_normal() const;
    /// radius times the largest |normal curvature| of the fitted surface at the origin (the
    /// eigenvalues of the Hessian of h there): about the angle, in radians, the surface turns
    /// over the patch. Near 0 on a well-resolved patch; a two-ring across a pinched tip or a
    /// thin neck turns by 1 or more.
    double turn() const;
};

/// Fits `vertices` (live vertex ids; duplicates are ignored) over the frame with origin `origin`
/// and normal `normal` (any length > 0), checking the graph condition on `triangles` (live
/// triangle ids: those whose surface the fit replaces). Returns nullopt where the fit is refused
/// (see the file comment). Throws std::invalid_argument on invalid options or a zero normal.
std::optional<SurfacePatch> fit_surface_patch(const SurfaceMesh& mesh,
                                              const std::vector<int>& vertices,
                                              const std::vector<int>& triangles, const Vec3& origin,
                                              const Vec3& normal,
                                              const SurfaceFitOptions& options = {});

/// Point on the smooth surface above the midpoint of live edge `ei`: the fit over the vertices
/// of both endpoints' one-rings, in the frame of the area-weighted normal of their triangles,
/// shifted along the normal by minus the mean of its residuals at the two endpoints.
/// nullopt where the fit is refused, the edge is a boundary or non-manifold edge, or the
/// placed point is further from the midpoint than max_offset_fraction of the patch radius.
std::optional<Vec3> fitted_edge_point(const SurfaceMesh& mesh, int ei,
                                      const SurfaceFitOptions& options = {});

/// Normal of live vertex `vi` on the smooth surface the mesh approximates: the area-weighted mean
/// normal of its majority cluster of triangles (normals within `cluster_angle_degrees` of one of
/// them) when that cluster holds at least `cluster_weight_fraction` of the area, else of all its
/// triangles. A vertex beside a crease or a fillet the mesh does not resolve (one or two chord
/// triangles bent across it) then keeps the normal of its own side, which its plain mean normal
/// tilts towards the chord; a vertex on the crease (two balanced clusters) gets the mean.
/// nullopt when its triangles' area vectors cancel.
std::optional<Vec3> majority_normal(const SurfaceMesh& mesh, int vi,
                                    double cluster_angle_degrees = 20.0,
                                    double cluster_weight_fraction = 0.6);

/// Midpoint of the circular arc between the ends of edge `ei` that meets each end's tangent
/// plane (normal to its majority_normal()) at the same angle: midpoint + (ℓ/2) tan(θ/4)
/// along −(w₀n₀ + w₁n₁) made orthogonal to the chord, with w₀ = (x₁ − x₀)·n₀, w₁ = (x₀ − x₁)·n₁
/// and sin(θ/2) = (|w₀| + |w₁|)/(2ℓ). Exact on spheres and circular fillets, where a quadratic
/// fit is refused (a rarefaction fan a few edges wide); for small θ it is the PN-triangle edge
/// midpoint, midpoint − (w₀n₀ + w₁n₁)/8. nullopt for boundary and non-manifold edges, normals
/// more than 120° apart, or θ/2 above 60°.
std::optional<Vec3> arc_edge_point(const SurfaceMesh& mesh, int ei);

/// Which rule placed a surface_edge_point().
enum class EdgePointRule {
    fitted,  ///< fitted_edge_point()
    arc,     ///< arc_edge_point()
};

/// A point on the smooth surface near the middle of an edge, and the rule that placed it.
struct SurfaceEdgePoint {
    Vec3 point = Vec3::Zero();
    EdgePointRule rule = EdgePointRule::fitted;
};

/// Where a vertex replacing live edge `ei` (a split's new vertex, a collapse's merged one) goes
/// on the smooth surface: fitted_edge_point() where both endpoints are smooth (quadric rank 1
/// under `thresholds`) and the fit is accepted, else arc_edge_point(). nullopt where neither
/// applies (callers fall back to the butterfly point).
std::optional<SurfaceEdgePoint> surface_edge_point(const SurfaceMesh& mesh, int ei,
                                                   const FeatureThresholds& thresholds,
                                                   const SurfaceFitOptions& options = {});

/// Where live vertex `vi` moved to `target` lands on the smooth surface fitted over its two-ring
/// (the vertex's own current position included), in the frame of its area-weighted normal,
/// shifted along the normal to pass through the vertex's current position (so a vertex that
/// does not move stays put, and the fit's own bias is not added on every call).
/// nullopt where the fit is refused, the vertex is on the open boundary, or the projection moves
/// `target` further than max_offset_fraction of the patch radius.
std::optional<Vec3> fitted_vertex_point(const SurfaceMesh& mesh, int vi, const Vec3& target,
                                        const SurfaceFitOptions& options = {});

/// The fit fitted_vertex_point() places points on: over live vertex `vi`'s two-ring, in the
/// frame of its area-weighted normal with the origin at the vertex. nullopt where it does.
std::optional<SurfacePatch> vertex_patch(const SurfaceMesh& mesh, int vi,
                                         const SurfaceFitOptions& options = {});
/// The same with the vertices at `positions` (one per vertex slot) instead of the mesh's own:
/// a predictor step's positions on the same connectivity. Throws std::invalid_argument when
/// `positions` is not sized num_vertices().
std::optional<SurfacePatch> vertex_patch(const SurfaceMesh& mesh,
                                         const std::vector<Vec3>& positions, int vi,
                                         const SurfaceFitOptions& options = {});

/// fitted_vertex_point() on a patch from vertex_patch(): where a vertex at `x` moved to
/// `target` lands, nullopt where it moves further than max_offset_fraction of the patch radius.
std::optional<Vec3> place_on_vertex_patch(const SurfacePatch& patch, const Vec3& x,
                                          const Vec3& target,
                                          const SurfaceFitOptions& options = {});

}  // namespace meniscus::tracker
