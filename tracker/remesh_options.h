#pragma once
/// \file Options of collision-safe mesh improvement (paper §3.5–3.6) and topology changes
/// (§3.6–3.7), and the per-step context the SurfaceTracker hands to `improve_mesh()` and
/// `change_topology()`.
///
/// Lengths are fractions of ξ, the mean edge length of the initial mesh, and volumes fractions
/// of ξ³, so a scene scales without retuning (paper §4: α = 1.5ξ, β = 0.5ξ, γ = 0.1ξ³).

#include "tracker/collision_resolution.h"

#include <cstdint>
#include <vector>

namespace meniscus::tracker {

/// Mesh improvement: split, flip, collapse and null-space smoothing (§3.5, §3.6.1).
struct RemeshOptions {
    bool split = true;     ///< split edges longer than α (§3.5.1)
    bool flip = true;      ///< flip non-Delaunay edges (§3.5.2)
    bool collapse = true;  ///< collapse edges shorter than β (§3.5.3)
    bool smooth = true;    ///< null-space smoothing (§3.6.1)

    double max_edge_fraction = 1.5;           ///< α / ξ: edges longer than α are split, > min
    double min_edge_fraction = 0.5;           ///< β / ξ: edges shorter than β collapse, > 0
    double max_volume_change_fraction = 0.1;  ///< γ / ξ³ per flip, collapse or split, > 0
    /// Curvature-adaptive sizing (remesh/sizing.h), not in the paper: c > 0 lowers α and β by
    /// the same factor s = clamp(c / (κ α), min_curvature_size_fraction, 1) where the surface
    /// turns with curvature κ, so edges there turn by at most about c radians (a neck of radius
    /// r keeps about 2π/c edges around it). 0 (the default) keeps α and β everywhere; ≥ 0.
    /// A2 (validate and scenes/flows/a2_*.json) uses c = 0.7: on the paper's dumbbell at
    /// ξ = 0.04 the neck pinched at t = 0.021957 instead of 0.022006 (reference 0.021925) and
    /// vertex L∞ at t = 0.025 fell from 1.39e-3 to 4.9e-4 (app/validate_parameters.h has the
    /// other c). On an earlier A2 dumbbell (bulbs 0.4, handle 0.15, blend 0.05; forward
    /// Euler, volume-keeping collapses) at ξ = 0.04
    /// (c = 0.5, s_min = 0.125, graded target lengths) L∞ fell from 2.4e-3 to 1.45e-3 and the
    /// pinch-off came 6e-4 s earlier, nearer the reference; at ξ = 0.02 L∞ stayed at 5.9e-4
    /// (L1 6.4e-5 against 6.6e-5) for twice the time (778 s against 383 s). Before the grading
    /// the ξ = 0.02 run stalled at the pinch (t = 0.01595), and with s_min = 1/16 at ξ = 0.04
    /// one run built an impact zone too large for memory (hence
    /// CollisionOptions::max_zone_matrix_entries), then spent over 10 minutes in one step.
    /// Needs split_on_fitted_surface: butterfly points on the irregular stencils of a graded
    /// mesh leave bumps, the curvature estimate sees them and refines further, without end
    /// (a static dumbbell handle went from 18 to 700 vertices in 12 improvements, splitting and
    /// collapsing 600 edges each; with fitted points it settled at 270 in 3).
    double curvature_edge_fraction = 0.0;
    /// Curvature-adaptive sizing sees only convex turning (the largest positive principal
    /// curvature, outward normals) instead of the largest in magnitude: tips and necks refine,
    /// concave creases do not. Not in the paper. On the A2 dumbbell the concave crease where
    /// the handle meets the balls is a kink at t = 0 that the flow rounds within a layer
    /// narrower than an edge; refined by splits on fitted surfaces it overfills, so with
    /// c = 0.35 every vertex ended outside at ξ = 0.02 (vertex L∞ 9.8e-5 at t = 0.025), while
    /// the just-pinched convex tips need that finer c (app/validate_parameters.h).
    bool curvature_sizing_convex_only = false;
    /// Smallest s of curvature-adaptive sizing, in (0, 1]: α and β never fall below this
    /// fraction (thin folds would otherwise refine without bound).
    double min_curvature_size_fraction = 0.25;
    /// Thin-sheet sizing (remesh/sizing.h), not in the paper: f > 0 lowers α and β (by the same
    /// factor s, floored at min_curvature_size_fraction) where a vertex faces another part of
    /// the surface — a triangle whose normal opposes the vertex normal — at a distance h that
    /// the chord sag κ(sα)²/8 of edges at the vertex's curvature κ would exceed f·h. The two
    /// discretized sides of a sheet thinner than their chord sag meet and are then held apart
    /// by collision handling while the flow stretches them (A4's volume gain). 0 (the default)
    /// turns it off; ≥ 0. Experimental. Needs split_on_fitted_surface, like
    /// curvature_edge_fraction. A4 at ξ = 0.04 with f = 1.5 and s_min = 0.5: volume +2.47 %
    /// at t = 25 on 138k triangles, against +9.90 % on 40k with uniform sizing (and +2.88 % at
    /// t = 24.45 on 226k with uniform sizing at ξ = 0.02).
    double thin_sheet_sag_fraction = 0.0;

