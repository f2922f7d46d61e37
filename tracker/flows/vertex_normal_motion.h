#pragma once
/// \file Motion in the normal direction by vertex normals (paper §4.1, Fig. 4.2): each vertex
/// moves by speed·Δt along its area-weighted vertex normal.
///
/// This is the "first instinct" scheme the paper compares face offsetting against. Where
/// characteristics merge (concave creases under outward motion, convex ones under inward
/// motion) it does not produce the entropy solution, and on the two-sphere test (docs/validation.md
/// A1) its error does not shrink under refinement. Kept for that comparison only.

#include "tracker/mesh.h"
#include "tracker/mesh_measures.h"  // area_weighted_vertex_normals

#include <vector>

namespace meniscus::tracker {

/// Displacements speed·dt·n_v for each live vertex (n_v from area_weighted_vertex_normals();
/// zero for dead vertices). `speed` in m/s along the outward normal (positive expands a closed
/// surface with outward normals), `dt` in s. Sized num_vertices().
std::vector<Vec3> vertex_normal_displacements(const SurfaceMesh& mesh, double speed, double dt);

}  // namespace meniscus::tracker
