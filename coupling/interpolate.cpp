#include "coupling/interpolate.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <stdexcept>

namespace meniscus::coupling {

namespace {

/// Quadratic B-spline weights of the nodes n−1, n, n+1 for a point at offset f ∈ [−½, ½] from
/// node n: they sum to 1 and have first moment f, hence reproduce linear functions.
std::array<double, 3> quadratic_bspline_weights(double f) {
    const double lo = 0.5 - f;
    const double hi = 0.5 + f;
    return {0.5 * lo * lo, 0.75 - f * f, 0.5 * hi * hi};
}

/// Quadratic B-spline sample of velocity component `axis` at `grid_position` (cell units from
/// the origin); falls back to trilinear where the stencil leaves the face lattice.
double sample_component_bspline(const fluid::MacGrid& grid, int axis,
                                const Eigen::Vector3d& grid_position) {
    const fluid::Array3<double>& field = grid.velocity(axis);
    const fluid::FieldLocation location = fluid::face_location(axis);
    const Eigen::Vector3d g = grid_position - fluid::field_offset(location);
    const std::array<int, 3> extent{field.ni(), field.nj(), field.nk()};
    std::array<int, 3> node{};
    std::array<std::array<double, 3>, 3> weights{};
    for (int d = 0; d < 3; ++d) {
        const double nearest = std::floor(g[d] + 0.5);
        node[static_cast<size_t>(d)] = static_cast<int>(nearest);
        if (!(nearest >= 1.0 && nearest <= extent[static_cast<size_t>(d)] - 2.0))
            return fluid::interpolate_trilinear(field, location, grid_position);
        weights[static_cast<size_t>(d)] = quadratic_bspline_weights(g[d] - nearest);
    }
    double value = 0.0;
    for (int c = 0; c < 3; ++c) {
        double plane = 0.0;
        for (int b = 0; b < 3; ++b) {
            const double* row = &field(node[0] - 1, node[1] - 1 + b, node[2] - 1 + c);
            const std::array<double, 3>& wx = weights[0];
            plane += weights[1][static_cast<size_t>(b)] *
                     (wx[0] * row[0] + wx[1] * row[1] + wx[2] * row[2]);
        }
        value += weights[2][static_cast<size_t>(c)] * plane;
    }
    return value;
}

}  // namespace

void InterpolateOptions::validate() const {
    if (method != VelocityInterpolation::trilinear &&
        method != VelocityInterpolation::quadratic_bspline)
        throw std::invalid_argument("method: expected trilinear or quadratic_bspline");
}

Eigen::Vector3d sample_grid_velocity(const fluid::MacGrid& grid, const Eigen::Vector3d& x,
                                     VelocityInterpolation method) {
    const Eigen::Vector3d g = grid.to_grid(x);
    Eigen::Vector3d velocity;
    for (int axis = 0; axis < 3; ++axis) {
        velocity[axis] =
            method == VelocityInterpolation::quadratic_bspline
                ? sample_component_bspline(grid, axis, g)
                : fluid::interpolate_trilinear(grid.velocity(axis), fluid::face_location(axis), g);
    }
    return velocity;
}

std::vector<tracker::Vec3> interpolate_vertex_velocities(const fluid::MacGrid& grid,
                                                         const tracker::SurfaceMesh& mesh,
                                                         const InterpolateOptions& options) {
    options.validate();
    std::vector<tracker::Vec3> velocities(static_cast<size_t>(mesh.num_vertices()),
                                          tracker::Vec3::Zero());
    tbb::parallel_for(tbb::blocked_range<int>(0, mesh.num_vertices()),
                      [&](const tbb::blocked_range<int>& range) {
                          for (int vi = range.begin(); vi != range.end(); ++vi)
                              if (mesh.vertex_alive(vi))
                                  velocities[static_cast<size_t>(vi)] =
                                      sample_grid_velocity(grid, mesh.position(vi), options.method);
                      });
    return velocities;
}

}  // namespace meniscus::coupling
