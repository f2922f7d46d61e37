#include "coupling/surface_tension.h"

#include "tracker/distance.h"
#include "tracker/flows/mean_curvature.h"
#include "tracker/mesh_measures.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace meniscus::coupling {

namespace {

using tracker::SurfaceMesh;
using tracker::Vec3;

/// Upper bound of SurfaceTensionOptions::subgrid_rate: D Δt ≤ β h² stays below the explicit
/// cotangent Laplacian's stability limit (about h²/3 on an equilateral mesh) with room for
/// irregular triangles.
constexpr double MAX_SUBGRID_RATE = 0.2;
/// Upper bound of SurfaceTensionOptions::subgrid_filter_order (beyond 3 the filter is as sharp
/// as its smoothing stencil allows and only costs passes).
constexpr int MAX_SUBGRID_FILTER_ORDER = 3;

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// +1 if the liquid lies behind the triangles of vertex vi (their normals point out of the
/// liquid), −1 if it lies in front; decided by the first incident live triangle that has the
/// liquid on exactly one side (+1 when none has).
double liquid_orientation(const SurfaceMesh& mesh, int vi, int liquid_region) {
    for (int ti : mesh.vertex_triangles(vi)) {
        if (!mesh.triangle_alive(ti))
            continue;
        const tracker::LabelPair& labels = mesh.labels(ti);
        const bool inside = labels.inside == liquid_region;
        const bool outside = labels.outside == liquid_region;
        if (inside != outside)
            return inside ? 1.0 : -1.0;
    }
    return 1.0;
}

/// κ at the point of live triangle ti closest to x, interpolated barycentrically; `distance`
/// receives |x − that point|.
double curvature_at_closest_point(const SurfaceMesh& mesh, const std::vector<double>& kappa, int ti,
                                  const Vec3& x, double& distance) {
    const tracker::Triangle& t = mesh.triangle(ti);
    const tracker::PointTriangleProximity proximity = tracker::point_triangle_proximity(
        x, mesh.position_near(t[0], x), mesh.position_near(t[1], x), mesh.position_near(t[2], x));
    distance = proximity.distance;
    return proximity.barycentric[0] * kappa[static_cast<size_t>(t[0])] +
           proximity.barycentric[1] * kappa[static_cast<size_t>(t[1])] +
           proximity.barycentric[2] * kappa[static_cast<size_t>(t[2])];
}

/// Subtracts from `velocities` a uniform normal speed per connected component so that each
/// component's enclosed volume has zero rate of change: dV/dt = Σ_v u_v · G_v with G_v = ⅓ Σ of
/// the area vectors of v's triangles (∇_v V of a closed mesh).
void remove_volume_change(const SurfaceMesh& mesh, std::vector<Vec3>& velocities,
                          const std::vector<char>& active) {
    const auto is_active = [&](size_t v) { return active.empty() || active[v] != 0; };
    const tracker::Components components = tracker::triangle_components(mesh);
    std::vector<Vec3> gradient(velocities.size(), Vec3::Zero());
    std::vector<int> vertex_component(velocities.size(), tracker::INVALID_INDEX);
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const tracker::Triangle& t = mesh.triangle(ti);
        const std::array<Vec3, 3> x = mesh.triangle_positions(ti);  // minimum image
        const Vec3 area_vector = 0.5 * (x[1] - x[0]).cross(x[2] - x[0]);
        for (int vi : t) {
            gradient[static_cast<size_t>(vi)] += area_vector / 3.0;
            vertex_component[static_cast<size_t>(vi)] =
                components.triangle_component[static_cast<size_t>(ti)];
        }
    }
    std::vector<double> rate(static_cast<size_t>(components.count), 0.0);
    std::vector<double> weight(static_cast<size_t>(components.count), 0.0);
    for (size_t v = 0; v < velocities.size(); ++v) {
        if (vertex_component[v] == tracker::INVALID_INDEX || !is_active(v))
            continue;
        rate[static_cast<size_t>(vertex_component[v])] += velocities[v].dot(gradient[v]);
        weight[static_cast<size_t>(vertex_component[v])] += gradient[v].norm();
    }
    for (size_t v = 0; v < velocities.size(); ++v) {
        const int c = vertex_component[v];
        const double norm = gradient[v].norm();
        if (c == tracker::INVALID_INDEX || !is_active(v) || norm == 0.0 ||
            weight[static_cast<size_t>(c)] == 0.0)
            continue;
        velocities[v] -=
            (rate[static_cast<size_t>(c)] / weight[static_cast<size_t>(c)]) * gradient[v] / norm;
    }
}

