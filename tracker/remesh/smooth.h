#pragma once
/// \file Null-space smoothing (Jiao 2007; paper §3.6.1): every vertex moves towards the
/// area-weighted centroid of its incident triangles, but only within the null space of its
/// quadric metric tensor — the tangent plane on a smooth patch, the ridge line on a ridge, not
/// at all at a corner — so volume and features are kept to first order. The whole smoothing
/// step is a pseudo-trajectory of all vertices. With collision safety it goes through
/// resolve_collisions (§3.8), or, with options.smoothing_holds_colliding_vertices, every vertex
/// of a pair that may collide during it (exact CCD) is held still, repeated until none may:
/// smoothing is not a physical motion, and resolve_collisions' impulses and impact zones move
/// the neighbouring sheets apart (on the A4 curl-noise test, thin sheets folded against each
/// other, that added 0.35 % volume by t = 9.5 and 1.9 % by t = 15.5, while the smoothing moves
/// themselves changed it by 0.03 %). Vertices on an open
/// boundary do not move (§4.4).

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
    /// Collision resolution of the last iteration (default-constructed when safety is off or
    /// smoothing_holds_colliding_vertices is on).
    CollisionReport collisions;
    /// Iterations whose pseudo-trajectory could not be made collision-free (motion dropped).
    int refused_collision = 0;
    /// With smoothing_holds_colliding_vertices: vertices held still because their move could
    /// collide, and rounds of collision checks (both summed over iterations).
    int held_colliding = 0;
    int collision_rounds = 0;
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

/// Runs options.smoothing_iterations smoothing steps. With collision safety the mesh stays
/// intersection-free: the motion of each step goes through resolve_collisions(context.collision)
/// with unit duration, or colliding vertices are held (see the file comment).
SmoothReport smooth_null_space(SurfaceMesh& mesh, const RemeshOptions& options,
                               const ImproveContext& context);

}  // namespace meniscus::tracker
