#include "tracker/remesh/sizing.h"

#include "tracker/broadphase.h"
#include "tracker/distance.h"
#include "tracker/mesh_measures.h"
#include "tracker/remesh/element_hash.h"

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <utility>
#include <stdexcept>

namespace meniscus::tracker {

std::vector<double> vertex_turning_curvature(const SurfaceMesh& mesh) {
    return vertex_turning_curvature(mesh, area_weighted_vertex_normals(mesh));
}

std::vector<double> vertex_turning_curvature(const SurfaceMesh& mesh,
                                             const std::vector<Vec3>& normals, bool convex_only) {
    if (normals.size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument("vertex_turning_curvature: one normal per vertex needed");
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
            const Vec3 x = mesh.position_near(wi, mesh.position(vi)) - mesh.position(vi);
            const double length2 = x.squaredNorm();
            if (!(length2 > 0.0) || nw.isZero())
                continue;
            const Eigen::Vector2d d(x.dot(t1), x.dot(t2));
            const Vec3 dn3 = nw - n;
            const Eigen::Vector2d dn(dn3.dot(t1), dn3.dot(t2));
            dd += d * d.transpose() / length2;
            nd += dn * d.transpose() / length2;
            if (!convex_only || dn3.dot(x) > 0.0) {
                max_turning = std::max(
                    max_turning, std::atan2(n.cross(nw).norm(), n.dot(nw)) / std::sqrt(length2));
            }
        }
        // Well-posed when the neighbours span the tangent plane; else the largest turning.
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> spread(dd);
        if (spread.eigenvalues()(0) > 1e-3 * spread.eigenvalues()(1)) {
            const Eigen::Matrix2d shape = nd * dd.inverse();
            const Eigen::Matrix2d symmetric = 0.5 * (shape + shape.transpose());
            const Eigen::Vector2d k = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(
                                          symmetric, Eigen::EigenvaluesOnly)
                                          .eigenvalues();
            // Ascending eigenvalues: k(1) is the most convex direction.
            curvature[static_cast<size_t>(vi)] =
                convex_only ? std::max(k(1), 0.0) : std::max(std::abs(k(0)), std::abs(k(1)));
        } else {
            curvature[static_cast<size_t>(vi)] = max_turning;
        }
    }
    return curvature;
}