/// Per-face tallies of one velocity component's faces, reduced after the parallel loop.
struct AxisTally {
    long long crossed = 0;
    long long without_triangle = 0;
    long long limited = 0;
    double min_kappa = std::numeric_limits<double>::infinity();
    double max_kappa = -std::numeric_limits<double>::infinity();
};

}  // namespace

void SurfaceTensionOptions::validate() const {
    if (smoothing_passes < 0)
        throw std::invalid_argument("smoothing_passes: expected an integer >= 0, got " +
                                    std::to_string(smoothing_passes));
    if (!(subgrid_rate >= 0.0 && subgrid_rate <= MAX_SUBGRID_RATE))
        throw std::invalid_argument("subgrid_rate: expected a number in [0, " +
                                    std::to_string(MAX_SUBGRID_RATE) + "], got " +
                                    std::to_string(subgrid_rate));
    if (subgrid_resolved_passes < 1)
        throw std::invalid_argument("subgrid_resolved_passes: expected an integer >= 1, got " +
                                    std::to_string(subgrid_resolved_passes));
    if (subgrid_filter_order < 1 || subgrid_filter_order > MAX_SUBGRID_FILTER_ORDER)
        throw std::invalid_argument("subgrid_filter_order: expected an integer in [1, " +
                                    std::to_string(MAX_SUBGRID_FILTER_ORDER) + "], got " +
                                    std::to_string(subgrid_filter_order));
    if (!(max_curvature_cells > 0.0) || !std::isfinite(max_curvature_cells))
        throw std::invalid_argument("max_curvature_cells: expected a positive number, got " +
                                    std::to_string(max_curvature_cells));
}

