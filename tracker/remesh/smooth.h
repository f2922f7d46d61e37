#pragma once
/// \file Null-space smoothing (Jiao 2007; paper §3.6.1): every vertex moves towards the
/// area-weighted centroid of its incident triangles, but only within the null space of its
/// quadric metric tensor — the tangent plane on a smooth patch, the ridge line on a ridge, not
/// at all at a corner — so volume and features are kept to first order. The whole smoothing
/// step is a pseudo-trajectory of all vertices made collision-free by resolve_collisions (§3.8).
/// Vertices on an open boundary do not move (§4.4).

#include "tracker/collision_resolution.h"
#include "tracker/mesh.h"
#include "tracker/remesh_options.h"

#include <vector>

namespace meniscus::tracker {

/// What a smoothing pass did.
struct SmoothReport {
    int iterations = 0;
    int vertices_moved = 0;     ///< vertices with a nonzero displacement, summed over iterations
    int ridge_vertices = 0;     ///< moved along a ridge line (last iteration)
    int corner_vertices = 0;    ///< kept still as corners (last iteration)
    int boundary_vertices = 0;  ///< kept still on the open boundary (last iteration)
    /// Collision resolution of the last iteration (default-constructed when safety is off).
    CollisionReport collisions;
    /// Iterations whose pseudo-trajectory could not be made collision-free (motion dropped).
    int refused_collision = 0;
    double seconds = 0.0;
};

/// Gradient (m²) of the enclosed volume with respect to vertex vi's position, all other vertices
/// fixed: Σ (u − x) × (w − x) / 6 over vi's triangles (x, u, w), one third of their summed area
/// vectors. The volume is linear in one vertex's position, so a displacement orthogonal to it
/// keeps the volume exactly.
Vec3 vertex_volume_gradient(const SurfaceMesh& mesh, int vi);

/// The null-space smoothing displacement of every live vertex (zero for dead, boundary and
/// corner vertices), scaled by options.smoothing_step_fraction; with
/// options.smoothing_preserves_volume, minus its component along vertex_volume_gradient (so
/// each vertex moved alone keeps the volume; moving neighbours together changes it at second
/// order).
std::vector<Vec3> null_space_displacements(const SurfaceMesh& mesh, const RemeshOptions& options,
                                           SmoothReport* counts = nullptr);

/// Runs options.smoothing_iterations smoothing steps. With collision safety the motion of each
/// step goes through resolve_collisions(context.collision) with unit duration.
SmoothReport smooth_null_space(SurfaceMesh& mesh, const RemeshOptions& options,
                               const ImproveContext& context);

}  // namespace meniscus::tracker