std::vector<double> vertex_facing_distance(const SurfaceMesh& mesh,
                                           const std::vector<Vec3>& normals,
                                           const std::vector<double>& radius) {
    const size_t n = static_cast<size_t>(mesh.num_vertices());
    if (normals.size() != n || radius.size() != n)
        throw std::invalid_argument("vertex_facing_distance: one normal and radius per vertex");
    std::vector<double> distance(n, std::numeric_limits<double>::infinity());
    if (std::none_of(radius.begin(), radius.end(), [](double r) { return r > 0.0; }))
        return distance;
    // Triangles by box, with their unit normals; hash cells as large as the mean box.
    std::vector<Vec3> triangle_normal(static_cast<size_t>(mesh.num_triangles()), Vec3::Zero());
    std::vector<Box3d> boxes(static_cast<size_t>(mesh.num_triangles()));
    double extent_sum = 0.0;
    int counted = 0;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        // Periodic meshes: the corners at the minimum image of the first.
        const auto [a, b, c] = mesh.triangle_positions(ti);
        const Vec3 normal = (b - a).cross(c - a);
        if (!(normal.squaredNorm() > 0.0))
            continue;
        triangle_normal[static_cast<size_t>(ti)] = normal.normalized();
        Box3d& box = boxes[static_cast<size_t>(ti)];
        box.extend(a);
        box.extend(b);
        box.extend(c);
        extent_sum += box.sizes().maxCoeff();
        ++counted;
    }
    if (counted == 0)
        return distance;
    const double mean_extent = extent_sum / counted;
    SpatialHash triangles(mean_extent);
    Box3d stored;  // union of the stored boxes, for the periodic images of a query
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        if (!triangle_normal[static_cast<size_t>(ti)].isZero()) {
            triangles.insert(ti, boxes[static_cast<size_t>(ti)]);
            stored.extend(boxes[static_cast<size_t>(ti)]);
        }
    const bool periodic = mesh.periodic();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<int> candidates;
        for (size_t vi = r.begin(); vi != r.end(); ++vi) {
            const Vec3& nv = normals[vi];
            if (!(radius[vi] > 0.0) || !mesh.vertex_alive(static_cast<int>(vi)) || nv.isZero())
                continue;
            const int v = static_cast<int>(vi);
            const Vec3& x = mesh.position(v);
            // Nearest facing triangle within `reach` (the box query finds every triangle at
            // distance ≤ reach); first within one mean triangle size, which usually settles it.
            const auto nearest = [&](double reach) {
                const Box3d query(x - Vec3::Constant(reach), x + Vec3::Constant(reach));
                if (periodic)
                    query_periodic(triangles, stored, mesh.periods(), query, candidates);
                else
                    triangles.query(query, candidates);
                double best = reach;
                bool found = false;
                for (int ti : candidates) {
                    // The box's distance bounds the triangle's from below (periodic meshes: the
                    // box may be at another image of the triangle than the one near x).
                    if (!periodic && triangles.box(ti).squaredExteriorDistance(x) > best * best)
                        continue;
                    const auto& t = mesh.triangle(ti);
                    if (t[0] == v || t[1] == v || t[2] == v ||
                        !(triangle_normal[static_cast<size_t>(ti)].dot(nv) < -0.5))
                        continue;
                    const double d = point_triangle_proximity(x, mesh.position_near(t[0], x),
                                                              mesh.position_near(t[1], x),
                                                              mesh.position_near(t[2], x))
                                         .distance;
                    if (d <= best) {
                        best = d;
                        found = true;
                    }
                }
                return found ? best : std::numeric_limits<double>::infinity();
            };
            const double first = std::min(mean_extent, radius[vi]);
            double d = nearest(first);
            if (!std::isfinite(d) && radius[vi] > first)
                d = nearest(radius[vi]);
            distance[vi] = d;
        }
    });
    return distance;
}

EdgeSizing::EdgeSizing(const SurfaceMesh& mesh, const RemeshOptions& options, double xi) {
    options.validate();
    if (!(xi > 0.0) || !std::isfinite(xi))
        throw std::invalid_argument("EdgeSizing: xi must be finite and > 0");
    m_limits = remesh_limits(options, xi);
    if (mesh.periodic()) {
        // Every element must stay much shorter than a period for the minimum image to be
        // unambiguous (periods.h): α is at most the smallest period over PERIOD_TO_EDGE_RATIO,
        // and β shrinks with it so that β/α keeps its ratio (splits and collapses never undo
        // each other).
        double period = std::numeric_limits<double>::infinity();
        for (int a = 0; a < 3; ++a)
            if (mesh.periods().wraps(a))
                period = std::min(period, mesh.periods().length[a]);
        const double bound = period / MeshPeriods::PERIOD_TO_EDGE_RATIO;
        if (m_limits.max_edge_length > bound) {
            m_limits.min_edge_length *= bound / m_limits.max_edge_length;
            m_limits.max_edge_length = bound;
        }
    }
    const double c = options.curvature_edge_fraction;
    const double f = options.thin_sheet_sag_fraction;
    if (c == 0.0 && f == 0.0)
        return;
    const std::vector<Vec3> normals = area_weighted_vertex_normals(mesh);
    const bool convex_sizing = c > 0.0 && options.curvature_sizing_convex_only;
    // The magnitude estimate feeds thin-sheet sizing and, unless convex-only, curvature sizing.
    std::vector<double> curvature;
    if (f > 0.0 || (c > 0.0 && !convex_sizing))
        curvature = vertex_turning_curvature(mesh, normals);
    const double alpha = m_limits.max_edge_length;
    const double floor = options.min_curvature_size_fraction;
    m_scale.assign(normals.size(), 1.0);
    if (c > 0.0) {
        const std::vector<double> sized =
            convex_sizing ? vertex_turning_curvature(mesh, normals, true) : std::vector<double>();
        const std::vector<double>& kappa = convex_sizing ? sized : curvature;
        for (size_t vi = 0; vi < kappa.size(); ++vi) {
            const double k = kappa[vi] * alpha;
            if (k > c)
                m_scale[vi] = std::max(floor, c / k);
        }
    }
    if (f > 0.0) {
        // Search as far as a facing triangle could still lower s: sag κα²/8 > f h.
        std::vector<double> radius(curvature.size(), 0.0);
        for (size_t vi = 0; vi < curvature.size(); ++vi)
            radius[vi] = std::min(alpha, curvature[vi] * alpha * alpha / (8.0 * f));
        const std::vector<double> h = vertex_facing_distance(mesh, normals, radius);
        for (size_t vi = 0; vi < curvature.size(); ++vi) {
            if (!std::isfinite(h[vi]) || !(curvature[vi] > 0.0))
                continue;
            const double s = std::sqrt(8.0 * f * h[vi] / curvature[vi]) / alpha;
            if (s < 1.0)
                m_scale[vi] = std::min(m_scale[vi], std::max(floor, s));
        }
    }
    grade(mesh);
}

