#pragma once
/// \file Motion in the normal direction by face offsetting (Jiao 2007; paper §4.1).
///
/// Each triangle plane moves along its unit normal by hᵢ = speedᵢ·Δt. Each vertex then takes
/// the displacement d that best fits its incident offset planes, nᵢ·d = hᵢ, in the weighted
/// least-squares sense, using the eigen-decomposition of
///
///     A = Σᵢ wᵢ nᵢ nᵢᵀ,   b = Σᵢ wᵢ hᵢ nᵢ,   A = Σₖ λₖ eₖ eₖᵀ (λ₁ ≥ λ₂ ≥ λ₃ ≥ 0).
///
/// The primary space is spanned by the eₖ with λₖ ≥ ε·λ₁ (ε = `primary_eigenvalue_ratio`):
/// the displacement there is Σ_primary (eₖ·b / λₖ) eₖ, i.e. the least-squares offset restricted
/// to the directions the planes determine (1 on a smooth patch, 2 on a ridge, 3 at a corner).
/// The null space (the other eₖ, tangential directions) gets an optional tangential smoothing
/// move and otherwise no motion.
///
/// Entropy condition. Where offset planes converge (a shock: concave crease moving outward,
/// convex crease moving inward) the vertex lands on the planes' intersection: the entropy
/// solution that vertex-normal motion misses. Where they diverge (an expansion fan: convex
/// moving outward, concave moving inward) the planes' intersection would keep the crease sharp
/// and overshoot the exact, rounded fan by (1/cos θ − 1) times the distance travelled (2θ the
/// angle between the crease's normals), without converging under refinement. With
/// `ExpansionRule::huygens` (default) such vertices instead move by the mean offset h̄ along the
/// mean normal m = Σ wᵢ nᵢ / |Σ wᵢ nᵢ| (Huygens' principle: the exact fan point at distance h from
/// the crease, for any m in the normal cone); remeshing then fills the widening fan. The decision
/// follows the vertex's sharpest incident edge (largest dihedral angle): the vertex is expanding
/// when that edge is convex and the motion outward (h̄ > 0), or concave and inward. Deciding by the
/// sharpest edge rather than by the mean curvature keeps a concave crease on a saddle (the neck
/// right after two spheres merge, convex around the neck) a shock. On smooth patches both rules
/// agree to O(h θ²), and the mean-normal move is exact for a sphere: convex vertices whose
/// sharpest edge bends less than `smooth_dihedral_degrees` always take it.
///
/// Weights wᵢ: triangle areas (default) or the triangle's interior angle at the vertex.
///
/// Convention: a triangle's normal is (b − a) × (c − a) normalized (outward for the meshes the
/// mesher builds); positive speed moves the surface along it.

#include "tracker/mesh.h"

#include <array>
#include <vector>

