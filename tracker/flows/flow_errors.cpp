#include "tracker/flows/flow_errors.h"

#include "tracker/mesh_distance.h"
#include "tracker/mesh_measures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace meniscus::tracker {

void SurfaceErrorOptions::validate() const {
    if (triangle_subdivisions < 1)
        throw std::invalid_argument("triangle_subdivisions: expected an integer >= 1, got " +
                                    std::to_string(triangle_subdivisions));
}

SurfaceError surface_error(const SurfaceMesh& mesh,
                           const std::function<double(const Vec3&)>& signed_distance,
                           const SurfaceErrorOptions& options) {
    options.validate();
    SurfaceError error;
    std::vector<double> vertex_signed(static_cast<size_t>(mesh.num_vertices()), 0.0);
    error.vertex_max_signed = -std::numeric_limits<double>::infinity();
    error.vertex_min_signed = std::numeric_limits<double>::infinity();
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        const double signed_phi = signed_distance(mesh.position(vi));
        const double phi = std::abs(signed_phi);
        vertex_signed[static_cast<size_t>(vi)] = signed_phi;
        error.vertex_max_signed = std::max(error.vertex_max_signed, signed_phi);
        error.vertex_min_signed = std::min(error.vertex_min_signed, signed_phi);
        if (phi > error.vertex_linf) {
            error.vertex_linf = phi;
            error.vertex_linf_position = mesh.position(vi);
        }
        ++error.samples;
    }
    error.linf = error.vertex_linf;

    const int m = options.triangle_subdivisions;
    const double inv_m = 1.0 / m;
    double weighted_sum = 0.0, vertex_weighted_sum = 0.0, vertex_signed_sum = 0.0;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        const Vec3& a = mesh.position(t[0]);
        const Vec3 e1 = mesh.position(t[1]) - a;
        const Vec3 e2 = mesh.position(t[2]) - a;
        const double area = 0.5 * e1.cross(e2).norm();
        auto sample = [&](double u, double v) {
            const double phi = std::abs(signed_distance(a + u * e1 + v * e2));
            error.linf = std::max(error.linf, phi);
            ++error.samples;
            return phi;
        };
        // Interior lattice points (the corners are the vertices, already sampled).
        for (int i = 0; i <= m; ++i)
            for (int j = 0; i + j <= m; ++j)
                if (!((i == 0 && j == 0) || i == m || j == m))
                    sample(i * inv_m, j * inv_m);
        // Midpoint rule over the m² sub-triangles ("up" and "down" ones).
        double sum = 0.0;
        for (int i = 0; i < m; ++i)
            for (int j = 0; i + j < m; ++j) {
                sum += sample((i + 1.0 / 3.0) * inv_m, (j + 1.0 / 3.0) * inv_m);
                if (i + j < m - 1)
                    sum += sample((i + 2.0 / 3.0) * inv_m, (j + 2.0 / 3.0) * inv_m);
            }
        weighted_sum += area * sum / (m * m);
        error.area += area;
        for (int vi : t) {
            const double signed_phi = vertex_signed[static_cast<size_t>(vi)];
            vertex_weighted_sum += area / 3.0 * std::abs(signed_phi);
            vertex_signed_sum += area / 3.0 * signed_phi;
        }
    }
    error.l1 = error.area > 0.0 ? weighted_sum / error.area : 0.0;
    error.vertex_l1 = error.area > 0.0 ? vertex_weighted_sum / error.area : 0.0;
    error.vertex_mean_signed = error.area > 0.0 ? vertex_signed_sum / error.area : 0.0;
    return error;
}

double two_ball_union_signed_distance(const Vec3& x, const Vec3& c0, const Vec3& c1,
                                      double radius) {
    if (!(radius > 0.0))
        throw std::invalid_argument("radius: expected a number > 0");
    const double d0 = (x - c0).norm();
    const double d1 = (x - c1).norm();
    const double outside = std::min(d0, d1) - radius;
    const Vec3 axis = c1 - c0;
    const double separation = axis.norm();
    if (outside >= 0.0 || separation >= 2.0 * radius || separation == 0.0)
        return outside;  // outside U, or the balls do not overlap (or coincide)

    // Inside U with overlapping balls: nearest of the two patches and the ring.
    const Vec3 u = axis / separation;  // from c0 towards c1
    const Vec3 mid = 0.5 * (c0 + c1);  // ring centre (equal radii)
    const double ring_radius = std::sqrt(radius * radius - 0.25 * separation * separation);
    const Vec3 rel = x - mid;
    const double axial = rel.dot(u);
    const double radial = (rel - axial * u).norm();
    double distance = std::hypot(axial, radial - ring_radius);

    const std::array<const Vec3*, 2> centers = {&c0, &c1};
    const std::array<double, 2> dists = {d0, d1};
    const std::array<Vec3, 2> towards_other = {u, Vec3(-u)};
    for (size_t i = 0; i < 2; ++i) {
        // Radial projection onto sphere i; at the centre any direction away from the other
        // ball is nearest, and it lies on the patch.
        const bool on_patch =
            dists[i] == 0.0 ||
            (*centers[i] + radius * (x - *centers[i]) / dists[i] - mid).dot(towards_other[i]) <=
                0.0;
        if (on_patch)
            distance = std::min(distance, std::abs(dists[i] - radius));
    }
    return -distance;
}

