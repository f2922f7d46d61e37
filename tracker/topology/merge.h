#pragma once
/// \file Merging (paper §3.7): edge pairs closer than the merge distance, each edge on exactly
/// two triangles, are zippered nearest first — the four triangles on the two edges are removed
/// and the two resulting four-edge holes joined by a closed-form band of eight triangles. The
/// merge is kept only if the new triangles intersect nothing (degenerate contacts count as
/// intersections); otherwise the mesh is left as it was. Edges touching an open boundary take
/// part in no merge (§4.4).

#include "tracker/mesh.h"
#include "tracker/remesh/element_hash.h"
#include "tracker/remesh_options.h"

#include <array>
#include <vector>

namespace meniscus::tracker {

/// What a merge pass did.
struct MergeReport {
    int candidates = 0;  ///< edge pairs closer than the merge distance
    int merges = 0;
    int stale = 0;                  ///< pairs whose edges an earlier merge changed or removed
    int deferred_near_merge = 0;    ///< pairs left for later: too close to a merge of this pass
    int refused_shared_vertex = 0;  ///< the two holes would share a vertex
    int refused_boundary = 0;       ///< a hole would touch an open boundary
    int refused_existing_edge = 0;  ///< the band would recreate an existing edge
    int refused_intersection = 0;   ///< every zipper alignment tried intersects or degenerates
    int refused_total() const {
        return refused_shared_vertex + refused_boundary + refused_existing_edge +
               refused_intersection;
    }
    double seconds = 0.0;
};

/// The hole left by removing the two triangles on an edge, as the loop of its four vertices in
/// the direction the removed triangles traversed them.
struct EdgeHole {
    std::array<int, 2> triangles{INVALID_INDEX, INVALID_INDEX};
    std::array<int, 4> loop{INVALID_INDEX, INVALID_INDEX, INVALID_INDEX, INVALID_INDEX};
};

/// The hole of edge ei (exactly two triangles, oppositely oriented), or false.
bool edge_hole(const SurfaceMesh& mesh, int ei, EdgeHole& hole);
/// True when an edge of either hole's loop has no triangle besides the removed one (boundary).
bool merge_touches_boundary(const SurfaceMesh& mesh, const EdgeHole& a, const EdgeHole& b);
/// True when the two loops share a vertex.
bool merge_shares_vertex(const EdgeHole& a, const EdgeHole& b);
/// The eight band triangles for alignment `shift` (0..3) of loop b against loop a.
std::vector<Triangle> zipper_triangles(const SurfaceMesh& mesh, const EdgeHole& a,
                                       const EdgeHole& b, int shift);
/// True when a band triangle's edge between the two loops already exists in the mesh.
bool merge_creates_existing_edge(const SurfaceMesh& mesh, const EdgeHole& a,
                                 const std::vector<Triangle>& band);
/// True when the band intersects the mesh without the four removed triangles, or itself.
bool merge_intersects(const SurfaceMesh& mesh, const ElementHash& hash, const EdgeHole& a,
                      const EdgeHole& b, const std::vector<Triangle>& band);

/// Finds edge pairs closer than merge_distance_fraction · xi and merges them nearest first,
/// deferring pairs within merge_spacing_fraction · xi of a merge made earlier in the pass.
/// With `collision_safety` off the intersection check is skipped. Does not separate: call
/// separate() afterwards (change_topology does).
MergeReport merge_proximal_edges(SurfaceMesh& mesh, const TopologyOptions& options,
                                 const TopologyContext& context);

}  // namespace meniscus::tracker
