#include "tracker/remesh/element_hash.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>

namespace meniscus::tracker {

Box3d triangle_box(const SurfaceMesh& mesh, int ti) {
    if (mesh.periodic()) {
        const std::array<Vec3, 3> p = mesh.triangle_positions(ti);
        Box3d b(p[0]);
        b.extend(p[1]);
        b.extend(p[2]);
        return b;
    }
    const Triangle& t = mesh.triangle(ti);
    Box3d b(mesh.position(t[0]));
    b.extend(mesh.position(t[1]));
    b.extend(mesh.position(t[2]));
    return b;
}

Box3d edge_box(const SurfaceMesh& mesh, int ei) {
    if (mesh.periodic()) {
        const std::array<Vec3, 2> p = mesh.edge_positions(ei);
        Box3d b(p[0]);
        b.extend(p[1]);
        return b;
    }
    const Edge& e = mesh.edge(ei);
    Box3d b(mesh.position(e[0]));
    b.extend(mesh.position(e[1]));
    return b;
}

void query_periodic(const SpatialHash& hash, const Box3d& stored_bounds, const MeshPeriods& periods,
                    const Box3d& box, std::vector<int>& out) {
    if (!periods.any()) {
        hash.query(box, out);
        return;
    }
    out.clear();
    if (stored_bounds.isEmpty() || box.isEmpty())
        return;
    // Per axis the whole-period shifts k with box + k L overlapping the stored boxes' union.
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = hi[a] = 0;
        if (!periods.wraps(a))
            continue;
        const double length = periods.length[a];
        lo[a] = static_cast<int>(std::ceil((stored_bounds.min()[a] - box.max()[a]) / length));
        hi[a] = static_cast<int>(std::floor((stored_bounds.max()[a] - box.min()[a]) / length));
    }
    thread_local std::vector<int> found;
    for (int i = lo[0]; i <= hi[0]; ++i)
        for (int j = lo[1]; j <= hi[1]; ++j)
            for (int k = lo[2]; k <= hi[2]; ++k) {
                const Vec3 shift(i * periods.length[0], j * periods.length[1],
                                 k * periods.length[2]);
                hash.query(Box3d(box.min() + shift, box.max() + shift), found);
                out.insert(out.end(), found.begin(), found.end());
            }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
}

ElementHash::ElementHash(const SurfaceMesh& mesh, double cell_size)
    : m_vertices(cell_size),
      m_edges(cell_size),
      m_triangles(cell_size),
      m_periods(mesh.periods()),
      m_periodic(mesh.periodic()) {
    // Three independent hashes, each filled in index order by one task: the same content
    // whatever the threading.
    tbb::parallel_invoke(
        [&] {
            for (int vi = 0; vi < mesh.num_vertices(); ++vi)
                if (mesh.vertex_alive(vi)) {
                    m_vertices.insert(vi, Box3d(mesh.position(vi)));
                    if (m_periodic)
                        m_vertex_bounds.extend(mesh.position(vi));
                }
        },
        [&] {
            for (int ei = 0; ei < mesh.num_edges(); ++ei)
                if (mesh.edge_alive(ei)) {
                    const Box3d b = edge_box(mesh, ei);
                    m_edges.insert(ei, b);
                    if (m_periodic)
                        m_edge_bounds.extend(b);
                }
        },
        [&] {
            for (int ti = 0; ti < mesh.num_triangles(); ++ti)
                if (mesh.triangle_alive(ti)) {
                    const Box3d b = triangle_box(mesh, ti);
                    m_triangles.insert(ti, b);
                    if (m_periodic)
                        m_triangle_bounds.extend(b);
                }
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
    if (!m_periodic) {
        m_vertices.insert(vi, Box3d(mesh.position(vi)));
        for (int ei : mesh.vertex_edges(vi))
            m_edges.insert(ei, edge_box(mesh, ei));
        for (int ti : mesh.vertex_triangles(vi))
            m_triangles.insert(ti, triangle_box(mesh, ti));
        return;
    }
    m_vertices.insert(vi, Box3d(mesh.position(vi)));
    m_vertex_bounds.extend(mesh.position(vi));
    for (int ei : mesh.vertex_edges(vi)) {
        const Box3d b = edge_box(mesh, ei);
        m_edges.insert(ei, b);
        m_edge_bounds.extend(b);
    }
    for (int ti : mesh.vertex_triangles(vi)) {
        const Box3d b = triangle_box(mesh, ti);
        m_triangles.insert(ti, b);
        m_triangle_bounds.extend(b);
    }
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

void ElementHash::query_vertices(const Box3d& box, std::vector<int>& out) const {
    if (m_periodic)
        query_periodic(m_vertices, m_vertex_bounds, m_periods, box, out);
    else
        m_vertices.query(box, out);
}

void ElementHash::query_edges(const Box3d& box, std::vector<int>& out) const {
    if (m_periodic)
        query_periodic(m_edges, m_edge_bounds, m_periods, box, out);
    else
        m_edges.query(box, out);
}

void ElementHash::query_triangles(const Box3d& box, std::vector<int>& out) const {
    if (m_periodic)
        query_periodic(m_triangles, m_triangle_bounds, m_periods, box, out);
    else
        m_triangles.query(box, out);
}

}  // namespace meniscus::tracker
