#include "tracker/isotropic_remesh.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace meniscus::tracker {

namespace {

constexpr double DEGREES_TO_RADIANS = M_PI / 180.0;
/// Minimum vertex valence kept on closed meshes (below it the mesh folds).
constexpr int MIN_VALENCE = 3;
/// Relative slack on the Delaunay angle test, so co-circular quads do not flip back and forth.
constexpr double DELAUNAY_SLACK = 1e-9;

// Periodic meshes (periods.h): every stencil is read at the images nearest one of its points,
// and every position computed here is wrapped back into the fundamental box before it is stored.

Vec3 triangle_normal(const SurfaceMesh& mesh, const Triangle& t) {
    const Vec3& a = mesh.position(t[0]);
    return (mesh.position_near(t[1], a) - a).cross(mesh.position_near(t[2], a) - a);
}

/// p as the mesh stores it: wrapped into the fundamental box of a periodic mesh.
Vec3 stored(const SurfaceMesh& mesh, const Vec3& p) {
    return mesh.periodic() ? mesh.periods().wrap(p) : p;
}

int valence(const SurfaceMesh& mesh, int vi) {
    return static_cast<int>(mesh.vertex_edges(vi).size());
}

bool is_manifold_interior_edge(const SurfaceMesh& mesh, int ei) {
    return mesh.edge_alive(ei) && mesh.edge_triangles(ei).size() == 2;
}

std::vector<int> one_ring(const SurfaceMesh& mesh, int vi) {
    std::vector<int> ring;
    for (int ei : mesh.vertex_edges(vi))
        ring.push_back(mesh.other_vertex(ei, vi));
    std::sort(ring.begin(), ring.end());
    return ring;
}

class Remesher {
public:
    Remesher(SurfaceMesh& mesh, const IsotropicRemeshOptions& o, const SurfaceProjection& project)
        : m_mesh(mesh),
          m_project(project),
          m_max_len(o.split_ratio * o.target_edge_length),
          m_min_len(o.collapse_ratio * o.target_edge_length),
          m_cos_max_turn(std::cos(o.max_normal_change_degrees * DEGREES_TO_RADIANS)) {}

    int split_long_edges() {
        int n = 0;
        for (int ei = 0; ei < m_mesh.num_edges(); ++ei) {
            if (!is_manifold_interior_edge(m_mesh, ei))
                continue;
            const Edge e = m_mesh.edge(ei);
            const Vec3 a = m_mesh.position(e[0]), b = m_mesh.position_near(e[1], a);
            if ((b - a).norm() <= m_max_len)
                continue;
            const int vi = m_mesh.split_edge(ei, stored(m_mesh, 0.5 * (a + b)));
            m_mesh.set_position(vi, stored(m_mesh, m_project(0.5 * (a + b))));
            ++n;
        }
        return n;
    }

    int collapse_short_edges() {
        int n = 0;
        for (int ei = 0; ei < m_mesh.num_edges(); ++ei) {
            if (!is_manifold_interior_edge(m_mesh, ei))
                continue;
            const Edge e = m_mesh.edge(ei);
            const Vec3& a = m_mesh.position(e[0]);
            if ((m_mesh.position_near(e[1], a) - a).norm() >= m_min_len)
                continue;
            if (try_collapse(ei))
                ++n;
        }
        return n;
    }

    int flip_edges() {
        int n = 0;
        const int edges_before = m_mesh.num_edges();  // new diagonals wait for the next sweep
        for (int ei = 0; ei < edges_before; ++ei) {
            if (!is_manifold_interior_edge(m_mesh, ei))
                continue;
            if (try_flip(ei))
                ++n;
        }
        return n;
    }