    int max_split_passes = 4;     ///< sweeps over long edges per improvement, ≥ 1
    /// New split vertices go onto a quadratic height field fitted over both endpoints' one-rings
    /// where both endpoints are smooth (quadric rank 1) and the fit is accepted, else onto the
    /// circular arc through the endpoints that meets their normals (a fillet or fan a few edges
    /// wide), else onto the butterfly point (§3.5.1); see remesh/surface_fit.h. With this off
    /// (the default), always the butterfly point. A1's growing spheres at ξ = 0.04: butterfly
    /// points landed 5e-4 inside on average (irregular stencils beside fresh splits), fitted
    /// points 4e-5 outside. Off by default because it is not volume-neutral: the Enright test at
    /// ξ = 0.02 gained 0.26 % volume with it (0.16 % without), and fluids need volume first.
    bool split_on_fitted_surface = false;
    /// Collapses aim the merged vertex at the point split_on_fitted_surface would give a split of
    /// the same edge (fitted surface, else circular arc) instead of the butterfly point, where
    /// both endpoints are smooth; collapse_preserves_volume then moves it as before. A shrinking
    /// shape collapses edges all the time, and butterfly points on the irregular stencils that
    /// earlier collapses leave sit inside the surface on average: a sphere shrunk by mean
    /// curvature from R = 0.3 to 0.1 at ξ = 0.02 (A2 scene, quadratic fitted smoothing) ended
    /// with signed vertex errors from −3.4e-5 to +1.3e-5 (mean −8.2e-6) with butterfly
    /// collapses, from +1.5e-7 to +2.5e-6 (mean +1.0e-6) with this. Off by default, like
    /// split_on_fitted_surface; its fit uses split_fit_residual_fraction.
    bool collapse_on_fitted_surface = false;
    /// Largest residual of the split fit, as a fraction of the patch radius, in (0, 1]. Tighter
    /// than for smoothing: a quadratic across a fan a few edges wide fits to within 1 % but puts
    /// the new vertex off it by up to ξ/7 (A1 at ξ = 0.02: L∞ 3.3e-3 with 1e-2, 2.8e-3 with 3e-3).
    double split_fit_residual_fraction = 3e-3;
    int max_collapse_passes = 4;  ///< sweeps over short edges per improvement, ≥ 1
    int max_flip_sweeps = 5;      ///< flip sweeps per improvement (paper: 5), ≥ 1
    /// A flip must shorten the edge by at least this fraction of its length (stops flip-flops);
    /// in [0, 1).
    double min_flip_length_decrease_fraction = 1e-3;
    /// Collapse trajectories tried, from the butterfly (or feature) position to the edge midpoint
    /// in equal steps (§3.5.3 "retried towards the midpoint"), ≥ 1.
    int collapse_position_attempts = 3;
    /// Collapses move the new vertex from the butterfly (or feature / midpoint) position along
    /// the gradient of the enclosed volume until the collapse keeps the volume exactly: the
    /// butterfly point alone lies on the smooth surface, but the coarser star cuts inside it
    /// (−0.25 % of the Enright sphere's volume over one period at ξ = 0.02). Off for shape
    /// accuracy on shrinking surfaces, which collapse edges all the time: each volume-keeping
    /// collapse lifts a vertex off the surface, and a mean-curvature sphere run to 0.9 of its
    /// extinction time at ξ = 0.04 lagged by vertex L∞ 2.28e-3 with it, 3.1e-4 without (A2 turns
    /// it off).
    bool collapse_preserves_volume = true;
    /// Smoothing displacements lose their component along each vertex's volume gradient, so a
    /// vertex moved alone keeps the enclosed volume exactly (the quadric's null space is only
    /// approximately orthogonal to it).
    bool smoothing_preserves_volume = true;
    /// Smooth vertices (quadric rank 1) land on a quadratic height field fitted over their
    /// two-ring (remesh/surface_fit.h) after the tangential move, instead of staying in the
    /// tangent plane, which puts a vertex moved by δ about δ²κ/2 off a curved surface every step
    /// (A1 at ξ = 0.04: the sphere parts sank 2.6e-4 over t ∈ [0, 1] from this alone). Where
    /// the fit is refused, see smoothing_unfitted_min_angle_degrees. Off by default (then
    /// smoothing_preserves_volume applies everywhere): it is not volume-neutral, and on the
    /// Enright test at ξ = 0.02 it gained 0.9 % volume (1.1 % with split_on_fitted_surface, 0.16 %
    /// with neither). Shape-accuracy runs (A1) turn both on.
    bool smoothing_onto_fitted_surface = false;
    /// Degree of that fit, 2 or 3 (SurfaceFitOptions::degree). A quadratic fitted where the
    /// curvature varies has a slope error that a vertex drifting across it turns into a normal
    /// error first order in the drift: on the A2 dumbbell at ξ = 0.02 fitted quadratic
    /// smoothing left every vertex outside by t = 0.025 (mean 2.2e-4), and tangent-plane
    /// smoothing every drop vertex inside (mean −6.6e-5; on a sphere shrunk to R = 0.1 by
    /// collapses −8.7e-5). The cubic: +3.0e-5 and −6.6e-6. 2 by default (A1 was measured with it);
    /// A2 uses 3 with smoothing_fit_max_turn 0.6 and collapse_on_fitted_surface (dumbbell at
    /// ξ = 0.02: mean −1.7e-5, app/validate_parameters.h).
    int smoothing_fit_degree = 2;
    /// With smoothing_onto_fitted_surface, fitted moves only where the fit turns by at most
    /// this over its patch (SurfacePatch::turn(), radians, ≥ 0; 0: no bound); every other
    /// smooth vertex — its fit refused or turning further — takes the tangent-plane move of
    /// plain smoothing instead. A two-ring across a thin neck or a just-pinched tip (turn ≥ 1)
    /// is too coarse for its fit to beat the plain move.
    double smoothing_fit_max_turn = 0.0;
    /// With collision safety, a smoothing move that may collide holds the vertices of the pair
    /// still (remesh/smooth.h) instead of going through resolve_collisions, whose impulses push
    /// the neighbouring sheets apart: on A4 curl noise (thin folded sheets) that push added
    /// 1.9 % volume by t = 15.5. Smoothing is an improvement, not a motion anyone asked for, so
    /// by default a colliding move is dropped rather than paid for by moving other vertices.
    /// (A1 face offsetting, L∞ at ξ = 0.04 / 0.02 / 0.01: 4.97e-3 / 2.12e-3 / 9.54e-4 with it,
    /// 4.97e-3 / 2.58e-3 / — pushing; Enright volume unchanged.)
    bool smoothing_holds_colliding_vertices = true;
    /// With smoothing_onto_fitted_surface, a smooth vertex whose fit is refused (a crease or an
    /// under-resolved fillet) moves only when a triangle around it has an angle below this
    /// (degrees, in [0, 60]; 60 always moves it): its tangent-plane move leaves the surface by
    /// about δ²κ/2 each step. A1 at ξ = 0.04: these moves pushed the neck's fan outwards, and
    /// L1 at t = 2 fell from 1.1e-3 to 8.0e-4 with 20.
    double smoothing_unfitted_min_angle_degrees = 20.0;
    /// A flip must beat the Delaunay test by more than this times the fold angle θ (radians)
    /// between the two triangles' normals: opposite angles summing to more than π + w·θ (at
    /// most π + π/4, beyond which a quad flips across any fold). A flip across a fold cuts into
    /// (or adds to) the surface by about θ times the quad's area and edge length; on flat
    /// patches (θ ≈ 0) the plain Delaunay test remains. ≥ 0 (0: plain Delaunay). Enright test
    /// at ξ = 0.02: flips changed the volume by −1.1 % with 0, −0.2 % with 2.
    double flip_fold_weight = 2.0;
    /// Largest angle (degrees) between a triangle's normal before and after a collapse or flip,
    /// in (0, 180]; 90 refuses only inversions. Face offsetting wants smaller values.
    double max_normal_change_degrees = 60.0;

