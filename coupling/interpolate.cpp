#include "coupling/interpolate.h"

#include "tracker/mesh_measures.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>

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

/// Lower node of the linear-interpolation interval of lattice coordinate `s` (clamped into the
/// lattice of `extent` nodes) and the fraction within it.
std::pair<int, double> lattice_interval(double s, int extent) {
    if (extent < 2)
        return {0, 0.0};
    const double clamped = std::clamp(s, 0.0, extent - 1.0);
    const int lower = std::min(static_cast<int>(std::floor(clamped)), extent - 2);
    return {lower, clamped - lower};
}

/// One-sided sample (VelocityInterpolation::one_sided) of velocity component `axis` at
/// `grid_position` (cell units) for an interface with unit normal `n` there.
double sample_component_one_sided(const fluid::MacGrid& grid, int axis,
                                  const Eigen::Vector3d& grid_position, const Eigen::Vector3d& n) {
    const fluid::Array3<double>& field = grid.velocity(axis);
    const std::array<int, 3> extent{field.ni(), field.nj(), field.nk()};
    // Points outside the face lattice are clamped onto it, as trilinear sampling does: vertices
    // far outside the domain (the cut ends of a wall-crossing column) must not see the columns
    // extrapolated over many cells.
    Eigen::Vector3d g = grid_position - fluid::field_offset(fluid::face_location(axis));
    for (int d = 0; d < 3; ++d)
        g[d] = std::clamp(g[d], 0.0, extent[static_cast<size_t>(d)] - 1.0);
    int a = 0;  // the column axis: the one closest to the normal
    n.cwiseAbs().maxCoeff(&a);
    const int b = (a + 1) % 3, e = (a + 2) % 3;
    const auto [ib, fb] = lattice_interval(g[b], extent[static_cast<size_t>(b)]);
    const auto [ie, fe] = lattice_interval(g[e], extent[static_cast<size_t>(e)]);
    const int na = extent[static_cast<size_t>(a)];
    double value = 0.0;
    for (int cb = 0; cb < 2; ++cb) {
        for (int ce = 0; ce < 2; ++ce) {
            const double weight = (cb ? fb : 1.0 - fb) * (ce ? fe : 1.0 - fe);
            if (weight == 0.0)
                continue;
            std::array<int, 3> node{};
            node[static_cast<size_t>(b)] = std::min(ib + cb, extent[static_cast<size_t>(b)] - 1);
            node[static_cast<size_t>(e)] = std::min(ie + ce, extent[static_cast<size_t>(e)] - 1);
            // Where the tangent plane n·(p − x) = 0 crosses this column.
            const double s = g[a] - (n[b] * (node[static_cast<size_t>(b)] - g[b]) +
                                     n[e] * (node[static_cast<size_t>(e)] - g[e])) /
                                        n[a];
            const auto at = [&](int i) {
                node[static_cast<size_t>(a)] = i;
                return field(node[0], node[1], node[2]);
            };
            double column = 0.0;
            if (na >= 4 && s >= 1.0 && s < na - 2.0) {
                const int i0 = static_cast<int>(std::floor(s));
                const double d = s - i0;
                const double f0 = at(i0), f1 = at(i0 + 1);
                const double below = f0 + d * (f0 - at(i0 - 1));
                const double above = f1 + (1.0 - d) * (f1 - at(i0 + 2));
                column = (1.0 - d) * below + d * above;
            } else if (na >= 2) {  // near a wall: linear along the column (extrapolated past
                                   // its ends, which keeps linear fields exact)
                const int i0 = std::clamp(static_cast<int>(std::floor(s)), 0, na - 2);
                const double d = s - i0;
                column = (1.0 - d) * at(i0) + d * at(i0 + 1);
            } else {
                column = at(0);
            }
            value += weight * column;
        }
    }
    return value;
}

}  // namespace

void InterpolateOptions::validate() const {
    if (method != VelocityInterpolation::trilinear &&
        method != VelocityInterpolation::quadratic_bspline &&
        method != VelocityInterpolation::one_sided)
        throw std::invalid_argument("method: expected trilinear, quadratic_bspline or one_sided");
    if (outside != OutsideVelocity::clamp && outside != OutsideVelocity::mirror)
        throw std::invalid_argument("outside: expected clamp or mirror");
}

Eigen::Vector3d sample_grid_velocity(const fluid::MacGrid& grid, const Eigen::Vector3d& x,
                                     VelocityInterpolation method, const Eigen::Vector3d& normal) {
    const Eigen::Vector3d g = grid.to_grid(x);
    const double length = normal.norm();
    const bool one_sided =
        method == VelocityInterpolation::one_sided && length > 0.0 && std::isfinite(length);
    Eigen::Vector3d velocity;
    for (int axis = 0; axis < 3; ++axis) {
        if (one_sided)
            velocity[axis] = sample_component_one_sided(grid, axis, g, normal / length);
        else if (method == VelocityInterpolation::quadratic_bspline)
            velocity[axis] = sample_component_bspline(grid, axis, g);
        else
            velocity[axis] =
                fluid::interpolate_trilinear(grid.velocity(axis), fluid::face_location(axis), g);
    }
    return velocity;
}

std::vector<tracker::Vec3> interpolate_vertex_velocities(const fluid::MacGrid& grid,
                                                         const tracker::SurfaceMesh& mesh,
                                                         const InterpolateOptions& options,
                                                         const fluid::WallOptions& walls) {
    options.validate();
    walls.validate();
    const bool mirror = options.outside == OutsideVelocity::mirror;
    const Eigen::Vector3d lo = grid.origin();
    const Eigen::Vector3d hi =
        lo + grid.dx() * Eigen::Vector3d(grid.nx(), grid.ny(), grid.nz());
    // The sample of a vertex at x with normal n; outside a free-slip wall (mirror), the sample at
    // the reflected point and normal with the wall-normal component negated back.
    const auto sample = [&](Eigen::Vector3d x, Eigen::Vector3d n) {
        std::array<bool, 3> reflected{};
        if (mirror)
            for (int d = 0; d < 3; ++d) {
                const int side = x[d] < lo[d] ? 0 : x[d] > hi[d] ? 1 : -1;
                if (side < 0 || walls.at(d, side) != fluid::WallType::free_slip)
                    continue;
                const double plane = side == 0 ? lo[d] : hi[d];
                x[d] = 2.0 * plane - x[d];
                n[d] = -n[d];
                reflected[static_cast<size_t>(d)] = true;
            }
        Eigen::Vector3d v = sample_grid_velocity(grid, x, options.method, n);
        for (int d = 0; d < 3; ++d)
            if (reflected[static_cast<size_t>(d)])
                v[d] = -v[d];
        return v;
    };
    std::vector<tracker::Vec3> velocities(static_cast<size_t>(mesh.num_vertices()),
                                          tracker::Vec3::Zero());
    const std::vector<tracker::Vec3> normals = options.method == VelocityInterpolation::one_sided
                                                   ? tracker::area_weighted_vertex_normals(mesh)
                                                   : std::vector<tracker::Vec3>{};
    tbb::parallel_for(
        tbb::blocked_range<int>(0, mesh.num_vertices()), [&](const tbb::blocked_range<int>& range) {
            for (int vi = range.begin(); vi != range.end(); ++vi)
                if (mesh.vertex_alive(vi))
                    velocities[static_cast<size_t>(vi)] =
                        sample(mesh.position(vi), normals.empty()
                                                      ? Eigen::Vector3d::Zero()
                                                      : normals[static_cast<size_t>(vi)]);
        });
    return velocities;
}

}  // namespace meniscus::coupling
