#include "tracker/remesh/butterfly.h"

namespace meniscus::tracker {

namespace {

/// The vertex across edge (u, v) from triangle `ti`, if that edge has exactly two triangles.
std::optional<int> vertex_across(const SurfaceMesh& mesh, int ti, int u, int v) {
    const int ei = mesh.find_edge(u, v);
    if (ei == INVALID_INDEX || mesh.edge_triangles(ei).size() != 2)
        return std::nullopt;
    const auto& et = mesh.edge_triangles(ei);
    const int other = et[0] == ti ? et[1] : et[0];
    return mesh.opposite_vertex(other, ei);
}

}  // namespace

Vec3 edge_midpoint(const SurfaceMesh& mesh, int ei) {
    const Edge& e = mesh.edge(ei);
    const Vec3& a = mesh.position(e[0]);
    return 0.5 * (a + mesh.position_near(e[1], a));
}

std::optional<Vec3> butterfly_point(const SurfaceMesh& mesh, int ei) {
    const auto& et = mesh.edge_triangles(ei);
    if (et.size() != 2)
        return std::nullopt;
    const Edge& e = mesh.edge(ei);
    const int p1 = e[0], p2 = e[1];
    // Periodic meshes: the stencil at its images nearest the edge's first vertex.
    const Vec3& reference = mesh.position(p1);
    Vec3 r_sum = Vec3::Zero();
    Vec3 q_sum = Vec3::Zero();
    for (int ti : et) {
        const int q = mesh.opposite_vertex(ti, ei);
        q_sum += mesh.position_near(q, reference);
        for (int p : {p1, p2}) {
            const std::optional<int> r = vertex_across(mesh, ti, p, q);
            if (!r)
                return std::nullopt;
            r_sum += mesh.position_near(*r, reference);
        }
    }
    constexpr double P_WEIGHT = 8.0, Q_WEIGHT = 2.0, R_WEIGHT = -1.0, NORMALIZER = 16.0;
    return (P_WEIGHT * (reference + mesh.position_near(p2, reference)) + Q_WEIGHT * q_sum +
            R_WEIGHT * r_sum) /
           NORMALIZER;
}

}  // namespace meniscus::tracker