    void relax_tangentially() {
        std::vector<Vec3> next = m_mesh.positions();
        for (int vi = 0; vi < m_mesh.num_vertices(); ++vi) {
            if (!m_mesh.vertex_alive(vi) || m_mesh.vertex_triangles(vi).empty())
                continue;
            const Vec3 p = m_mesh.position(vi);
            Vec3 normal = Vec3::Zero(), centroid = Vec3::Zero();
            double area = 0.0;
            for (int ti : m_mesh.vertex_triangles(vi)) {
                const Triangle& t = m_mesh.triangle(ti);
                const Vec3 n = triangle_normal(m_mesh, t);
                const double a = n.norm();
                normal += n;
                centroid += a *
                            (m_mesh.position_near(t[0], p) + m_mesh.position_near(t[1], p) +
                             m_mesh.position_near(t[2], p)) /
                            3.0;
                area += a;
            }
            if (!(area > 0.0) || !(normal.norm() > 0.0))
                continue;
            normal.normalize();
            const Vec3 d = centroid / area - p;
            next[static_cast<size_t>(vi)] =
                stored(m_mesh, m_project(p + d - normal * normal.dot(d)));
        }
        m_mesh.set_positions(next);
    }

    void project_all() {
        for (int vi = 0; vi < m_mesh.num_vertices(); ++vi)
            if (m_mesh.vertex_alive(vi))
                m_mesh.set_position(vi, stored(m_mesh, m_project(m_mesh.position(vi))));
    }

private:
    /// True if moving vertices moved_a and moved_b to new_pos keeps every surviving triangle
    /// of `triangles` non-degenerate and within the allowed normal change.
    bool normals_stay_close(const std::vector<int>& triangles, int moved_a, int moved_b,
                            const Vec3& new_pos) const {
        for (int ti : triangles) {
            if (!m_mesh.triangle_alive(ti))
                continue;
            const Triangle& t = m_mesh.triangle(ti);
            const bool has_a = std::count(t.begin(), t.end(), moved_a) > 0;
            const bool has_b = std::count(t.begin(), t.end(), moved_b) > 0;
            if (has_a && has_b)
                continue;  // deleted by the collapse
            std::array<Vec3, 3> p;
            for (int k = 0; k < 3; ++k)
                p[k] = (t[k] == moved_a || t[k] == moved_b) ? new_pos
                                                            : m_mesh.position_near(t[k], new_pos);
            const Vec3 before = triangle_normal(m_mesh, t);
            const Vec3 after = (p[1] - p[0]).cross(p[2] - p[0]);
            const double nb = before.norm(), na = after.norm();
            if (!(na > 0.0))
                return false;
            if (nb > 0.0 && before.dot(after) < m_cos_max_turn * nb * na)
                return false;
        }
        return true;
    }

    bool try_collapse(int ei) {
        const Edge e = m_mesh.edge(ei);
        const int a = e[0], b = e[1];
        const auto& et = m_mesh.edge_triangles(ei);
        const int c = m_mesh.opposite_vertex(et[0], ei), d = m_mesh.opposite_vertex(et[1], ei);
        // Link condition: the one-rings of a and b share exactly the two opposite vertices.
        const std::vector<int> ra = one_ring(m_mesh, a), rb = one_ring(m_mesh, b);
        std::vector<int> common;
        std::set_intersection(ra.begin(), ra.end(), rb.begin(), rb.end(),
                              std::back_inserter(common));
        if (common.size() != 2 || c == d)
            return false;
        if (valence(m_mesh, c) <= MIN_VALENCE || valence(m_mesh, d) <= MIN_VALENCE)
            return false;
        if (valence(m_mesh, a) + valence(m_mesh, b) - 4 < MIN_VALENCE)
            return false;
        const Vec3& pa = m_mesh.position(a);
        const Vec3 target = m_project(0.5 * (pa + m_mesh.position_near(b, pa)));
        // Do not create long edges.
        for (const std::vector<int>* ring : {&ra, &rb})
            for (int vj : *ring)
                if (vj != a && vj != b &&
                    (m_mesh.position_near(vj, target) - target).norm() > m_max_len)
                    return false;
        std::vector<int> affected = m_mesh.vertex_triangles(a);
        affected.insert(affected.end(), m_mesh.vertex_triangles(b).begin(),
                        m_mesh.vertex_triangles(b).end());
        if (!normals_stay_close(affected, a, b, target))
            return false;
        m_mesh.collapse_edge(ei, a, stored(m_mesh, target), 0.5);
        return true;
    }

