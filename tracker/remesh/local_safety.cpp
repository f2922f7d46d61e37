#include "tracker/remesh/local_safety.h"

#include "tracker/ccd.h"
#include "tracker/intersection.h"
#include "tracker/predicates.h"

#include <algorithm>
#include <array>

namespace meniscus::tracker {

namespace {

bool contains(const std::vector<int>& sorted, int value) {
    return std::binary_search(sorted.begin(), sorted.end(), value);
}

void sort_unique(std::vector<int>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
}

/// Positions at t0 and t1 and the identification of a pseudo-motion. On a periodic mesh every
/// vertex is read at its image nearest the first moving vertex (one reference for the whole
/// check), and an end position at its image nearest the vertex's start.
class MotionView {
public:
    MotionView(const SurfaceMesh& mesh, const PseudoMotion& motion)
        : m_mesh(mesh),
          m_motion(motion),
          m_periodic(mesh.periodic() && !motion.vertices.empty()),
          m_reference(m_periodic ? mesh.position(motion.vertices.front()) : Vec3::Zero()) {}
    Vec3 t0(int vi) const {
        return m_periodic ? m_mesh.position_near(vi, m_reference) : m_mesh.position(vi);
    }
    Vec3 t1(int vi) const {
        for (size_t k = 0; k < m_motion.vertices.size(); ++k)
            if (m_motion.vertices[k] == vi)
                return m_periodic ? m_mesh.periods().nearest_image(m_motion.x_t1[k], t0(vi))
                                  : m_motion.x_t1[k];
        return t0(vi);
    }
    int representative(int vi) const {
        return vi == m_motion.identified.second ? m_motion.identified.first : vi;
    }
    bool vertex_in_triangle(int vi, const Triangle& t) const {
        const int r = representative(vi);
        return r == representative(t[0]) || r == representative(t[1]) || r == representative(t[2]);
    }
    bool edges_share_vertex(const Edge& a, const Edge& b) const {
        const int a0 = representative(a[0]), a1 = representative(a[1]);
        const int b0 = representative(b[0]), b1 = representative(b[1]);
        return a0 == b0 || a0 == b1 || a1 == b0 || a1 == b1;
    }
    Box3d vertex_box(int vi) const {
        Box3d b(t0(vi));
        b.extend(t1(vi));
        return b;
    }
    Box3d triangle_box(const Triangle& t) const {
        Box3d b(t0(t[0]));
        for (int vi : t) {
            b.extend(t0(vi));
            b.extend(t1(vi));
        }
        return b;
    }
    Box3d edge_box(const Edge& e) const {
        Box3d b(t0(e[0]));
        for (int vi : e) {
            b.extend(t0(vi));
            b.extend(t1(vi));
        }
        return b;
    }
    bool point_triangle(int vi, const Triangle& t) const {
        return point_triangle_ccd(t0(vi), t0(t[0]), t0(t[1]), t0(t[2]), t1(vi), t1(t[0]), t1(t[1]),
                                  t1(t[2]));
    }
    bool edge_edge(const Edge& a, const Edge& b) const {
        return edge_edge_ccd(t0(a[0]), t0(a[1]), t0(b[0]), t0(b[1]), t1(a[0]), t1(a[1]), t1(b[0]),
                             t1(b[1]));
    }

private:
    const SurfaceMesh& m_mesh;
    const PseudoMotion& m_motion;
    const bool m_periodic;
    const Vec3 m_reference;
};

}  // namespace

bool pseudo_motion_collides(const SurfaceMesh& mesh, const ElementHash& hash,
                            const PseudoMotion& motion) {
    const MotionView view(mesh, motion);
    std::vector<int> moving = motion.vertices;
    sort_unique(moving);
    std::vector<int> moving_triangles, moving_edges;
    for (int vi : moving) {
        const auto& vt = mesh.vertex_triangles(vi);
        moving_triangles.insert(moving_triangles.end(), vt.begin(), vt.end());
        const auto& ve = mesh.vertex_edges(vi);
        moving_edges.insert(moving_edges.end(), ve.begin(), ve.end());
    }
    sort_unique(moving_triangles);
    sort_unique(moving_edges);

    std::vector<int> found;
    // Moving vertices against static triangles and against moving triangles.
    for (int vi : moving) {
        const Box3d box = view.vertex_box(vi);
        hash.query_triangles(box, found);
        for (int ti : found) {
            if (!mesh.triangle_alive(ti) || contains(moving_triangles, ti))
                continue;
            const Triangle& t = mesh.triangle(ti);
            if (!view.vertex_in_triangle(vi, t) && view.point_triangle(vi, t))
                return true;
        }
        for (int ti : moving_triangles) {
            const Triangle& t = mesh.triangle(ti);
            if (view.vertex_in_triangle(vi, t) || !box.intersects(view.triangle_box(t)))
                continue;
            if (view.point_triangle(vi, t))
                return true;
        }
    }
    // Static vertices against moving triangles.
    for (int ti : moving_triangles) {
        const Triangle& t = mesh.triangle(ti);
        hash.query_vertices(view.triangle_box(t), found);
        for (int vi : found) {
            if (!mesh.vertex_alive(vi) || contains(moving, vi) || view.vertex_in_triangle(vi, t))
                continue;
            if (view.point_triangle(vi, t))
                return true;
        }
    }
    // Moving edges against static and moving edges.
    for (size_t k = 0; k < moving_edges.size(); ++k) {
        const Edge& a = mesh.edge(moving_edges[k]);
        const Box3d box = view.edge_box(a);
        hash.query_edges(box, found);
        for (int ej : found) {
            if (!mesh.edge_alive(ej) || contains(moving_edges, ej))
                continue;
            const Edge& b = mesh.edge(ej);
            if (!view.edges_share_vertex(a, b) && view.edge_edge(a, b))
                return true;
        }
        for (size_t l = k + 1; l < moving_edges.size(); ++l) {
            const Edge& b = mesh.edge(moving_edges[l]);
            if (view.edges_share_vertex(a, b) || !box.intersects(view.edge_box(b)))
                continue;
            if (view.edge_edge(a, b))
                return true;
        }
    }
    return false;
}

bool candidate_triangles_intersect(const SurfaceMesh& mesh, const ElementHash& hash,
                                   const CandidateTriangles& candidates,
                                   const std::vector<int>& replaced) {
    auto raw_position = [&](int vi) -> const Vec3& {
        for (const auto& [index, p] : candidates.overrides)
            if (index == vi)
                return p;
        return mesh.position(vi);
    };
    // Periodic meshes: every vertex at its image nearest the first candidate's first corner
    // (one reference, so a vertex two triangles share is the same point in both).
    const bool periodic = mesh.periodic() && !candidates.triangles.empty();
    const Vec3 reference = periodic ? raw_position(candidates.triangles.front()[0]) : Vec3::Zero();
    auto position = [&](int vi) -> Vec3 {
        return periodic ? mesh.periods().nearest_image(raw_position(vi), reference)
                        : raw_position(vi);
    };
    auto corners = [&](const Triangle& t) {
        return std::array<Vec3, 3>{position(t[0]), position(t[1]), position(t[2])};
    };
    std::vector<int> ignored = replaced;
    sort_unique(ignored);
    std::vector<int> found;
    const auto& tris = candidates.triangles;
    for (size_t k = 0; k < tris.size(); ++k) {
        const std::array<Vec3, 3> p = corners(tris[k]);
        if (collinear3d(p[0], p[1], p[2]))
            return true;
        Box3d box(p[0]);
        box.extend(p[1]);
        box.extend(p[2]);
        hash.query_triangles(box, found);
        for (int ti : found) {
            if (!mesh.triangle_alive(ti) || contains(ignored, ti))
                continue;
            const Triangle& t = mesh.triangle(ti);
            if (triangles_intersect(p, tris[k], corners(t), t))
                return true;
        }
        for (size_t l = k + 1; l < tris.size(); ++l)
            if (triangles_intersect(p, tris[k], corners(tris[l]), tris[l]))
                return true;
    }
    return false;
}

}  // namespace meniscus::tracker
