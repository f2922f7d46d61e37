#pragma once
/// \file Edge flip (paper §3.5.2): an edge whose two opposite vertices are closer than the edge
/// is long, and whose opposite angles sum to more than π (it is not locally Delaunay), is
/// replaced by the other diagonal — unless that creates an intersection, a vertex lies in the
/// tetrahedron the flip sweeps, the enclosed volume changes by more than γ, or a triangle normal
/// turns too far. Non-manifold edges are flipped on a consistently oriented pair of their
/// triangles; boundary edges never (§4.4).

#include "tracker/mesh.h"
#include "tracker/remesh/element_hash.h"
#include "tracker/remesh_options.h"

namespace meniscus::tracker {

/// What a flip pass did.
struct FlipReport {
    int flips = 0;
    int sweeps = 0;                        ///< sweeps run (≤ max_flip_sweeps)
    int refused_existing_edge = 0;         ///< the new diagonal already exists (would pinch)
    int refused_volume = 0;                ///< |tetrahedron volume| > γ
    int refused_normal = 0;                ///< a new triangle turns too far or is degenerate
    int refused_intersection = 0;          ///< new triangles would intersect the mesh
    int refused_point_in_tetrahedron = 0;  ///< a vertex lies in the swept tetrahedron
    int refused_total() const {
        return refused_existing_edge + refused_volume + refused_normal + refused_intersection +
               refused_point_in_tetrahedron;
    }
    double seconds = 0.0;
};

/// A flip candidate: edge (a, b) with t0 = (a, b, c) traversing a→b and t1 = (b, a, d).
struct FlipStencil {
    int ei = INVALID_INDEX;
    int t0 = INVALID_INDEX, t1 = INVALID_INDEX;
    int a = INVALID_INDEX, b = INVALID_INDEX, c = INVALID_INDEX, d = INVALID_INDEX;
};

/// Fold angle (radians, in [0, π]) between the normals of triangles (a, b, c) and (b, a, d).
double flip_fold_angle(const SurfaceMesh& mesh, const FlipStencil& s);
/// True when the stencil's edge should flip: |cd| < (1 − min decrease) |ab| and the angles at
/// c and d sum to more than π + min(options.flip_fold_weight · flip_fold_angle, π/4) (not
/// locally Delaunay, by more than the fold makes it worth: a flip across a fold changes the
/// shape; a quad beyond π/4 flips anyway).
bool flip_improves(const SurfaceMesh& mesh, const FlipStencil& s, const RemeshOptions& options);
/// True when edge (c, d) already exists (the flip would create a non-manifold edge or a
/// degenerate tetrahedron) or c = d.
bool flip_creates_existing_edge(const SurfaceMesh& mesh, const FlipStencil& s);
/// True when the tetrahedron (a, b, c, d) — the volume change of the flip — exceeds γ.
bool flip_changes_volume_too_much(const SurfaceMesh& mesh, const FlipStencil& s, double gamma);
/// True when a new triangle is degenerate or its normal differs from either old normal by more
/// than `max_normal_change_degrees`.
bool flip_changes_normals_too_much(const SurfaceMesh& mesh, const FlipStencil& s,
                                   const RemeshOptions& options);
/// True when a new triangle would intersect an existing one (exact).
bool flip_intersects(const SurfaceMesh& mesh, const ElementHash& hash, const FlipStencil& s);
/// True when some other vertex lies in the closed tetrahedron (a, b, c, d) the flip sweeps.
bool flip_sweeps_vertex(const SurfaceMesh& mesh, const ElementHash& hash, const FlipStencil& s);

/// Sweeps all edges, flipping where `flip_improves` and every check passes, until a sweep
/// flips nothing or `options.max_flip_sweeps` sweeps ran. With collision safety off the
/// intersection and point-in-tetrahedron checks are skipped.
FlipReport flip_edges(SurfaceMesh& mesh, const RemeshOptions& options,
                      const ImproveContext& context);

}  // namespace meniscus::tracker