void EdgeSizing::grade(const SurfaceMesh& mesh) {
    // Dijkstra over the edge graph on the target length H = s α: H_v ≤ H_w + g |x_v − x_w|.
    // H is kept apart from s so that the stale-entry test compares the very values queued.
    const double alpha = m_limits.max_edge_length;
    std::vector<double> target(m_scale.size());
    for (size_t vi = 0; vi < m_scale.size(); ++vi)
        target[vi] = m_scale[vi] * alpha;
    using Item = std::pair<double, int>;  // (H, vertex)
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
    for (size_t vi = 0; vi < m_scale.size(); ++vi)
        if (m_scale[vi] < 1.0 && mesh.vertex_alive(static_cast<int>(vi)))
            queue.emplace(target[vi], static_cast<int>(vi));
    while (!queue.empty()) {
        const auto [h, vi] = queue.top();
        queue.pop();
        if (h > target[static_cast<size_t>(vi)])
            continue;  // stale entry
        for (int ei : mesh.vertex_edges(vi)) {
            const int wi = mesh.other_vertex(ei, vi);
            const double reach =
                h + SIZE_GRADING *
                        (mesh.position_near(wi, mesh.position(vi)) - mesh.position(vi)).norm();
            if (reach < target[static_cast<size_t>(wi)]) {
                target[static_cast<size_t>(wi)] = reach;
                m_scale[static_cast<size_t>(wi)] = reach / alpha;
                queue.emplace(reach, wi);
            }
        }
    }
}

void EdgeSizing::inherit(const SurfaceMesh& mesh, int vi, int a, int b) {
    if (m_scale.empty() || vi < 0)
        return;
    // The graded field's bound at the new vertex: H ≤ H_w + g |x − x_w| for both endpoints.
    const auto of = [this](int w) {
        return w >= 0 && static_cast<size_t>(w) < m_scale.size() ? m_scale[static_cast<size_t>(w)]
                                                                  : 1.0;
    };
    const Vec3& x = mesh.position(vi);
    const double alpha = m_limits.max_edge_length;
    const double s = std::min(
        {1.0, of(a) + SIZE_GRADING * (x - mesh.position_near(a, x)).norm() / alpha,
         of(b) + SIZE_GRADING * (x - mesh.position_near(b, x)).norm() / alpha});
    if (static_cast<size_t>(vi) >= m_scale.size())
        m_scale.resize(static_cast<size_t>(vi) + 1, 1.0);
    m_scale[static_cast<size_t>(vi)] = s;
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
