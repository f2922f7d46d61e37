#pragma once
/// \file Edge split (paper §3.5.1): edges longer than α (lowered where the surface turns, with
/// curvature-adaptive sizing: remesh/sizing.h) get a new vertex, first at the midpoint (which
/// cannot create an intersection in exact arithmetic; with collision safety the rounded one is
/// checked), then moved to its target as a pseudo-motion checked by
/// CCD; if that motion may collide the vertex stays at the midpoint. The target is the butterfly
/// point, or with RemeshOptions::split_on_fitted_surface the fitted-surface or circular-arc
/// point of remesh/surface_fit.h where those exist. Boundary and non-manifold edges are never
/// split (§3.5.1, §4.4).

#include "tracker/mesh.h"
#include "tracker/remesh/element_hash.h"
#include "tracker/remesh_options.h"

namespace meniscus::tracker {

/// What a split pass did.
struct SplitReport {
    int splits = 0;                 ///< edges split
    int fitted = 0;                 ///< of those, aimed at the fitted surface (surface_fit.h)
    int arc = 0;                    ///< of those, aimed at the circular-arc point (surface_fit.h)
    int butterfly_collides = 0;     ///< of those, kept at the midpoint: butterfly motion collided
    int butterfly_unavailable = 0;  ///< of those, at the midpoint: no butterfly stencil
    int volume_limited = 0;  ///< of those, offset from the midpoint scaled back to change the volume by γ
    /// long edges not split because the rounded midpoint would make the new triangles
    /// intersect something (exactly, the midpoint cannot)
    int refused_midpoint = 0;
    int skipped_boundary = 0;       ///< long boundary edges left alone (§4.4)
    int skipped_nonmanifold = 0;    ///< long non-manifold edges left alone
    int passes = 0;                 ///< sweeps over the long edges
    double seconds = 0.0;
};

/// True when the edge may be split at all (exactly two triangles: not boundary, not
/// non-manifold).
bool split_allowed(const SurfaceMesh& mesh, int ei);

/// True when moving new vertex `vi` (just created at a midpoint) to `target` may collide.
bool split_butterfly_collides(const SurfaceMesh& mesh, const ElementHash& hash, int vi,
                              const Vec3& target);

/// True when the four triangles of splitting edge `ei` at `midpoint` (its rounded midpoint)
/// would be degenerate or intersect another triangle (exact test; `hash` current).
bool split_midpoint_intersects(const SurfaceMesh& mesh, const ElementHash& hash, int ei,
                               const Vec3& midpoint);

/// Splits every edge longer than α, longest first, sweeping until none is left or
/// `options.max_split_passes` sweeps ran. With `context.collision_safety` off the target is
/// used without a check.
SplitReport split_long_edges(SurfaceMesh& mesh, const RemeshOptions& options,
                             const ImproveContext& context);

}  // namespace meniscus::tracker
