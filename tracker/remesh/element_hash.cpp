#include "tracker/remesh/element_hash.h"

#include <tbb/parallel_invoke.h>

namespace meniscus::tracker {

Box3d triangle_box(const SurfaceMesh& mesh, int ti) {
    const Triangle& t = mesh.triangle(ti);
    Box3d b(mesh.position(t[0]));
    b.extend(mesh.position(t[1]));
    b.extend(mesh.position(t[2]));
    return b;
}

Box3d edge_box(const SurfaceMesh& mesh, int ei) {
    const Edge& e = mesh.edge(ei);
    Box3d b(mesh.position(e[0]));
    b.extend(mesh.position(e[1]));
    return b;
}

ElementHash::ElementHash(const SurfaceMesh& mesh, double cell_size)
    : m_vertices(cell_size), m_edges(cell_size), m_triangles(cell_size) {
    // Three independent hashes, each filled in index order by one task: the same content
    // whatever the threading.
    tbb::parallel_invoke(
        [&] {
            for (int vi = 0; vi < mesh.num_vertices(); ++vi)
                if (mesh.vertex_alive(vi))
                    m_vertices.insert(vi, Box3d(mesh.position(vi)));
        },
        [&] {
            for (int ei = 0; ei < mesh.num_edges(); ++ei)
                if (mesh.edge_alive(ei))
                    m_edges.insert(ei, edge_box(mesh, ei));
        },
        [&] {
            for (int ti = 0; ti < mesh.num_triangles(); ++ti)
                if (mesh.triangle_alive(ti))
                    m_triangles.insert(ti, triangle_box(mesh, ti));
        });
}

void ElementHash::begin_update(const SurfaceMesh& mesh, const std::vector<int>& vertices) {
    for (int vi : vertices) {
        if (!mesh.vertex_alive(vi))
            continue;
        m_pending_vertices.push_back(vi);
        const auto& ve = mesh.vertex_edges(vi);
        m_pending_edges.insert(m_pending_edges.end(), ve.begin(), ve.end());
        const auto& vt = mesh.vertex_triangles(vi);
        m_pending_triangles.insert(m_pending_triangles.end(), vt.begin(), vt.end());
    }
}

void ElementHash::insert_star(const SurfaceMesh& mesh, int vi) {
    m_vertices.insert(vi, Box3d(mesh.position(vi)));
    for (int ei : mesh.vertex_edges(vi))
        m_edges.insert(ei, edge_box(mesh, ei));
    for (int ti : mesh.vertex_triangles(vi))
        m_triangles.insert(ti, triangle_box(mesh, ti));
}

void ElementHash::refresh(const SurfaceMesh& mesh, const std::vector<int>& vertices) {
    for (int vi : m_pending_vertices)
        if (!mesh.vertex_alive(vi))
            m_vertices.remove(vi);
    for (int ei : m_pending_edges)
        if (!mesh.edge_alive(ei))
            m_edges.remove(ei);
    for (int ti : m_pending_triangles)
        if (!mesh.triangle_alive(ti))
            m_triangles.remove(ti);
    m_pending_vertices.clear();
    m_pending_edges.clear();
    m_pending_triangles.clear();
    for (int vi : vertices)
        if (mesh.vertex_alive(vi))
            insert_star(mesh, vi);
}

}  // namespace meniscus::tracker