namespace meniscus::tracker {

/// Weights wᵢ of the incident triangles in A = Σ wᵢ nᵢ nᵢᵀ.
enum class OffsetWeighting {
    area,   ///< triangle area (m²)
    angle,  ///< interior angle of the triangle at the vertex (radians)
};

/// Treatment of vertices where the offset planes diverge (see the file comment).
enum class ExpansionRule {
    huygens,  ///< mean offset along the mean normal: the exact expansion-fan point
    planes,   ///< least-squares plane intersection everywhere (sharp creases; Jiao's formula)
};

/// Options of face_offset_displacements().
struct FaceOffsettingOptions {
    OffsetWeighting weighting = OffsetWeighting::area;
    ExpansionRule expansion = ExpansionRule::huygens;
    /// Eigenvalues λₖ ≥ ratio·λ₁ of A form the primary space (Jiao's threshold ε); in (0, 1).
    double primary_eigenvalue_ratio = 0.003;
    /// Fraction in [0, 1] of the null-space projection of (area-weighted mean of the incident
    /// triangle centroids − vertex) added as tangential smoothing; 0 (default) leaves the null
    /// space still, so displacements are exactly linear in Δt and the tracker's own null-space
    /// smoothing improves the mesh between steps.
    double null_space_smoothing = 0.0;
    /// Cap on the offset part of a displacement: |d| ≤ max_offset_ratio · maxᵢ |hᵢ| over the
    /// incident triangles (≥ 1). Two planes whose normals are 2θ apart intersect at h / cos θ,
    /// so the default 4 binds only at creases sharper than 2·75.5° — folds right after a merge
    /// and low-valence vertices with scattered normals, where the least-squares intersection
    /// would otherwise throw the vertex many offsets away.
    double max_offset_ratio = 4.0;
    /// Convex or flat vertices whose sharpest incident edge bends by less than this (degrees,
    /// in [0, 180)) lie on a smooth patch and move by the mean offset along the mean normal
    /// whatever the direction: there characteristics do not cross within a step, and the plane
    /// intersection would overshoot a shrinking sphere by h (1/cos θ − 1) per step (θ the
    /// spread of the face normals), a bias that accumulates (A1 at ξ = 0.04: vertices 1.1e-3
    /// inside the exact spheres at t = 2 with 0, 5e-4 with 20). Sharper creases and concave
    /// vertices follow the entropy rule above.
    /// Off (0) by default. With split points and smoothing moves on a fitted surface
    /// (remesh/surface_fit.h), A1 at t = 2 with 0 / 20: L∞ 4.97e-3 / 4.94e-3, 2.08e-3 / 2.50e-3,
    /// 9.99e-4 / 1.57e-3 at ξ = 0.04, 0.02, 0.01; L1 1.00e-3 / 6.57e-4, 3.26e-4 / 2.64e-4,
    /// 1.22e-4 / 1.28e-4: it trades the neck's L∞ for the spheres' L1.
    double smooth_dihedral_degrees = 0.0;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Result of face_offset_displacements().
struct FaceOffset {
    /// Per vertex slot (zero for dead vertices and vertices without live triangles), metres.
    std::vector<Vec3> displacements;
    /// Per vertex slot: dimension of the primary space (1 smooth, 2 ridge, 3 corner; 0 for dead
    /// or isolated vertices).
    std::vector<int> primary_rank;
    /// Per vertex slot: 1 if the vertex was treated as an expansion (Huygens rule), else 0
    /// (smooth vertices moving by the mean normal without diverging planes count 0).
    std::vector<int> expanding;
    /// Per vertex slot: 1 if max_offset_ratio capped the offset, else 0.
    std::vector<int> capped;
};

/// Face-offsetting displacements over one step of length `dt` (s) with per-triangle normal
/// speeds `triangle_speeds` (m/s, sized num_triangles(); dead slots ignored).
/// Degenerate triangles (area below 1e-14 of the squared longest edge) carry no plane.
/// Throws std::invalid_argument on a size mismatch, non-finite dt or invalid options.
FaceOffset face_offset_displacements(const SurfaceMesh& mesh,
                                     const std::vector<double>& triangle_speeds, double dt,
                                     const FaceOffsettingOptions& options = {});

/// Same with one speed (m/s) for every triangle.
FaceOffset face_offset_displacements(const SurfaceMesh& mesh, double speed, double dt,
                                     const FaceOffsettingOptions& options = {});

/// Options of the step limit that keeps triangles from inverting.
struct InversionLimitOptions {
    /// Every live triangle must keep at least this fraction of its signed area measured along
    /// its normal at the start of the step; in [0, 1). 0 only forbids inversion itself; the
    /// default leaves a margin so that no triangle becomes exactly degenerate.
    double min_area_fraction = 0.1;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Largest τ in [0, 1] such that, moving every vertex along x + τ'·d for τ' in [0, τ], each live
/// triangle's area vector dotted with its unit normal at τ' = 0 stays ≥ min_area_fraction times
/// its area at τ' = 0. Per triangle this is a quadratic in τ', solved in closed form. Triangles
/// already degenerate at τ' = 0 (area below 1e-14 of the squared longest edge) are ignored.
/// For face offsetting with null_space_smoothing = 0, displacements are linear in Δt, so the
/// shortened step is exactly τ·Δt. Throws std::invalid_argument if `displacements` is not
/// sized num_vertices().
double max_non_inverting_step_fraction(const SurfaceMesh& mesh,
                                       const std::vector<Vec3>& displacements,
                                       const InversionLimitOptions& options = {});

/// One face-offsetting step with the inversion limit applied (paper §4.1: "we adjust the time
/// step to avoid inverting any triangles over a single offsetting step").
struct FaceOffsetStep {
    std::vector<Vec3> displacements;  ///< for the step actually taken (metres)
    double dt = 0.0;                  ///< step actually taken (s), ≤ the requested one
    bool shortened = false;           ///< true if dt < the requested step
    int attempts = 0;                 ///< displacement evaluations (1 unless shortened)
};

/// Computes displacements for `dt_max` and shortens the step to the inversion limit. With
/// null_space_smoothing = 0 displacements are linear in Δt, so they are scaled by the limit
/// fraction τ (dt = τ·dt_max, one evaluation). With smoothing they are recomputed and checked
/// again, halving further on failure, at most `MAX_STEP_ATTEMPTS` evaluations (then the last
/// ones are scaled back, which is inversion-free along straight lines).
/// Throws std::invalid_argument on invalid options or dt_max ≤ 0.
FaceOffsetStep face_offset_step(const SurfaceMesh& mesh, const std::vector<double>& triangle_speeds,
                                double dt_max, const FaceOffsettingOptions& offsetting = {},
                                const InversionLimitOptions& inversion = {});

/// Bound on the displacement evaluations in face_offset_step().
constexpr int MAX_STEP_ATTEMPTS = 16;

/// Remeshing guard for face-offsetting runs (paper §4.1: "we reject any edge collapse or edge
/// flip operation that results in a triangle with a normal that is too different from the
/// original triangle normals"). improve_mesh() applies its own per-triangle form of this test
/// through RemeshOptions::max_normal_change_degrees (remesh_options.h, default 60°);
/// face-offsetting runs should lower that to `max_angle_degrees` here. These functions serve
/// callers that assemble an operation's before/after triangles themselves.
struct NormalTurnLimit {
    /// Largest allowed angle (degrees, in (0, 180)) between a new triangle's normal and the
    /// reference normal of the triangles it replaces.
    double max_angle_degrees = 30.0;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// True if triangle (a, b, c) — oriented, normal (b − a) × (c − a) — turns its normal by more
/// than `limit` away from `reference_normal` (any length > 0), or is degenerate (area below
/// 1e-14 of its squared longest edge). Throws std::invalid_argument on a zero reference.
bool triangle_normal_turn_too_large(const Vec3& reference_normal, const Vec3& a, const Vec3& b,
                                    const Vec3& c, const NormalTurnLimit& limit = {});

/// Positions of an oriented triangle's three corners.
using TriangleCorners = std::array<Vec3, 3>;

/// For a remeshing operation that replaces `old_triangles` by `new_triangles` (positions after
/// the operation, same orientation convention): true if any new triangle turns its normal too
/// far from the area-weighted mean normal of the old ones (see triangle_normal_turn_too_large).
/// Edge flip: the two triangles on the edge before and after. Edge collapse: the triangles
/// around both endpoints before, the surviving rewired triangles after. Returns true (refuse)
/// if the old triangles have no mean normal (they cancel). Throws std::invalid_argument if
/// `old_triangles` is empty.
bool operation_turns_normals_too_far(const std::vector<TriangleCorners>& old_triangles,
                                     const std::vector<TriangleCorners>& new_triangles,
                                     const NormalTurnLimit& limit = {});

}  // namespace meniscus::tracker
