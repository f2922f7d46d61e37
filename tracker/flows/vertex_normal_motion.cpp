#include "tracker/flows/vertex_normal_motion.h"

namespace meniscus::tracker {

std::vector<Vec3> vertex_normal_displacements(const SurfaceMesh& mesh, double speed, double dt) {
    std::vector<Vec3> displacements = area_weighted_vertex_normals(mesh);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        Vec3& d = displacements[static_cast<size_t>(vi)];
        d = mesh.vertex_alive(vi) ? Vec3(speed * dt * d) : Vec3::Zero();
    }
    return displacements;
}

}  // namespace meniscus::tracker
