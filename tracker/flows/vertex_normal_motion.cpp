#include "tracker/flows/vertex_normal_motion.h"

namespace meniscus::tracker {

std::vector<Vec3> area_weighted_vertex_normals(const SurfaceMesh& mesh) {
    std::vector<Vec3> normals(static_cast<size_t>(mesh.num_vertices()), Vec3::Zero());
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        const Vec3& a = mesh.position(t[0]);
        const Vec3 area_vector = (mesh.position(t[1]) - a).cross(mesh.position(t[2]) - a);
        for (int vi : t)
            normals[static_cast<size_t>(vi)] += area_vector;
    }
    for (Vec3& n : normals) {
        const double length = n.norm();
        n = length > 0.0 ? Vec3(n / length) : Vec3::Zero();
    }
    return normals;
}

std::vector<Vec3> vertex_normal_displacements(const SurfaceMesh& mesh, double speed, double dt) {
    std::vector<Vec3> displacements = area_weighted_vertex_normals(mesh);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        Vec3& d = displacements[static_cast<size_t>(vi)];
        d = mesh.vertex_alive(vi) ? Vec3(speed * dt * d) : Vec3::Zero();
    }
    return displacements;
}

}  // namespace meniscus::tracker
