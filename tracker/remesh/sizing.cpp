#include "tracker/remesh/sizing.h"

#include "tracker/mesh_measures.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace meniscus::tracker {

std::vector<double> vertex_turning_curvature(const SurfaceMesh& mesh) {
    const std::vector<Vec3> normals = area_weighted_vertex_normals(mesh);
    std::vector<double> curvature(static_cast<size_t>(mesh.num_vertices()), 0.0);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        const Vec3& n = normals[static_cast<size_t>(vi)];
        if (!mesh.vertex_alive(vi) || n.isZero())
            continue;
        // Tangent basis (t1, t2) of n; S (2×2) fits n_w − n_v ≈ S (x_w − x_v) in it, each
        // neighbour weighted by 1/|x_w − x_v|² so that every direction counts alike.
        const Vec3 t1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
        const Vec3 t2 = n.cross(t1);
        Eigen::Matrix2d dd = Eigen::Matrix2d::Zero();  // Σ w d dᵀ
        Eigen::Matrix2d nd = Eigen::Matrix2d::Zero();  // Σ w Δn dᵀ
        double max_turning = 0.0;
        for (int ei : mesh.vertex_edges(vi)) {
            const int wi = mesh.other_vertex(ei, vi);
            const Vec3& nw = normals[static_cast<size_t>(wi)];
            const Vec3 x = mesh.position(wi) - mesh.position(vi);
            const double length2 = x.squaredNorm();
            if (!(length2 > 0.0) || nw.isZero())
                continue;
            const Eigen::Vector2d d(x.dot(t1), x.dot(t2));
            const Vec3 dn3 = nw - n;
            const Eigen::Vector2d dn(dn3.dot(t1), dn3.dot(t2));
            dd += d * d.transpose() / length2;
            nd += dn * d.transpose() / length2;
            max_turning = std::max(max_turning, std::atan2(n.cross(nw).norm(), n.dot(nw)) /
                                                    std::sqrt(length2));
        }
        // Well-posed when the neighbours span the tangent plane; else the largest turning.
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> spread(dd);
        if (spread.eigenvalues()(0) > 1e-3 * spread.eigenvalues()(1)) {
            const Eigen::Matrix2d shape = nd * dd.inverse();
            const Eigen::Matrix2d symmetric = 0.5 * (shape + shape.transpose());
            const Eigen::Vector2d k = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(
                                          symmetric, Eigen::EigenvaluesOnly)
                                          .eigenvalues();
            curvature[static_cast<size_t>(vi)] = std::max(std::abs(k(0)), std::abs(k(1)));
        } else {
            curvature[static_cast<size_t>(vi)] = max_turning;
        }
    }
    return curvature;
}

EdgeSizing::EdgeSizing(const SurfaceMesh& mesh, const RemeshOptions& options, double xi) {
    options.validate();
    if (!(xi > 0.0) || !std::isfinite(xi))
        throw std::invalid_argument("EdgeSizing: xi must be finite and > 0");
    m_limits = remesh_limits(options, xi);
    if (options.curvature_edge_fraction == 0.0)
        return;
    const std::vector<double> curvature = vertex_turning_curvature(mesh);
    m_scale.resize(curvature.size());
    const double floor = options.min_curvature_size_fraction;
    for (size_t vi = 0; vi < curvature.size(); ++vi) {
        const double k = curvature[vi] * m_limits.max_edge_length;
        m_scale[vi] = k > options.curvature_edge_fraction
                          ? std::max(floor, options.curvature_edge_fraction / k)
                          : 1.0;
    }
}

double EdgeSizing::scale(int a, int b) const {
    const auto of = [this](int vi) {
        return vi >= 0 && static_cast<size_t>(vi) < m_scale.size()
                   ? m_scale[static_cast<size_t>(vi)]
                   : 1.0;
    };
    return std::min(of(a), of(b));
}

}  // namespace meniscus::tracker
