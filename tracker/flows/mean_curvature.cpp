#include "tracker/flows/mean_curvature.h"

#include "tracker/flows/vertex_normal_motion.h"
#include "tracker/mesh_measures.h"
#include "tracker/remesh/surface_fit.h"

#include <tbb/parallel_for.h>

#include <array>
#include <atomic>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

namespace {

/// cot of the angle between u and v. A degenerate corner (|u × v| = 0) contributes nothing.
double cotangent(const Vec3& u, const Vec3& v) {
    const double sine = u.cross(v).norm();
    return sine > 0.0 ? u.dot(v) / sine : 0.0;
}

/// Per-triangle cotangent accumulation and mixed areas for every vertex slot.
struct CotangentSums {
    std::vector<Vec3> laplacian_sum;  ///< Σⱼ (cot αᵢⱼ + cot βᵢⱼ)(xᵢ − xⱼ) per vertex
    std::vector<double> mixed_area;
};

/// With the vertices at `position(v)` (the mesh's own positions, or predicted ones).
template <typename Position>
CotangentSums accumulate(const SurfaceMesh& mesh, const Position& position) {
    const size_t nv = static_cast<size_t>(mesh.num_vertices());
    CotangentSums sums{std::vector<Vec3>(nv, Vec3::Zero()), std::vector<double>(nv, 0.0)};
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        std::array<Vec3, 3> p = {position(t[0]), position(t[1]), position(t[2])};
        if (mesh.periodic()) {
            // The minimum image about the first corner: every quantity below (edge vectors,
            // cotangents, areas) is translation invariant, so each vertex's sum over its one-ring
            // is the one of the one-ring unwrapped about it. `position` may be unwrapped
            // (Heun's predictor), hence the periods rather than position_near().
            p[1] = mesh.periods().nearest_image(p[1], p[0]);
            p[2] = mesh.periods().nearest_image(p[2], p[0]);
        }
        const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
        std::array<double, 3> cot{};
        int obtuse_corner = -1;
        for (int k = 0; k < 3; ++k) {
            const Vec3 u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
            cot[static_cast<size_t>(k)] = cotangent(u, v);
            if (u.dot(v) < 0.0)
                obtuse_corner = k;
        }
        for (int k = 0; k < 3; ++k) {
            // Edge (i, j) opposite corner k, weighted by cot of that corner.
            const int i = (k + 1) % 3, j = (k + 2) % 3;
            const Vec3 e = p[static_cast<size_t>(i)] - p[static_cast<size_t>(j)];
            const double w = cot[static_cast<size_t>(k)];
            sums.laplacian_sum[static_cast<size_t>(t[static_cast<size_t>(i)])] += w * e;
            sums.laplacian_sum[static_cast<size_t>(t[static_cast<size_t>(j)])] -= w * e;
        }
        for (int k = 0; k < 3; ++k) {
            double a;
            if (obtuse_corner < 0) {
                // Voronoi area at corner k: (1/8)(|e_ki|² cot j + |e_kj|² cot i).
                const int i = (k + 1) % 3, j = (k + 2) % 3;
                const double len_ki =
                    (p[static_cast<size_t>(i)] - p[static_cast<size_t>(k)]).squaredNorm();
                const double len_kj =
                    (p[static_cast<size_t>(j)] - p[static_cast<size_t>(k)]).squaredNorm();
                a = 0.125 *
                    (len_ki * cot[static_cast<size_t>(j)] + len_kj * cot[static_cast<size_t>(i)]);
            } else {
                a = k == obtuse_corner ? 0.5 * area : 0.25 * area;
            }
            sums.mixed_area[static_cast<size_t>(t[static_cast<size_t>(k)])] += a;
        }
    }
    return sums;
}

auto mesh_positions(const SurfaceMesh& mesh) {
    return [&mesh](int v) -> const Vec3& { return mesh.position(v); };
}

/// Vertices fitted per task of fitted_mean_curvature_normals(): a fit takes a few µs.
constexpr int FIT_GRAIN = 256;
/// The quartic needs 15 coefficients: degree 4 of SurfaceFitOptions.
constexpr int QUARTIC_DEGREE = 4;
/// A vertex whose two-ring has too few vertices for the quartic (vertex_patch() fits a
/// degree only where more vertices than its unknowns constrain it: a valence-4 vertex has 14
/// others for the quartic's 14) gets the cubic through it with the same refit. The quartic
/// interpolating such a two-ring made the explicit step unstable: on the A2 dumbbell at
/// ξ = 0.01 one such vertex had Σⱼ |∂κ/∂hⱼ| · Δt = 12.7 at the CFL step (every other vertex
/// ≤ 1.02), and its height oscillated, growing 1.7 times per step, to 1.3e-4 off the surface.
/// The cotangent K there would err by several percent (5.9 % on the spheroid of
/// QuarticFitCurvatureConvergesPointwiseOnASpheroid; the cubic 0.11 %).
constexpr int CUBIC_DEGREE = 3;

/// K = (1 / 2A) Σ (cot α + cot β)(xᵢ − xⱼ) per vertex from the accumulated sums.
std::vector<Vec3> curvature_normals(const SurfaceMesh& mesh, const CotangentSums& sums) {
    std::vector<Vec3> k(static_cast<size_t>(mesh.num_vertices()), Vec3::Zero());
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        const size_t i = static_cast<size_t>(vi);
        if (!mesh.vertex_alive(vi) || !(sums.mixed_area[i] > 0.0) || mesh.is_boundary_vertex(vi))
            continue;
        // The per-triangle sum holds Σ cot·(xᵢ − xⱼ).
        k[i] = sums.laplacian_sum[i] / (2.0 * sums.mixed_area[i]);
    }
    return k;
}

}  // namespace

