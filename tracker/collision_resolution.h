#pragma once
/// \file Collision-safe motion (paper §3.8): given an intersection-free mesh at x_t0 and desired
/// end positions x_t1, change x_t1 as little as possible so that the linear motion from x_t0 to
/// x_t1 has no collision — hence the mesh at x_t1 is intersection-free.
///
/// Pipeline: (1) repulsion impulses for vertex–triangle and edge–edge proximities closer than
/// ε_p at t0; (2) up to `impulse_sweeps` sweeps of CCD with per-collision inelastic impulses;
/// (3) impact zones: colliding elements grouped by shared vertices and solved together,
/// minimizing ‖u′ − u‖_M subject to each collision's relative normal displacement reaching
/// its small separating target (an inequality: the dual, min ½λᵀ(C M⁻¹ Cᵀ)λ − λᵀ(b − C u) over
/// λ ≥ 0, by projected Gauss–Seidel), zones merging as new collisions appear, until none
/// remains; (4) bounded fallbacks: rigid impact zones (each zone moves as a rigid body), then
/// shortening the step (x_t1 pulled back towards x_t0), then — if still not free — no motion at
/// all. Every loop has a bound; what was used is reported. Never prints, never loops forever.

#include "common/cancellation.h"
#include "tracker/mesh.h"

#include <cstdint>
#include <vector>

namespace meniscus::tracker {

/// Options of collision resolution. Distances are absolute (metres); the SurfaceTracker
/// derives them from fractions of the mesh's initial mean edge length ξ.
struct CollisionOptions {
    double proximity_epsilon = 1e-5;      ///< ε_p: repulsion distance (m), > 0
    bool repulsion = true;                ///< phase (1) on/off
    int impulse_sweeps = 3;               ///< phase (2) sweeps (paper: 3), ≥ 0
    int max_impact_zone_iterations = 64;  ///< phase (3) detect/solve rounds, ≥ 1
    int max_rigid_zone_iterations = 16;   ///< phase (4a) rounds, ≥ 0
    int max_step_shortenings = 10;        ///< phase (4b): halvings of the remaining motion, ≥ 0
    /// Largest C M⁻¹ Cᵀ one impact-zone solve may assemble, in entries before duplicates are
    /// summed (16 bytes each: 2·10⁷ is 320 MB); ≥ 1. A vertex in k rows of a zone adds k². A
    /// neck pinching at edges of ξ/16 under mean-curvature flow put thousands of contacts on a
    /// few vertices, and assembling them asked for more memory than the machine had. A larger
    /// zone goes to the rigid-zone fallback (CollisionReport::oversized_zone_solves).
    int max_zone_matrix_entries = 20'000'000;
    /// Volume-aware response (issue 34; not in the paper): once the motion is collision-free,
    /// give each closed component back the volume collision handling changed (the component's
    /// volume under the requested motion minus its volume after the response) by the smallest
    /// mass-weighted displacement of the vertices the response left alone
    /// (volume_constraint.h). The corrected motion is kept only when CCD verifies it free;
    /// otherwise the verified uncorrected motion stays.
    bool preserve_volume = false;
    /// Attempts of that correction, ≥ 1: each one CCD rejects takes the vertices of the
    /// collisions it found out of the next attempt.
    int max_volume_rounds = 3;
    /// Checked before every detection round: throws meniscus::Cancelled once requested.
    CancellationToken cancel;
    void validate() const;                ///< throws std::invalid_argument naming the field
};

/// What collision resolution did.
struct CollisionReport {
    int proximities = 0;             ///< pairs closer than ε_p at t0 (repulsion applied)
    int collisions_first_sweep = 0;  ///< CCD hits in the first impulse sweep
    int impulses = 0;                ///< individual CCD impulses applied
    int impact_zone_iterations = 0;
    int impact_zones = 0;         ///< zones in the last impact-zone round
    int largest_impact_zone = 0;  ///< vertices in the largest zone
    /// Impact-zone solves handed to the rigid fallback because their matrix would have
    /// exceeded CollisionOptions::max_zone_matrix_entries.
    int oversized_zone_solves = 0;
    int rigid_zone_iterations = 0;
    int step_shortenings = 0;
    int broad_phases = 0;  ///< candidate-pair sets built (each a broad phase over the mesh)
    /// Corrected motions CCD checked (CollisionOptions::preserve_volume); the last one was kept
    /// when volume_restored.
    int volume_rounds = 0;
    bool volume_restored = false;  ///< a volume correction was verified and applied
    /// Σ over closed components of |V(response) − V(requested)| before and after the volume
    /// correction (m³); both 0 when preserve_volume is off.
    double volume_error_before = 0.0;
    double volume_error_after = 0.0;
    /// Fraction of the requested motion actually applied (1 unless step shortening was used;
    /// 0 when every fallback failed and the mesh stayed at x_t0).
    double motion_fraction = 1.0;
    /// True when the final motion was verified collision-free by CCD (always true unless
    /// motion_fraction is 0 because nothing could be verified — the mesh then did not move).
    bool collision_free = true;
};

/// Makes the motion x_t0 → x_t1 collision-free by changing x_t1 (both sized
/// mesh.num_vertices(); dead slots ignored). `dt` > 0 is the step's duration; everything is
/// computed on displacements x_t1 − x_t0 (velocity · dt), so only they matter. `masses` (optional,
/// > 0 per vertex) weight the impulses (M = I when null); `pinned` (optional) vertices never move.
/// x_t0 must be intersection-free for the guarantee to hold. Throws std::invalid_argument on size
/// mismatch or bad options.
CollisionReport resolve_collisions(const SurfaceMesh& mesh, const std::vector<Vec3>& x_t0,
                                   std::vector<Vec3>& x_t1, double dt,
                                   const CollisionOptions& options,
                                   const std::vector<double>* masses = nullptr,
                                   const std::vector<std::uint8_t>* pinned = nullptr);

/// True when the linear motion x_t0 → x_t1 has no possible vertex–triangle or edge–edge
/// collision (exact broad phase + CCD).
bool motion_is_collision_free(const SurfaceMesh& mesh, const std::vector<Vec3>& x_t0,
                              const std::vector<Vec3>& x_t1);

}  // namespace meniscus::tracker
