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

#include <utility>
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

/// A vertex make_edge_manifold() added: at parameter `s` from `from0` towards `from1` (a copy of
/// a vertex has from0 = from1 = the original and s = 0).
struct AddedVertex {
    int vi = INVALID_INDEX;
    int from0 = INVALID_INDEX;
    int from1 = INVALID_INDEX;
    double s = 0.0;
};

/// What make_edge_manifold() did.
struct EdgeManifoldReport {
    int nonmanifold_edges = 0;       ///< live edges with more than two triangles, before
    int vertices_split = 0;          ///< singular vertices split into one copy per fan
    std::vector<AddedVertex> added;  ///< in creation order (new vertices are appended)
};

/// For files that must be edge-manifold (renderers, booleans, printers): makes every edge of a
/// closed, consistently oriented mesh have exactly two triangles, one in each direction, and
/// every vertex a single fan, without moving the surface.
///
/// 1. Every non-manifold edge (two sheets brought together along it mid-merge or mid-pinch) is
///    split at its midpoint. Its endpoints may each have a single fan — the sheets meet again
///    around them (a pinched tube) — but the midpoint touches the sheets only through the split
///    edge, so its triangles form one fan per sheet (vertex_fans()' wedge pairs).
/// 2. Every singular vertex — one whose triangles form several fans (vertex_fans()), such as
///    those midpoints, or a vertex where two sheets touch — is split into one copy per fan at
///    the same position (the paper's separation, §3.6, without its nudge).
///
/// The midpoints lie on their edges, so the split triangles are coplanar halves of the old ones,
/// and copies do not move: the enclosed volume changes by round-off only. Vertices on an open
/// boundary are left alone. (The tracker's own separation, separate(), nudges copies apart and
/// refuses a split that would intersect; this one never moves anything, so it always succeeds
/// where the windings alternate around each edge.)
EdgeManifoldReport make_edge_manifold(SurfaceMesh& mesh);

}  // namespace meniscus::tracker