    /// Quadric metric tensor A = Σ wᵢ nᵢ nᵢᵀ / Σ wᵢ (eigenvalues λ₁ ≥ λ₂ ≥ λ₃, summing to 1):
    /// a vertex is on a ridge when λ₂ ≥ ridge_eigenvalue_ratio · λ₁, in (0, 1).
    double ridge_eigenvalue_ratio = 0.1;
    /// ... and at a corner when λ₃ ≥ corner_eigenvalue_ratio · λ₁, in (0, 1).
    double corner_eigenvalue_ratio = 0.1;

    int smoothing_iterations = 1;  ///< null-space smoothing steps per improvement, ≥ 0
    /// Fraction of the null-space projected displacement to the area-weighted centroid of the
    /// incident triangles applied per step, in (0, 1].
    double smoothing_step_fraction = 0.5;

    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Separation of pinched surfaces (§3.6): removal of degenerate tetrahedra and duplication of
/// singular vertices.
struct SeparationOptions {
    /// Each copy of a singular vertex moves towards the centroid of its triangle fan by this
    /// fraction of the distance (so no two vertices share a point), in (0, 0.5).
    double nudge_fraction = 0.01;
    /// Halvings of the nudge tried when the nudged fans would intersect something, ≥ 0.
    int max_nudge_halvings = 4;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Topology changes: merging (§3.7) and separation (§3.6).
struct TopologyOptions {
    bool allow_merging = true;     ///< zipper proximal edge pairs (§3.7)
    bool allow_separation = true;  ///< remove degenerate tetrahedra, split singular vertices
    /// Edge pairs closer than this fraction of ξ are merged, > 0. Must exceed the collision
    /// proximity ε_p / ξ for approaching surfaces ever to merge.
    double merge_distance_fraction = 0.1;
    /// Closed-form zipper alignments tried per pair (cheapest first), in [1, 4].
    int max_zipper_alignments = 4;
    /// Within one pass, a pair closer than this fraction of ξ to a pair already merged in that
    /// pass is left for a later step, so one contact patch opens one neck instead of several
    /// tubes (handles) at once; ≥ 0, and 0 merges every pair as the paper's §3.7 does.
    double merge_spacing_fraction = 4.0;
    SeparationOptions separation;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Per-step facts `improve_mesh()` needs besides its options.
struct ImproveContext {
    double xi = 0.0;                     ///< ξ: initial mean edge length (metres, > 0)
    bool collision_safety = true;        ///< §3.3 switch: check every operation for collisions
    bool allow_topology_changes = true;  ///< §3.3 switch: false refuses pinching operations
    /// Collision resolution for the smoothing pseudo-trajectory (absolute ε_p).
    CollisionOptions collision;
    /// Used to clean up after collapses and flips when topology changes are allowed.
    SeparationOptions separation;
    /// Vertices that stay where they are (optional; indices past its end are free): smoothing
    /// leaves them, and a collapse onto one keeps its position (as an open surface's boundary).
    const std::vector<std::uint8_t>* pinned = nullptr;
    /// Is vertex vi pinned?
    bool is_pinned(int vi) const {
        return pinned && static_cast<size_t>(vi) < pinned->size() &&
               (*pinned)[static_cast<size_t>(vi)] != 0;
    }
    /// Checked between operations: throws meniscus::Cancelled once requested (the mesh is then
    /// valid but only partly improved).
    CancellationToken cancel;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Per-step facts `change_topology()` needs besides its options.
struct TopologyContext {
    double xi = 0.0;               ///< ξ: initial mean edge length (metres, > 0)
    bool collision_safety = true;  ///< §3.3 switch: refuse merges whose triangles intersect
    CancellationToken cancel;      ///< checked between merges (throws meniscus::Cancelled)
    void validate() const;         ///< throws std::invalid_argument naming the field
};

/// Absolute thresholds derived from options and ξ.
struct RemeshLimits {
    double max_edge_length = 0.0;    ///< α (metres)
    double min_edge_length = 0.0;    ///< β (metres)
    double max_volume_change = 0.0;  ///< γ (metres³)
};
RemeshLimits remesh_limits(const RemeshOptions& options, double xi);

}  // namespace meniscus::tracker
