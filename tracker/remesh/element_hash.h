#pragma once
/// \file Static boxes of every live vertex, edge and triangle of a mesh in three spatial hashes,
/// kept current while local operations mutate the mesh (paper §3.5: each operation is checked
/// against the elements near it). Built once per pass; after each mutation the caller refreshes
/// the stars of the vertices it touched.
///
/// Periodic meshes (issue 39): an element's box is built from its corners at the minimum image
/// (triangle_positions, edge_positions), so it lies near its first corner, inside or just past
/// the fundamental box. Queries come from a stencil unwrapped around one of its vertices, so
/// they too lie near the box, possibly past a face. Instead of inserting each box near a face
/// again at its images (whose reach would have to cover every query box, unknown when the
/// element is inserted), a query box is looked up at each of its images by whole periods that
/// can reach the union of the stored boxes (kept as they are inserted): the same pairs, found
/// from the query side. Found elements must then be read at the minimum image relative to the
/// query's reference (SurfaceMesh::position_near). Non-periodic meshes: one lookup, as before.

#include "tracker/broadphase.h"
#include "tracker/mesh.h"

#include <vector>

namespace meniscus::tracker {

/// Vertex, edge and triangle boxes at the mesh's current positions.
class ElementHash {
public:
    /// Hashes every live element; `cell_size` > 0 (metres), near the mean edge length.
    ElementHash(const SurfaceMesh& mesh, double cell_size);

    /// The elements a mutation may touch: call before mutating with the vertices involved,
    /// then `refresh()` after. Records their incident triangles and edges.
    void begin_update(const SurfaceMesh& mesh, const std::vector<int>& vertices);
    /// Drops the recorded elements that died and re-inserts the boxes of the given live
    /// vertices and all their incident edges and triangles (new or moved).
    void refresh(const SurfaceMesh& mesh, const std::vector<int>& vertices);

    /// Replace `out` with every live-at-insertion vertex, edge or triangle whose box overlaps
    /// `box` or, on a periodic mesh, one of its images by whole periods (sorted, each once).
    void query_vertices(const Box3d& box, std::vector<int>& out) const;
    void query_edges(const Box3d& box, std::vector<int>& out) const;
    void query_triangles(const Box3d& box, std::vector<int>& out) const;

private:
    void insert_star(const SurfaceMesh& mesh, int vi);

    SpatialHash m_vertices, m_edges, m_triangles;
    std::vector<int> m_pending_vertices, m_pending_edges, m_pending_triangles;
    MeshPeriods m_periods;
    bool m_periodic = false;
    /// Periodic meshes: the union of every box ever inserted per hash (never shrinks).
    Box3d m_vertex_bounds, m_edge_bounds, m_triangle_bounds;
};

/// Box of triangle ti at the mesh's positions (corners at the minimum image of the first).
Box3d triangle_box(const SurfaceMesh& mesh, int ti);
/// Box of edge ei at the mesh's positions (ends at the minimum image of the first).
Box3d edge_box(const SurfaceMesh& mesh, int ei);

/// `hash.query(box, out)` for boxes of a periodic mesh: also looks up every image of `box` by
/// whole periods along the wrapping axes of `periods` that can overlap `stored_bounds` (a box
/// holding every stored box); `out` sorted, each id once. Without a wrapping axis, one query.
void query_periodic(const SpatialHash& hash, const Box3d& stored_bounds, const MeshPeriods& periods,
                    const Box3d& box, std::vector<int>& out);

}  // namespace meniscus::tracker
