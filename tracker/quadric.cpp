#include "tracker/quadric.h"

#include <Eigen/Eigenvalues>

#include <array>

namespace meniscus::tracker {

Eigen::Matrix3d VertexQuadric::null_space_projector() const {
    switch (feature) {
        case VertexFeature::smooth: {
            const Eigen::Vector3d e1 = eigenvectors.col(0);
            return Eigen::Matrix3d::Identity() - e1 * e1.transpose();
        }
        case VertexFeature::ridge: {
            const Eigen::Vector3d e3 = eigenvectors.col(2);
            return e3 * e3.transpose();
        }
        case VertexFeature::corner:
            break;
    }
    return Eigen::Matrix3d::Zero();
}

VertexQuadric vertex_quadric(const SurfaceMesh& mesh, int vi, const FeatureThresholds& thresholds) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    double total_weight = 0.0;
    for (int ti : mesh.vertex_triangles(vi)) {
        // Periodic meshes: corners at the minimum image of the first (normals need no more).
        const std::array<Vec3, 3> p = mesh.triangle_positions(ti);
        const Vec3 n = (p[1] - p[0]).cross(p[2] - p[0]);
        const double twice_area = n.norm();
        if (!(twice_area > 0.0))
            continue;
        // Area weight times unit normal outer product: n nᵀ / |n| = (|n|/1) n̂ n̂ᵀ.
        a += n * n.transpose() / twice_area;
        total_weight += twice_area;
    }
    VertexQuadric q;
    if (!(total_weight > 0.0))
        return q;  // corner: no usable normal
    a /= total_weight;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(a);
    // Eigen sorts ascending; we want descending.
    for (int k = 0; k < 3; ++k) {
        q.eigenvalues[k] = std::max(0.0, solver.eigenvalues()[2 - k]);
        q.eigenvectors.col(k) = solver.eigenvectors().col(2 - k);
    }
    const double l1 = q.eigenvalues[0];
    if (q.eigenvalues[2] >= thresholds.corner_eigenvalue_ratio * l1)
        q.feature = VertexFeature::corner;
    else if (q.eigenvalues[1] >= thresholds.ridge_eigenvalue_ratio * l1)
        q.feature = VertexFeature::ridge;
    else
        q.feature = VertexFeature::smooth;
    return q;
}

}  // namespace meniscus::tracker
