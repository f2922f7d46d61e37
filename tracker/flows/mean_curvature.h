#pragma once
/// \file Motion by mean curvature (paper §4.2) with the discrete operators of Meyer, Desbrun,
/// Schröder and Barr 2003 ("Discrete differential-geometry operators for triangulated
/// 2-manifolds"): cotangent weights and mixed Voronoi areas.
///
/// Conventions (shared with coupling/ for surface tension):
/// - κ is the *sum* of the principal curvatures (2/R for a sphere of radius R), in 1/m;
/// - the curvature normal is K(xᵢ) = (1 / (2 A_mixed,i)) Σⱼ (cot αᵢⱼ + cot βᵢⱼ) (xᵢ − xⱼ)
///   = κ n, with n the outward normal (so K points out of a sphere and |K| = 2/R);
/// - mean-curvature flow moves the surface with velocity −K = −κ n (a sphere shrinks with
///   R(t) = sqrt(R₀² − 4t));
/// - the signed scalar κᵢ = K(xᵢ) · nᵢ with nᵢ the area-weighted vertex normal: κ > 0 on a
///   convex closed surface with outward normals.
///
/// Boundary vertices of open surfaces (§4.4) have no closed one-ring: their K and κ are zero
/// (they are held fixed by the flow). Non-manifold edges contribute the cotangents of every
/// incident triangle.

#include "tracker/mesh.h"

#include <vector>