std::vector<tracker::Vec3> subgrid_tension_velocities(const tracker::SurfaceMesh& mesh,
                                                      double diffusivity, int resolved_passes,
                                                      int filter_order,
                                                      const std::vector<char>& active) {
    if (!(diffusivity >= 0.0))
        throw std::invalid_argument("subgrid_tension_velocities: diffusivity must be >= 0");
    if (resolved_passes < 1)
        throw std::invalid_argument("subgrid_tension_velocities: resolved_passes must be >= 1");
    if (filter_order < 1 || filter_order > MAX_SUBGRID_FILTER_ORDER)
        throw std::invalid_argument("subgrid_tension_velocities: filter_order must be in [1, " +
                                    std::to_string(MAX_SUBGRID_FILTER_ORDER) + "]");
    if (!active.empty() && active.size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument(
            "subgrid_tension_velocities: active must be empty or sized num_vertices()");
    const std::vector<Vec3> curvature_normal = tracker::mean_curvature_normals(mesh);
    std::vector<Vec3> velocities(curvature_normal.size(), Vec3::Zero());
    if (diffusivity == 0.0)
        return velocities;
    std::vector<double> component(curvature_normal.size());
    for (int axis = 0; axis < 3; ++axis) {
        for (size_t v = 0; v < component.size(); ++v)
            component[v] = curvature_normal[v][axis];
        // (I − S)^order K: each application removes what S keeps.
        for (int order = 0; order < filter_order; ++order) {
            const std::vector<double> resolved =
                smooth_vertex_values(mesh, component, resolved_passes);
            for (size_t v = 0; v < component.size(); ++v)
                component[v] -= resolved[v];
        }
        for (size_t v = 0; v < component.size(); ++v)
            velocities[v][axis] = active.empty() || active[v] ? -diffusivity * component[v] : 0.0;
    }
    remove_volume_change(mesh, velocities, active);
    return velocities;
}

std::vector<double> smooth_vertex_values(const tracker::SurfaceMesh& mesh,
                                         std::vector<double> values, int passes) {
    if (passes < 0)
        throw std::invalid_argument("smooth_vertex_values: passes must be >= 0");
    if (values.size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument("smooth_vertex_values: expected one value per vertex");
    if (passes == 0)
        return values;
    // Lazy passes, x_v <- (x_v + neighbour mean)/2, not the closed one-ring mean
    // (a_v x_v + sum a_w x_w)/(a_v + sum a_w): the latter keeps only ~1/7 of the vertex itself,
    // so its transfer function is 1 - (6/7) lambda with lambda up to ~1.5 on a triangle mesh,
    // i.e. about -0.27 for the roughest (mesh-scale) pattern. An odd number of such passes
    // reverses the sign of the curvature of mesh-scale wrinkles, turning the capillary force on
    // them from restoring into driving: a moving interface wrinkles and blows up (oscillating
    // drop, scenes/oscillating_drop.json). The neighbour mean is a convex combination, so its
    // eigenvalues lie in [-1, 1] and a lazy pass's in [0, 1]: every pattern keeps its sign.
    const std::vector<double> area = tracker::mixed_voronoi_areas(mesh);
    std::vector<double> smoothed(values.size(), 0.0);
    for (int pass = 0; pass < passes; ++pass) {
        tbb::parallel_for(0, mesh.num_vertices(), [&](int vi) {
            const size_t v = static_cast<size_t>(vi);
            smoothed[v] = values[v];
            if (!mesh.vertex_alive(vi) || mesh.vertex_edges(vi).empty() ||
                mesh.is_boundary_vertex(vi))
                return;
            double weighted = 0.0;
            double total = 0.0;
            for (int ei : mesh.vertex_edges(vi)) {
                const size_t w = static_cast<size_t>(mesh.other_vertex(ei, vi));
                weighted += area[w] * values[w];
                total += area[w];
            }
            if (total > 0.0)
                smoothed[v] = 0.5 * (values[v] + weighted / total);
        });
        values.swap(smoothed);
    }
    return values;
}

std::vector<double> liquid_vertex_curvatures(const tracker::SurfaceMesh& mesh, int liquid_region,
                                             int smoothing_passes) {
    if (smoothing_passes < 0)
        throw std::invalid_argument("smoothing_passes: expected an integer >= 0");
    std::vector<double> kappa = tracker::mean_curvatures(mesh);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            kappa[static_cast<size_t>(vi)] *= liquid_orientation(mesh, vi, liquid_region);
    return smooth_vertex_values(mesh, std::move(kappa), smoothing_passes);
}

SurfaceTensionResult face_curvatures(const tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid,
                                     const RasterizeResult& raster,
                                     const SurfaceTensionOptions& options,
                                     fluid::InterfaceInput& interface) {
    options.validate();
    const int nx = grid.nx();
    const int ny = grid.ny();
    const int nz = grid.nz();
    const auto sized = [&](const auto& field) {
        return field.ni() == nx && field.nj() == ny && field.nk() == nz;
    };
    if (!sized(raster.phi) || !sized(raster.closest_triangle))
        throw std::invalid_argument("raster: phi and closest_triangle must be nx x ny x nz");

    SurfaceTensionResult result;
    const Clock::time_point vertex_start = Clock::now();
    const std::vector<double> kappa =
        liquid_vertex_curvatures(mesh, raster.liquid_region, options.smoothing_passes);
    result.vertex_seconds = seconds_since(vertex_start);

    const Clock::time_point face_start = Clock::now();
    interface.kappa_u.resize(nx + 1, ny, nz, 0.0);
    interface.kappa_v.resize(nx, ny + 1, nz, 0.0);
    interface.kappa_w.resize(nx, ny, nz + 1, 0.0);
    std::array<AxisTally, 3> tallies;
    const double kappa_limit = options.max_curvature_cells / grid.dx();
    for (int axis = 0; axis < 3; ++axis) {
        fluid::Array3<double>& face_kappa = interface.kappa(axis);
        const int di = axis == 0 ? 1 : 0;
        const int dj = axis == 1 ? 1 : 0;
        const int dk = axis == 2 ? 1 : 0;
        // Only interior faces have two cells; slabs in k run in parallel. Along a periodic axis
        // the face at index 0 is the seam between cell n − 1 (lo, at its image one period
        // back, where the mesh — unrolled, periodic_images.h — has its triangles too) and cell 0;
        // its copy at n is not visited (the fluid reads the seam at 0).
        const int seam = grid.periodic()[static_cast<size_t>(axis)] && grid.cells(axis) > 1 ? 1 : 0;
        const int n_axis = grid.cells(axis);
        const int si = di * seam, sj = dj * seam, sk = dk * seam;
        tallies[static_cast<size_t>(axis)] = tbb::parallel_reduce(
            tbb::blocked_range<int>(dk - sk, face_kappa.nk() - dk), AxisTally(),
            [&](const tbb::blocked_range<int>& range, AxisTally tally) {
                for (int k = range.begin(); k != range.end(); ++k)
                    for (int j = dj - sj; j < face_kappa.nj() - dj; ++j)
                        for (int i = di - si; i < face_kappa.ni() - di; ++i) {
                            const int along = axis == 0 ? i : (axis == 1 ? j : k);
                            const int wrap = along == 0 ? n_axis : 0;  // lo cell across the seam
                            const int li = i - di + di * wrap, lj = j - dj + dj * wrap,
                                      lk = k - dk + dk * wrap;
                            const double phi_lo = raster.phi(li, lj, lk);
                            const double phi_hi = raster.phi(i, j, k);
                            if (fluid::is_liquid(phi_lo) == fluid::is_liquid(phi_hi))
                                continue;
                            ++tally.crossed;
                            const Vec3 x_lo = grid.cell_centre(i - di, j - dj, k - dk);
                            const Vec3 x_hi = grid.cell_centre(i, j, k);
                            const double theta = phi_lo / (phi_lo - phi_hi);
                            const Vec3 x = x_lo + theta * (x_hi - x_lo);
                            double best = std::numeric_limits<double>::infinity();
                            double value = 0.0;
                            for (int ti : {raster.closest_triangle(li, lj, lk),
                                           raster.closest_triangle(i, j, k)}) {
                                if (ti == tracker::INVALID_INDEX)
                                    continue;
                                double distance = 0.0;
                                const double candidate = curvature_at_closest_point(
                                    mesh, kappa, walk_to_closest_triangle(mesh, ti, x), x,
                                    distance);
                                if (distance < best) {
                                    best = distance;
                                    value = candidate;
                                }
                            }
                            if (best == std::numeric_limits<double>::infinity()) {
                                ++tally.without_triangle;
                                continue;
                            }
                            if (std::abs(value) > kappa_limit || std::isnan(value)) {
                                // NaN from a degenerate one-ring counts as the limit too.
                                value = value < 0.0 ? -kappa_limit : kappa_limit;
                                ++tally.limited;
                            }
                            face_kappa(i, j, k) = value;
                            tally.min_kappa = std::min(tally.min_kappa, value);
                            tally.max_kappa = std::max(tally.max_kappa, value);
                        }
                return tally;
            },
            [](AxisTally a, const AxisTally& b) {
                a.crossed += b.crossed;
                a.without_triangle += b.without_triangle;
                a.limited += b.limited;
                a.min_kappa = std::min(a.min_kappa, b.min_kappa);
                a.max_kappa = std::max(a.max_kappa, b.max_kappa);
                return a;
            });
    }
    double min_kappa = std::numeric_limits<double>::infinity();
    double max_kappa = -std::numeric_limits<double>::infinity();
    for (const AxisTally& tally : tallies) {
        result.crossed_faces += tally.crossed;
        result.faces_without_triangle += tally.without_triangle;
        result.limited_faces += tally.limited;
        min_kappa = std::min(min_kappa, tally.min_kappa);
        max_kappa = std::max(max_kappa, tally.max_kappa);
    }
    if (min_kappa <= max_kappa) {
        result.min_kappa = min_kappa;
        result.max_kappa = max_kappa;
    }
    result.face_seconds = seconds_since(face_start);
    return result;
}

fluid::InterfaceInput interface_from_mesh(const tracker::SurfaceMesh& mesh,
                                          const fluid::MacGrid& grid,
                                          const RasterizeOptions& raster_options,
                                          const SurfaceTensionOptions& tension_options,
                                          SurfaceTensionResult* tension_result) {
    tension_options.validate();
    RasterizeResult raster = rasterize_mesh(mesh, grid, raster_options);
    fluid::InterfaceInput interface;
    const SurfaceTensionResult tension =
        face_curvatures(mesh, grid, raster, tension_options, interface);
    interface.phi = std::move(raster.phi);
    if (tension_result != nullptr)
        *tension_result = tension;
    return interface;
}

}  // namespace meniscus::coupling
