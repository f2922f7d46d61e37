#pragma once
/// \file Static boxes of every live vertex, edge and triangle of a mesh in three spatial hashes,
/// kept current while local operations mutate the mesh (paper §3.5: each operation is checked
/// against the elements near it). Built once per pass; after each mutation the caller refreshes
/// the stars of the vertices it touched.

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

    const SpatialHash& vertices() const { return m_vertices; }
    const SpatialHash& edges() const { return m_edges; }
    const SpatialHash& triangles() const { return m_triangles; }

private:
    void insert_star(const SurfaceMesh& mesh, int vi);

    SpatialHash m_vertices, m_edges, m_triangles;
    std::vector<int> m_pending_vertices, m_pending_edges, m_pending_triangles;
};

/// Box of triangle ti at the mesh's positions.
Box3d triangle_box(const SurfaceMesh& mesh, int ti);
/// Box of edge ei at the mesh's positions.
Box3d edge_box(const SurfaceMesh& mesh, int ei);

}  // namespace meniscus::tracker