    bool try_flip(int ei) {
        const auto& et = m_mesh.edge_triangles(ei);
        int t0 = et[0], t1 = et[1];
        if (m_mesh.edge_orientation_in_triangle(t0, ei) ==
            m_mesh.edge_orientation_in_triangle(t1, ei))
            return false;
        if (m_mesh.edge_orientation_in_triangle(t0, ei) < 0)
            std::swap(t0, t1);
        // t0 = (a, b, c) traverses a→b, t1 = (b, a, d); the flip makes (c, a, d) and (d, b, c).
        const Edge e = m_mesh.edge(ei);
        const int a = e[0], b = e[1];
        const int c = m_mesh.opposite_vertex(t0, ei), d = m_mesh.opposite_vertex(t1, ei);
        if (c == d || m_mesh.find_edge(c, d) != INVALID_INDEX)
            return false;
        if (valence(m_mesh, a) <= MIN_VALENCE || valence(m_mesh, b) <= MIN_VALENCE)
            return false;
        const Vec3 pa = m_mesh.position(a), pb = m_mesh.position_near(b, pa),
                   pc = m_mesh.position_near(c, pa), pd = m_mesh.position_near(d, pa);
        // Delaunay criterion: flip when the angles opposite the edge sum to more than π.
        const auto angle = [](const Vec3& apex, const Vec3& p, const Vec3& q) {
            const Vec3 u = p - apex, v = q - apex;
            return std::atan2(u.cross(v).norm(), u.dot(v));
        };
        if (angle(pc, pa, pb) + angle(pd, pa, pb) <= M_PI * (1.0 + DELAUNAY_SLACK))
            return false;
        // The new triangles must be non-degenerate and agree in orientation with the old ones.
        const Vec3 n_old = triangle_normal(m_mesh, m_mesh.triangle(t0)).normalized() +
                           triangle_normal(m_mesh, m_mesh.triangle(t1)).normalized();
        for (const Vec3& n : {Vec3((pa - pc).cross(pd - pc)), Vec3((pb - pd).cross(pc - pd))}) {
            const double nn = n.norm();
            if (!(nn > 0.0) || n.dot(n_old) < m_cos_max_turn * nn * n_old.norm())
                return false;
        }
        m_mesh.flip_edge(ei, t0, t1);
        return true;
    }

    SurfaceMesh& m_mesh;
    const SurfaceProjection& m_project;
    double m_max_len, m_min_len, m_cos_max_turn;
};

}  // namespace

void IsotropicRemeshOptions::validate() const {
    if (!(target_edge_length > 0.0) || !std::isfinite(target_edge_length))
        throw std::invalid_argument("target_edge_length: expected a number > 0");
    if (iterations < 0)
        throw std::invalid_argument("iterations: expected an integer >= 0");
    if (smoothing_steps < 0)
        throw std::invalid_argument("smoothing_steps: expected an integer >= 0");
    if (!(split_ratio > 1.0))
        throw std::invalid_argument("split_ratio: expected a number > 1");
    if (!(collapse_ratio > 0.0 && collapse_ratio < 1.0))
        throw std::invalid_argument("collapse_ratio: expected a number in (0, 1)");
    if (!(max_normal_change_degrees > 0.0 && max_normal_change_degrees < 180.0))
        throw std::invalid_argument("max_normal_change_degrees: expected a number in (0, 180)");
}

IsotropicRemeshReport isotropic_remesh(SurfaceMesh& mesh, const IsotropicRemeshOptions& options,
                                       const SurfaceProjection& project) {
    options.validate();
    IsotropicRemeshReport report;
    Remesher remesher(mesh, options, project);
    for (int it = 0; it < options.iterations; ++it) {
        options.cancel.throw_if_requested("remeshing the initial surface");
        report.splits += remesher.split_long_edges();
        report.collapses += remesher.collapse_short_edges();
        mesh.compact();
        report.flips += remesher.flip_edges();
        for (int s = 0; s < options.smoothing_steps; ++s)
            remesher.relax_tangentially();
    }
    remesher.project_all();
    mesh.compact();
    return report;
}

}  // namespace meniscus::tracker
