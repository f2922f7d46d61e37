#pragma once
/// \file Exact solutions and error measures for the geometric flows (docs/validation.md part A).
///
/// Error of a mesh against an exact surface given by its signed distance φ (negative inside):
///
///     L∞ = max |φ(x)| over the live vertices and sample points on every live triangle,
///     L1 = (1 / A) Σ_T ∫_T |φ| dA   (A = total live area),
///
/// i.e. L1 is the area-weighted mean distance of the mesh from the exact surface. The paper
/// (§4.1, Table 4.1) does not define its norms; this is the standard surface-to-surface choice.
/// Sample points: each triangle is cut into m² congruent sub-triangles (m =
/// `triangle_subdivisions`); ∫_T |φ| is the midpoint rule over their centroids, and L∞ also
/// takes the lattice points (corners of the sub-triangles). Vertex-only measures are reported
/// separately, since vertices sit on the surface while chords cut inside it by about ℓ²/(8R):
///
///     vertex L∞ = max over live vertices of |φ(xᵥ)|,
///     vertex L1 = Σᵥ Aᵥ |φ(xᵥ)| / Σᵥ Aᵥ,  Aᵥ = one third of the areas of v's live triangles.
///
/// and the same vertex samples signed (φ > 0 outside): max φ, min φ and Σᵥ Aᵥ φ(xᵥ) / Σᵥ Aᵥ.
/// The paper's released code (El Topo, talpa/drivers/meancurvature.cpp) reports its Table 4.3
/// "L∞" and "L1" as these signed max and mean, so inside and outside errors cancel in its L1
/// and vertices inside the reference do not count in its L∞.
///
/// The sampled measures include the polygonal mesh's own chord error (about ℓ²/(12R) on
/// average for a sphere mesh with vertices on the sphere); the vertex measures do not.

#include "tracker/mesh.h"

#include <functional>

namespace meniscus::tracker {

/// Options of surface_error().
struct SurfaceErrorOptions {
    int triangle_subdivisions = 4;  ///< m ≥ 1: m² midpoint samples per triangle
    void validate() const;          ///< throws std::invalid_argument naming the field
};

/// Distances of a mesh from an exact surface (metres).
struct SurfaceError {
    double linf = 0.0;         ///< max |φ| over vertices and triangle samples
    double l1 = 0.0;           ///< area-weighted mean |φ|
    double vertex_linf = 0.0;  ///< max |φ| over live vertices only
    double vertex_l1 = 0.0;    ///< mean |φ| over vertices weighted by barycentric vertex areas
    double vertex_max_signed = 0.0;   ///< max φ over live vertices (signed; > 0 outside)
    double vertex_min_signed = 0.0;   ///< min φ over live vertices (signed; < 0 inside)
    double vertex_mean_signed = 0.0;  ///< Σᵥ Aᵥ φ(xᵥ) / Σᵥ Aᵥ (signed)
    Vec3 vertex_linf_position = Vec3::Zero();  ///< where vertex_linf is attained
    double area = 0.0;         ///< total live triangle area (m²)
    long samples = 0;          ///< number of φ evaluations
};

/// Error of `mesh` against the surface φ = 0 of `signed_distance` (see the file comment).
/// A mesh without live triangles gives area 0, l1 0 and the vertex maximum.
/// Throws std::invalid_argument on invalid options.
SurfaceError surface_error(const SurfaceMesh& mesh,
                           const std::function<double(const Vec3&)>& signed_distance,
                           const SurfaceErrorOptions& options = {});

/// Exact signed distance (negative inside) to the boundary of the union of the balls of equal
/// `radius` (> 0) around c0 and c1. Outside: min over the balls of |x − cᵢ| − r. Inside: minus
/// the distance to the nearer of the two boundary patches (the part of each sphere outside the
/// other ball), where the distance to a patch is | |x − cᵢ| − r | if x's radial projection onto
/// sphere i lies on the patch, else the distance to the ring where the spheres meet.
double two_ball_union_signed_distance(const Vec3& x, const Vec3& c0, const Vec3& c1, double radius);

/// docs/validation.md A1 (paper §4.1): two spheres moving in the normal direction with speed +s
/// until `reversal_time` T, then −s. The exact (entropy) solution: for t ≤ T the union U(t) of
/// the two balls of radius r₀ + s t; for t ≥ T the erosion {x : dist(x, complement of U(T)) >
/// s (t − T)} — the neck formed by the merge stays merged. Its signed distance is
/// φ_U(T)(x) + s (t − T): exact because U(T) is a union of balls of radius r₀ + sT ≥ s (t − T),
/// so each point of U(T) lies in a ball of radius s (t − T) inside U(T) (erosion then dilation
/// gives U(T) back).
struct TwoSphereNormalFlow {
    Vec3 center0{-0.25, 0.0, 0.0};  ///< m
    Vec3 center1{0.25, 0.0, 0.0};   ///< m
    double initial_radius = 0.2;    ///< r₀ (m, > 0)
    double speed = 0.2;             ///< s (m/s, > 0): outward before T, inward after
    double reversal_time = 1.0;     ///< T (s, ≥ 0)
    void validate() const;          ///< throws std::invalid_argument naming the field

