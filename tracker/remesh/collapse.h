#pragma once
/// \file Edge collapse (paper §3.5.3): edges shorter than β are replaced by one vertex. The new
/// position is the butterfly point (with RemeshOptions::collapse_on_fitted_surface, the
/// fitted-surface or circular-arc point of remesh/surface_fit.h where those exist), except that a
/// vertex on a ridge or corner (quadric metric tensor, quadric.h) keeps its place when the other
/// end is less of a feature (of two corners, the sharper one), and an edge between two ridge
/// vertices collapses to its midpoint (the butterfly stencil would reach across the feature and
/// round it off). With RemeshOptions::collapse_preserves_volume (default) that position then moves
/// along the gradient of the enclosed volume (the area-weighted normal of the new star, so a kept
/// ridge vertex moves across its ridge, not along it; a kept corner does not move) until the
/// collapse keeps the volume exactly: the coarser star otherwise cuts inside a convex
/// surface. Both endpoints
/// move there as a pseudo-motion checked by CCD; if it may collide, positions closer to the
/// edge midpoint are tried (not when a feature vertex stays put), and if none is safe the
/// collapse is abandoned. A collapse is also
/// refused when it turns a triangle normal too far, changes the enclosed volume by more than
/// γ (counting the motion of both endpoints), or — with topology changes off — would pinch the
/// surface. Boundary and non-manifold edges are never collapsed (§3.5.3, §4.4).

#include "tracker/mesh.h"
#include "tracker/remesh/element_hash.h"
#include "tracker/remesh_options.h"

namespace meniscus::tracker {

/// What a collapse pass did. Refusals count attempts (an edge refused in two passes counts
/// twice); the reason is that of the last trajectory tried.
struct CollapseReport {
    int collapses = 0;
    int passes = 0;
    int skipped_boundary = 0;     ///< short edges on or pinning the open boundary (§4.4)
    int skipped_nonmanifold = 0;  ///< short non-manifold edges
    int refused_topology = 0;     ///< would pinch (topology changes off) or duplicate a triangle
    int refused_normal = 0;       ///< a triangle would invert, degenerate or turn too far
    int refused_volume = 0;       ///< enclosed volume would change by more than γ
    int refused_long_edge = 0;    ///< an edge would grow beyond α
    int refused_collision = 0;    ///< no collision-free trajectory found
    int retries_towards_midpoint = 0;  ///< collapses that succeeded on a later trajectory
    int feature_vertex_kept = 0;       ///< collapses into a ridge/corner vertex's position
    /// Collapses to a fitted-surface or circular-arc point (collapse_on_fitted_surface).
    int fitted = 0;
    int arc = 0;
    int refused_total() const {
        return refused_topology + refused_normal + refused_volume + refused_long_edge +
               refused_collision;
    }
    double seconds = 0.0;
};

/// One way to collapse edge `ei`: `removed` merges into `kept`, which moves to `position`.
struct CollapsePlan {
    int ei = INVALID_INDEX;
    int kept = INVALID_INDEX;
    int removed = INVALID_INDEX;
    Vec3 position = Vec3::Zero();
};

/// True when the edge is a boundary edge or both its endpoints are on the boundary (the
/// collapse would change the boundary, §4.4).
bool collapse_touches_boundary(const SurfaceMesh& mesh, int ei);
/// True when the collapse would change the topology: the endpoints share a neighbour that is
/// not opposite the edge (link condition), or a vertex opposite the edge has only three
/// neighbours (the collapse would leave a degenerate tetrahedron).
bool collapse_changes_topology(const SurfaceMesh& mesh, int ei);
/// True when a rewired triangle would coincide with an existing triangle of the same
/// orientation (a configuration separation cannot clean up).
bool collapse_duplicates_triangle(const SurfaceMesh& mesh, const CollapsePlan& plan);
/// True when a surviving triangle would degenerate or its normal turn by more than
/// `max_normal_change_degrees` (> 90° is an inversion).
bool collapse_inverts_normal(const SurfaceMesh& mesh, const CollapsePlan& plan,
                             double max_normal_change_degrees);
/// Signed change of the enclosed volume when both endpoints move to plan.position.
double collapse_volume_change(const SurfaceMesh& mesh, const CollapsePlan& plan);
/// Gradient of the enclosed volume after the collapse with respect to plan.position (m²): the
/// volume is linear in that position, so moving it by −ΔV g/|g|² keeps the volume exactly.
Vec3 collapse_volume_gradient(const SurfaceMesh& mesh, const CollapsePlan& plan);
/// True when |collapse_volume_change| > γ.
bool collapse_changes_volume_too_much(const SurfaceMesh& mesh, const CollapsePlan& plan,
                                      double gamma);
/// True when an edge to the new vertex would be longer than α and longer than before.
bool collapse_creates_long_edge(const SurfaceMesh& mesh, const CollapsePlan& plan, double alpha);
/// True when moving both endpoints linearly to plan.position may collide (CCD).
bool collapse_collides(const SurfaceMesh& mesh, const ElementHash& hash, const CollapsePlan& plan);

/// Collapses edges shorter than β, shortest first, sweeping until none collapses or
/// `options.max_collapse_passes` sweeps ran. Collision checks only with collision safety on;
/// topology checks only with topology changes off (then separation must run afterwards to
/// remove what pinching leaves: improve_mesh does that).
CollapseReport collapse_short_edges(SurfaceMesh& mesh, const RemeshOptions& options,
                                    const ImproveContext& context);

}  // namespace meniscus::tracker