void TwoSphereNormalFlow::validate() const {
    if (!(initial_radius > 0.0) || !std::isfinite(initial_radius))
        throw std::invalid_argument("initial_radius: expected a finite number > 0 (metres)");
    if (!(speed > 0.0) || !std::isfinite(speed))
        throw std::invalid_argument("speed: expected a finite number > 0 (m/s)");
    if (!(reversal_time >= 0.0) || !std::isfinite(reversal_time))
        throw std::invalid_argument("reversal_time: expected a finite number >= 0 (s)");
    if (!center0.allFinite() || !center1.allFinite())
        throw std::invalid_argument("center0/center1: expected finite coordinates");
}

double TwoSphereNormalFlow::normal_speed(double t) const {
    return t < reversal_time ? speed : -speed;
}

double TwoSphereNormalFlow::signed_distance(const Vec3& x, double t) const {
    validate();
    const double merged_radius = initial_radius + speed * reversal_time;
    const double extinction = reversal_time + merged_radius / speed;
    if (!(t >= 0.0 && t <= extinction))
        throw std::invalid_argument("t: expected a time in [0, " + std::to_string(extinction) +
                                    "] s, got " + std::to_string(t));
    if (t <= reversal_time)
        return two_ball_union_signed_distance(x, center0, center1, initial_radius + speed * t);
    return two_ball_union_signed_distance(x, center0, center1, merged_radius) +
           speed * (t - reversal_time);
}

SurfaceError two_sphere_normal_flow_error(const SurfaceMesh& mesh, const TwoSphereNormalFlow& flow,
                                          double t, const SurfaceErrorOptions& options) {
    flow.validate();
    flow.signed_distance(flow.center0, t);  // validates t once, before the sampling
    return surface_error(
        mesh, [&flow, t](const Vec3& x) { return flow.signed_distance(x, t); }, options);
}

double sphere_mean_curvature_radius(double initial_radius, double t) {
    if (!(initial_radius > 0.0) || !std::isfinite(initial_radius))
        throw std::invalid_argument("initial_radius: expected a finite number > 0 (metres)");
    const double extinction = 0.25 * initial_radius * initial_radius;
    if (!(t >= 0.0 && t <= extinction))
        throw std::invalid_argument(
            "t: expected a time in [0, R0^2/4 = " + std::to_string(extinction) + "] s");
    return std::sqrt(std::max(0.0, initial_radius * initial_radius - 4.0 * t));
}

SurfaceError sphere_error(const SurfaceMesh& mesh, const Vec3& center, double radius,
                          const SurfaceErrorOptions& options) {
    if (!(radius > 0.0) || !std::isfinite(radius))
        throw std::invalid_argument("radius: expected a finite number > 0 (metres)");
    return surface_error(
        mesh, [&center, radius](const Vec3& x) { return (x - center).norm() - radius; }, options);
}

HausdorffDistance hausdorff_distance(const SurfaceMesh& a, const SurfaceMesh& b,
                                     const SurfaceErrorOptions& options) {
    options.validate();
    const MeshDistance to_a(a), to_b(b);
    HausdorffDistance h;
    h.a_to_b = surface_error(a, [&to_b](const Vec3& x) { return to_b.distance(x); }, options);
    h.b_to_a = surface_error(b, [&to_a](const Vec3& x) { return to_a.distance(x); }, options);
    h.symmetric = std::max(h.a_to_b.linf, h.b_to_a.linf);
    return h;
}

double relative_volume_change(double initial_volume, double volume) {
    if (initial_volume == 0.0 || !std::isfinite(initial_volume))
        throw std::invalid_argument("initial_volume: expected a finite nonzero volume");
    return (volume - initial_volume) / initial_volume;
}

double relative_volume_change(const SurfaceMesh& mesh, double initial_volume) {
    return relative_volume_change(initial_volume, enclosed_volume(mesh));
}

}  // namespace meniscus::tracker