    /// Normal speed at time t (m/s): +speed for t < T, −speed for t ≥ T (docs/validation.md A1).
    double normal_speed(double t) const;
    /// Signed distance (m, negative inside) to the exact surface at time t ≥ 0, valid until the
    /// eroded set vanishes (t ≤ T + (r₀ + sT)/s). Throws std::invalid_argument outside that.
    double signed_distance(const Vec3& x, double t) const;
};

/// Error of `mesh` against the exact A1 surface at time t (see TwoSphereNormalFlow).
SurfaceError two_sphere_normal_flow_error(const SurfaceMesh& mesh, const TwoSphereNormalFlow& flow,
                                          double t, const SurfaceErrorOptions& options = {});

/// Radius of a sphere under mean-curvature flow with κ = sum of principal curvatures:
/// R(t) = sqrt(R₀² − 4t) (m). Throws std::invalid_argument unless R₀ > 0 and
/// 0 ≤ t ≤ R₀²/4 (the extinction time).
double sphere_mean_curvature_radius(double initial_radius, double t);

/// Error of `mesh` against the sphere of `radius` (> 0) around `center`: φ = |x − c| − R.
SurfaceError sphere_error(const SurfaceMesh& mesh, const Vec3& center, double radius,
                          const SurfaceErrorOptions& options = {});

/// Sampled Hausdorff distance between two meshes (metres). Each one-sided part samples one
/// mesh as surface_error() does (vertices, lattice points and sub-triangle centroids) and
/// measures the unsigned distance of every sample to the nearest live triangle of the other
/// mesh (MeshDistance, exact point–triangle distances): its `linf` is the one-sided Hausdorff
/// distance over the samples (a lower bound on the continuous one, closer to it than the
/// sample spacing, edge / triangle_subdivisions), its `l1` the area-weighted mean distance.
/// The signed vertex fields of SurfaceError are unsigned here.
struct HausdorffDistance {
    SurfaceError a_to_b;     ///< distances of samples of `a` from `b`
    SurfaceError b_to_a;     ///< distances of samples of `b` from `a`
    double symmetric = 0.0;  ///< max(a_to_b.linf, b_to_a.linf)
};

/// Hausdorff distance between the live triangles of `a` and `b` (see HausdorffDistance).
/// Throws std::invalid_argument if either has no live triangle or on invalid options.
HausdorffDistance hausdorff_distance(const SurfaceMesh& a, const SurfaceMesh& b,
                                     const SurfaceErrorOptions& options = {});

/// Relative volume change (V − V₀) / V₀ (dimensionless; ×100 for the paper's percentages).
/// Throws std::invalid_argument if V₀ is zero or not finite.
double relative_volume_change(double initial_volume, double volume);

/// relative_volume_change() of the mesh's enclosed volume (mesh_measures.h) against V₀.
double relative_volume_change(const SurfaceMesh& mesh, double initial_volume);

}  // namespace meniscus::tracker
