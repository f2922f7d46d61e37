#pragma once
/// \file Mesh separation (paper §3.6): after collapses, flips and merges, delete degenerate
/// tetrahedra (two triangles on the same three vertices) and the vertices they orphan, then
/// split every singular vertex — one whose triangles form several fans not connected through
/// its edges — into one copy per fan, each nudged slightly towards its fan so that no two
/// vertices share a point. Together these let a thinning surface pinch off. (A SurfaceMesh
/// cannot hold "collapsed" triangles with a repeated vertex: add_triangle refuses them, so
/// there are none to delete.) Vertices on an open boundary are left alone (§4.4).

#include "tracker/mesh.h"
#include "tracker/remesh_options.h"

#include <vector>

namespace meniscus::tracker {

/// What a separation pass did.
struct SeparationReport {
    int degenerate_tetrahedra_removed = 0;  ///< triangle pairs on the same three vertices
    int orphan_vertices_removed = 0;        ///< vertices left without triangles
    int singular_vertices_split = 0;        ///< vertices split into one copy per fan
    int copies_created = 0;                 ///< new vertices (fans beyond the first)
    /// Singular vertices left joined because every nudge tried would make an intersection.
    int refused_intersection = 0;
    double seconds = 0.0;
};

/// The triangle fans around vertex vi: groups of its triangles connected through edges
/// incident to vi. More than one fan means vi is singular. Across a non-manifold edge (two
/// sheets brought together along it) triangles connect only in the pairs that bound one wedge
/// of the inside, so each sheet is its own fan and the edge's vertices are split too.
std::vector<std::vector<int>> vertex_fans(const SurfaceMesh& mesh, int vi);

/// Removes degenerate tetrahedra and orphaned vertices, then splits singular vertices. With
/// `collision_safety`, a split whose nudged fans would intersect the mesh (exact test) is
/// retried with halved nudges and refused when none is safe. `xi` sizes the broad phase.
SeparationReport separate(SurfaceMesh& mesh, const SeparationOptions& options,
                          bool collision_safety, double xi);

}  // namespace meniscus::tracker