namespace meniscus::tracker {

/// Mixed Voronoi area of each vertex (Meyer et al. 2003, Fig. 4): per incident triangle, the
/// Voronoi region area (1/8)(|pr|² cot q + |pq|² cot r) if the triangle is not obtuse, else
/// area/2 at the obtuse corner and area/4 at the two others. Units m²; zero for dead vertices.
/// The areas of all vertices sum to the mesh area.
std::vector<double> mixed_voronoi_areas(const SurfaceMesh& mesh);

/// Curvature normal K = κ n at each vertex (1/m; see the file comment). Zero for dead,
/// isolated and boundary vertices.
std::vector<Vec3> mean_curvature_normals(const SurfaceMesh& mesh);

/// Signed mean curvature κ (sum of principal curvatures, 1/m) at each vertex: K · n with n the
/// area-weighted vertex normal. Zero for dead, isolated and boundary vertices.
std::vector<double> mean_curvatures(const SurfaceMesh& mesh);

/// Time integration of mean-curvature flow.
enum class MeanCurvatureIntegrator {
    /// xᵢ ← xᵢ − dt K(x) (the paper's §4.2).
    forward_euler,
    /// Heun's method (explicit trapezoidal rule, second order): x* = x − dt K(x), then
    /// xᵢ ← xᵢ − (dt/2)(K(x) + K(x*)) on the same connectivity. Same stability bound as
    /// forward Euler on the cotangent Laplacian's real spectrum (|1 + z + z²/2| ≤ 1 for
    /// z ∈ [−2, 0]) for two curvature evaluations per step. Forward Euler's O(dt κ²) lag
    /// accumulates where curvature is high: at the CFL step (dt ∝ ℓ²) it is as large as the
    /// operator's O(ℓ² κ²) error, worst on small shrinking blobs and necks.
    heun,
};

/// The discrete mean-curvature normal the flow moves vertices by.
enum class CurvatureOperator {
    /// Meyer et al.'s cotangent formula K (the paper's §4.2). Its integral is exact on a
    /// sphere (the area-weighted mean of κ is 2/R to rounding), but its pointwise error does
    /// not shrink with the edge length on irregular meshes and carries an O(ℓ²κ²) bias that
    /// follows the shape: on a spheroid of semi-axes 0.12, 0.076 meshed at ℓ = 0.0125, κ is
    /// 2.3e-3 too small at the poles and 1e-3 too large at the waist (6e-4 and 4e-4 at half ℓ),
    /// so an elongated drop rounds off too slowly.
    cotangent,
    /// κ n of a quartic height field fitted through the vertex over its two-ring and refitted
    /// as h = p + c·h² with c = −κ/4 (SurfaceFitOptions::sphere_refit;
    /// fitted_mean_curvature_normals()), where that fit is accepted, else the cotangent K:
    /// pointwise convergent at about fourth order on smooth patches (the same spheroid with its
    /// vertices on it: largest relative κ error 1.3e-3 at ℓ = 0.0128 and 1.2e-4 at 0.0064,
    /// where the cotangent K's is 9.6 % and 7.5 %). The tangential motion of the cotangent
    /// formula is dropped where the fit is used: the flow is normal, and remeshing keeps the
    /// mesh. Without the refit the quartic's error is one-signed (κ too small, a fraction of
    /// order (ρκ)⁴ for a two-ring of radius ρ: 3.4e-3 and 3.4e-4 on that spheroid), and on
    /// the A2 dumbbell at ξ = 0.04, whose final drops are barely wider than a two-ring, every
    /// drop lagged (vertex L1 2.8e-4, above the paper's 2.6e-4; with the refit 5.0e-5).
    quartic_fit,
};

/// Options of mean-curvature flow.
struct MeanCurvatureFlowOptions {
    /// Step limit Δt ≤ cfl_number · (shortest live edge)². The explicit cotangent Laplacian on
    /// an equilateral mesh is stable up to ℓ²/3; 0.1 leaves room for irregular triangles.
    /// In (0, 1].
    double cfl_number = 0.1;
    MeanCurvatureIntegrator integrator = MeanCurvatureIntegrator::forward_euler;
    CurvatureOperator curvature_operator = CurvatureOperator::cotangent;
    /// quartic_fit: the fit is used only where it turns by at most this much over its two-ring
    /// (SurfacePatch::turn(), radians, > 0): a thin neck or a just-pinched tip a few edges
    /// around is no height field, and the cotangent K takes over there.
    double fit_max_turn = 1.0;
    /// quartic_fit: refit each quartic as h = p + c·h² with c = −κ/4 from the first fit
    /// (SurfaceFitOptions::sphere_refit), which removes its truncation error on spheres
    /// (one-signed, κ too small). false: the single fit.
    bool fit_sphere_refit = true;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Curvature normals K = κ n (1/m, the convention of the file comment) of the vertices at
/// `positions` (one per vertex slot; nullptr: the mesh's own) with a quartic height field
/// fitted through each vertex over its two-ring and, with `sphere_refit`, refitted with the
/// sphere's h² term (SurfaceFitOptions::degree 4, through_origin, sphere_refit;
/// vertex_patch()): κ is the fit's mean curvature and n its normal at the vertex. A two-ring
/// too small or degenerate for the quartic (it needs 15 vertices besides the centre, so a
/// valence-4 vertex, with 14, is not interpolated) gets the cubic through the vertex with the
/// same refit. Where neither is accepted, or the fit turns by more than `max_turn` (radians),
/// the cotangent K instead. Zero for dead, isolated and boundary vertices. `fallbacks`, when
/// given, receives the number of live vertices that took the cotangent K.
/// Throws std::invalid_argument on a wrongly sized `positions` or max_turn ≤ 0.
std::vector<Vec3> fitted_mean_curvature_normals(const SurfaceMesh& mesh, double max_turn,
                                                const std::vector<Vec3>* positions = nullptr,
                                                int* fallbacks = nullptr,
                                                bool sphere_refit = true);

/// The CFL-limited forward-Euler step cfl_number · ℓ_min² (s, with unit diffusion coefficient:
/// the flow speed is κ in m/s). Throws std::invalid_argument on invalid options or a mesh
/// without live edges.
double mean_curvature_time_step(const SurfaceMesh& mesh,
                                const MeanCurvatureFlowOptions& options = {});

/// Forward-Euler displacements −K(xᵢ)·dt (m) for a step `dt` (s). Zero for dead and boundary
/// vertices. Sized num_vertices().
std::vector<Vec3> mean_curvature_displacements(const SurfaceMesh& mesh, double dt);

/// Displacements for a step `dt` (s) with `integrator` (see MeanCurvatureIntegrator). Zero for
/// dead and boundary vertices. Sized num_vertices().
std::vector<Vec3> mean_curvature_displacements(const SurfaceMesh& mesh, double dt,
                                               MeanCurvatureIntegrator integrator);

/// Displacements for a step `dt` (s) with the integrator and curvature operator of `options`.
/// Zero for dead and boundary vertices. Sized num_vertices(). Throws std::invalid_argument on
/// invalid options.
std::vector<Vec3> mean_curvature_displacements(const SurfaceMesh& mesh, double dt,
                                               const MeanCurvatureFlowOptions& options);

}  // namespace meniscus::tracker