std::vector<double> mixed_voronoi_areas(const SurfaceMesh& mesh) {
    return accumulate(mesh, mesh_positions(mesh)).mixed_area;
}

std::vector<Vec3> mean_curvature_normals(const SurfaceMesh& mesh) {
    return curvature_normals(mesh, accumulate(mesh, mesh_positions(mesh)));
}

std::vector<double> mean_curvatures(const SurfaceMesh& mesh) {
    const std::vector<Vec3> k = mean_curvature_normals(mesh);
    const std::vector<Vec3> n = area_weighted_vertex_normals(mesh);
    std::vector<double> kappa(k.size(), 0.0);
    for (size_t i = 0; i < k.size(); ++i)
        kappa[i] = k[i].dot(n[i]);
    return kappa;
}

std::vector<Vec3> fitted_mean_curvature_normals(const SurfaceMesh& mesh, double max_turn,
                                                const std::vector<Vec3>* positions, int* fallbacks,
                                                bool sphere_refit) {
    if (!(max_turn > 0.0))
        throw std::invalid_argument("max_turn: expected a number > 0 (radians), got " +
                                    std::to_string(max_turn));
    if (positions && positions->size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument("positions: expected one per vertex slot");
    std::vector<Vec3> k =
        positions
            ? curvature_normals(mesh, accumulate(mesh,
                                                 [positions](int v) -> const Vec3& {
                                                     return (*positions)[static_cast<size_t>(v)];
                                                 }))
            : mean_curvature_normals(mesh);
    SurfaceFitOptions fit;
    fit.degree = QUARTIC_DEGREE;
    fit.through_origin = true;  // the vertex is on the surface; its curvature is wanted
    fit.sphere_refit = sphere_refit;
    std::atomic<int> cotangent{0};
    tbb::parallel_for(
        tbb::blocked_range<int>(0, mesh.num_vertices(), FIT_GRAIN),
        [&](const tbb::blocked_range<int>& range) {
            int local = 0;
            for (int vi = range.begin(); vi < range.end(); ++vi) {
                if (!mesh.vertex_alive(vi) || mesh.vertex_triangles(vi).empty() ||
                    mesh.is_boundary_vertex(vi))
                    continue;
                const std::optional<SurfacePatch> patch =
                    positions ? vertex_patch(mesh, *positions, vi, fit)
                              : vertex_patch(mesh, vi, fit);
                if (patch && patch->degree >= CUBIC_DEGREE && patch->turn() <= max_turn)
                    k[static_cast<size_t>(vi)] = patch->mean_curvature() * patch->surface_normal();
                else
                    ++local;
            }
            cotangent += local;
        });
    if (fallbacks)
        *fallbacks = cotangent;
    return k;
}

void MeanCurvatureFlowOptions::validate() const {
    if (!(cfl_number > 0.0 && cfl_number <= 1.0))
        throw std::invalid_argument("cfl_number: expected a number in (0, 1], got " +
                                    std::to_string(cfl_number));
    if (!(fit_max_turn > 0.0))
        throw std::invalid_argument("fit_max_turn: expected a number > 0 (radians), got " +
                                    std::to_string(fit_max_turn));
}

double mean_curvature_time_step(const SurfaceMesh& mesh, const MeanCurvatureFlowOptions& options) {
    options.validate();
    const EdgeLengthStats stats = edge_length_stats(mesh);
    if (stats.count == 0)
        throw std::invalid_argument("mesh: expected at least one live edge");
    return options.cfl_number * stats.min * stats.min;
}

std::vector<Vec3> mean_curvature_displacements(const SurfaceMesh& mesh, double dt) {
    std::vector<Vec3> d = mean_curvature_normals(mesh);
    for (Vec3& v : d)
        v *= -dt;
    return d;
}

std::vector<Vec3> mean_curvature_displacements(const SurfaceMesh& mesh, double dt,
                                               const MeanCurvatureFlowOptions& options) {
    options.validate();
    if (options.curvature_operator == CurvatureOperator::cotangent)
        return mean_curvature_displacements(mesh, dt, options.integrator);
    std::vector<Vec3> d = fitted_mean_curvature_normals(mesh, options.fit_max_turn, nullptr,
                                                        nullptr, options.fit_sphere_refit);
    for (Vec3& v : d)
        v *= -dt;
    if (options.integrator == MeanCurvatureIntegrator::forward_euler)
        return d;
    std::vector<Vec3> predicted(d.size(), Vec3::Zero());
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            predicted[static_cast<size_t>(vi)] = mesh.position(vi) + d[static_cast<size_t>(vi)];
    const std::vector<Vec3> k = fitted_mean_curvature_normals(
        mesh, options.fit_max_turn, &predicted, nullptr, options.fit_sphere_refit);
    for (size_t i = 0; i < d.size(); ++i)
        d[i] = 0.5 * (d[i] - dt * k[i]);
    return d;
}

std::vector<Vec3> mean_curvature_displacements(const SurfaceMesh& mesh, double dt,
                                               MeanCurvatureIntegrator integrator) {
    std::vector<Vec3> d = mean_curvature_displacements(mesh, dt);
    if (integrator == MeanCurvatureIntegrator::forward_euler)
        return d;
    // K at the predicted positions x − dt K(x), on the same connectivity.
    const auto predicted = [&mesh, &d](int v) -> Vec3 {
        return mesh.position(v) + d[static_cast<size_t>(v)];
    };
    const std::vector<Vec3> k = curvature_normals(mesh, accumulate(mesh, predicted));
    for (size_t i = 0; i < d.size(); ++i)
        d[i] = 0.5 * (d[i] - dt * k[i]);
    return d;
}

}  // namespace meniscus::tracker
