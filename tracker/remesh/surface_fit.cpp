#include "tracker/remesh/surface_fit.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

namespace {

/// Design matrices whose normal matrix has an LDLT pivot below the square of this times its
/// largest (columns are scaled to the patch radius) count as rank-deficient.
constexpr double RANK_TOLERANCE = 1e-6;
constexpr int QUADRATIC_COEFFICIENTS = 6;
constexpr int CUBIC_COEFFICIENTS = 10;
using Coefficients = Eigen::Matrix<double, CUBIC_COEFFICIENTS, 1>;
/// arc_edge_point(): the two vertex normals may be at most 120° apart, and the arc's half angle
/// (between the chord and each end's tangent plane) at most 60°.
constexpr double ARC_MIN_NORMAL_COSINE = -0.5;
constexpr double ARC_MAX_HALF_ANGLE = M_PI / 3.0;

/// Unit vector orthogonal to unit n.
Vec3 any_orthogonal(const Vec3& n) {
    const Vec3 axis = std::abs(n.x()) < 0.6 ? Vec3::UnitX() : Vec3::UnitY();
    return n.cross(axis).normalized();
}

/// Area vector (twice the area, along the normal) of live triangle ti.
Vec3 area_vector(const SurfaceMesh& mesh, int ti) {
    const Triangle& t = mesh.triangle(ti);
    const Vec3& a = mesh.position(t[0]);
    return (mesh.position(t[1]) - a).cross(mesh.position(t[2]) - a);
}

/// Appends the vertices of vi's triangles (vi included) to `out`.
void append_one_ring(const SurfaceMesh& mesh, int vi, std::vector<int>& out) {
    out.push_back(vi);
    for (int ti : mesh.vertex_triangles(vi))
        for (int w : mesh.triangle(ti))
            out.push_back(w);
}

/// Least-squares height field with N coefficients (6: quadratic, 10: cubic, in the order of
/// the file comment) through `local` ((s, t, h) in the patch frame), in units of the patch
/// radius: the scaled coefficients, zero-padded to 10, or nullopt where the design is
/// rank-deficient or a vertex is further than `max_residual_fraction` of the radius from it.
template <int N>
std::optional<Coefficients> solve_height_field(const std::vector<Eigen::Vector3d>& local,
                                               double radius, double max_residual_fraction) {
    const double inv = 1.0 / radius;
    using Row = Eigen::Matrix<double, N, 1>;
    const auto design_row = [inv](const Eigen::Vector3d& l) {
        const double s = l.x() * inv, t = l.y() * inv;
        Coefficients all;
        all << 1.0, s, t, s * s, s * t, t * t, s * s * s, s * s * t, s * t * t, t * t * t;
        return Row(all.template head<N>());
    };
    // Normal equations, every column O(1) in these units. Fixed-size keeps this off the heap;
    // it runs for every smooth vertex on every smoothing step.
    Eigen::Matrix<double, N, N> normal_matrix = Eigen::Matrix<double, N, N>::Zero();
    Row right = Row::Zero();
    for (const Eigen::Vector3d& l : local) {
        const Row row = design_row(l);
        normal_matrix.template selfadjointView<Eigen::Lower>().rankUpdate(row);
        right += l.z() * row;
    }
    normal_matrix = normal_matrix.template selfadjointView<Eigen::Lower>();
    // Pivoted LDLT of AᵀA: its pivots bound the squared singular values of A.
    const Eigen::LDLT<Eigen::Matrix<double, N, N>> ldlt(normal_matrix);
    const Row pivots = ldlt.vectorD().cwiseAbs();
    if (ldlt.info() != Eigen::Success || !(pivots.maxCoeff() > 0.0) ||
        pivots.minCoeff() < RANK_TOLERANCE * RANK_TOLERANCE * pivots.maxCoeff())
        return std::nullopt;
    const Row scaled = ldlt.solve(right);
    double residual = 0.0;
    for (const Eigen::Vector3d& l : local)
        residual = std::max(residual, std::abs(design_row(l).dot(scaled) - l.z()));
    if (!(residual <= max_residual_fraction * radius))
        return std::nullopt;
    Coefficients padded = Coefficients::Zero();
    padded.template head<N>() = scaled;
    return padded;
}

}  // namespace

std::optional<Vec3> majority_normal(const SurfaceMesh& mesh, int vi, double cluster_angle_degrees,
                                    double cluster_weight_fraction) {
    struct Face {
        Vec3 n;
        double w;
    };
    std::vector<Face> faces;
    Vec3 mean = Vec3::Zero();
    double total = 0.0;
    for (int ti : mesh.vertex_triangles(vi)) {
        const Vec3 a = area_vector(mesh, ti);
        const double length = a.norm();
        if (!(length > 0.0))
            continue;
        faces.push_back({a / length, length});
        mean += a;
        total += length;
    }
    if (!(mean.norm() > 0.0))
        return std::nullopt;
    const double cosine = std::cos(cluster_angle_degrees * M_PI / 180.0);
    double best_weight = 0.0;
    Vec3 best = Vec3::Zero();
    for (const Face& f : faces) {
        double weight = 0.0;
        Vec3 sum = Vec3::Zero();
        for (const Face& g : faces)
            if (g.n.dot(f.n) >= cosine) {
                weight += g.w;
                sum += g.w * g.n;
            }
        if (weight > best_weight && sum.norm() > 0.0) {
            best_weight = weight;
            best = sum;
        }
    }
    return best_weight >= cluster_weight_fraction * total ? best.normalized() : mean.normalized();
}

void SurfaceFitOptions::validate() const {
    if (!(max_normal_angle_degrees > 0.0 && max_normal_angle_degrees < 90.0))
        throw std::invalid_argument("max_normal_angle_degrees: expected a number in (0, 90), got " +
                                    std::to_string(max_normal_angle_degrees));
    if (!(max_offset_fraction > 0.0 && max_offset_fraction <= 1.0))
        throw std::invalid_argument("max_offset_fraction: expected a number in (0, 1], got " +
                                    std::to_string(max_offset_fraction));
    if (!(max_residual_fraction > 0.0 && max_residual_fraction <= 1.0))
        throw std::invalid_argument("max_residual_fraction: expected a number in (0, 1], got " +
                                    std::to_string(max_residual_fraction));
    if (degree != 2 && degree != 3)
        throw std::invalid_argument("degree: expected 2 or 3, got " + std::to_string(degree));
}

Vec3 SurfacePatch::point_above(const Vec3& x) const {
    const Vec3 r = x - origin;
    const double s = r.dot(u), t = r.dot(v);
    const auto& c = coefficients;
    const double h = c[0] + c[1] * s + c[2] * t + c[3] * s * s + c[4] * s * t + c[5] * t * t +
                     c[6] * s * s * s + c[7] * s * s * t + c[8] * s * t * t + c[9] * t * t * t;
    return origin + s * u + t * v + h * normal;
}

double SurfacePatch::turn() const {
    // Hessian [[a, b], [b, c]] of h at the origin.
    const double a = 2.0 * coefficients[3], b = coefficients[4], c = 2.0 * coefficients[5];
    return radius * (0.5 * std::abs(a + c) + std::hypot(0.5 * (a - c), b));
}

std::optional<SurfacePatch> fit_surface_patch(const SurfaceMesh& mesh,
                                              const std::vector<int>& vertices,
                                              const std::vector<int>& triangles, const Vec3& origin,
                                              const Vec3& normal,
                                              const SurfaceFitOptions& options) {
    options.validate();
    const double normal_length = normal.norm();
    if (!(normal_length > 0.0))
        throw std::invalid_argument("normal: expected a nonzero vector");
    SurfacePatch patch;
    patch.origin = origin;
    patch.normal = normal / normal_length;
    patch.u = any_orthogonal(patch.normal);
    patch.v = patch.normal.cross(patch.u);

    const double min_cosine = std::cos(options.max_normal_angle_degrees * M_PI / 180.0);
    for (int ti : triangles) {
        const Vec3 a = area_vector(mesh, ti);
        const double length = a.norm();
        if (!(length > 0.0) || a.dot(patch.normal) < min_cosine * length)
            return std::nullopt;
    }

    // A few dozen ids with many repeats: a linear scan beats sorting (the sort was 29 % of A1's
    // run time at ξ = 0.02).
    std::vector<int> ids;
    ids.reserve(vertices.size());
    for (int id : vertices)
        if (std::find(ids.begin(), ids.end(), id) == ids.end())
            ids.push_back(id);
    if (ids.size() < static_cast<size_t>(QUADRATIC_COEFFICIENTS))
        return std::nullopt;

    std::vector<Eigen::Vector3d> local(ids.size());
    for (size_t i = 0; i < ids.size(); ++i) {
        const Vec3 r = mesh.position(ids[i]) - origin;
        local[i] = {r.dot(patch.u), r.dot(patch.v), r.dot(patch.normal)};
        patch.radius = std::max(patch.radius, std::hypot(local[i].x(), local[i].y()));
    }
    if (!(patch.radius > 0.0))
        return std::nullopt;
    const double inv = 1.0 / patch.radius;
    std::optional<Coefficients> scaled;
    if (options.degree == 3 && ids.size() >= static_cast<size_t>(CUBIC_COEFFICIENTS))
        scaled = solve_height_field<CUBIC_COEFFICIENTS>(local, patch.radius,
                                                        options.max_residual_fraction);
    if (!scaled)
        scaled = solve_height_field<QUADRATIC_COEFFICIENTS>(local, patch.radius,
                                                            options.max_residual_fraction);
    if (!scaled)
        return std::nullopt;
    // Back from units of the patch radius: a term of degree k scales by inv^k.
    const Coefficients& f = *scaled;
    patch.coefficients << f[0], f[1] * inv, f[2] * inv, f[3] * inv * inv, f[4] * inv * inv,
        f[5] * inv * inv, f[6] * inv * inv * inv, f[7] * inv * inv * inv, f[8] * inv * inv * inv,
        f[9] * inv * inv * inv;
    if (!patch.coefficients.allFinite())
        return std::nullopt;
    return patch;
}

std::optional<Vec3> fitted_edge_point(const SurfaceMesh& mesh, int ei,
                                      const SurfaceFitOptions& options) {
    if (mesh.edge_triangles(ei).size() != 2)
        return std::nullopt;
    const Edge& e = mesh.edge(ei);
    if (mesh.is_boundary_vertex(e[0]) || mesh.is_boundary_vertex(e[1]))
        return std::nullopt;
    std::vector<int> vertices, triangles;
    Vec3 normal = Vec3::Zero();
    for (int end : e) {
        append_one_ring(mesh, end, vertices);
        for (int ti : mesh.vertex_triangles(end)) {
            triangles.push_back(ti);
            normal += area_vector(mesh, ti);
        }
    }
    if (!(normal.norm() > 0.0))
        return std::nullopt;
    const Vec3 midpoint = 0.5 * (mesh.position(e[0]) + mesh.position(e[1]));
    const std::optional<SurfacePatch> patch =
        fit_surface_patch(mesh, vertices, triangles, midpoint, normal, options);
    if (!patch)
        return std::nullopt;
    // The least-squares surface misses the endpoints by its residuals there (a quadratic fitted
    // to a sphere cap sits above it in the middle): shift it by their mean so that it
    // interpolates the edge's ends on average.
    const Vec3 residual = 0.5 * (patch->point_above(mesh.position(e[0])) - mesh.position(e[0]) +
                                 patch->point_above(mesh.position(e[1])) - mesh.position(e[1]));
    const Vec3 point = patch->point_above(midpoint) - residual;
    if ((point - midpoint).norm() > options.max_offset_fraction * patch->radius)
        return std::nullopt;
    return point;
}

std::optional<Vec3> arc_edge_point(const SurfaceMesh& mesh, int ei) {
    if (mesh.edge_triangles(ei).size() != 2)
        return std::nullopt;
    const Edge& e = mesh.edge(ei);
    Vec3 n[2];
    for (int k = 0; k < 2; ++k) {
        const std::optional<Vec3> normal = majority_normal(mesh, e[k]);
        if (!normal)
            return std::nullopt;
        n[k] = *normal;
    }
    const Vec3 p0 = mesh.position(e[0]), p1 = mesh.position(e[1]);
    const Vec3 chord = p1 - p0;
    const double length = chord.norm();
    if (!(length > 0.0) || n[0].dot(n[1]) < ARC_MIN_NORMAL_COSINE)
        return std::nullopt;
    const Vec3 midpoint = 0.5 * (p0 + p1);
    // w₀ = chord·n₀ and w₁ = −chord·n₁ are both ℓ sin(θ/2) for a circular arc of angle θ,
    // negative where it bulges along the normals (convex), positive where it sags (concave).
    const double w0 = chord.dot(n[0]), w1 = -chord.dot(n[1]);
    Vec3 direction = -(w0 * n[0] + w1 * n[1]);
    direction -= direction.dot(chord) / (length * length) * chord;
    const double direction_length = direction.norm();
    if (!(direction_length > 0.0))
        return midpoint;
    const double sine = std::min(1.0, 0.5 * (std::abs(w0) + std::abs(w1)) / length);
    const double half_angle = std::asin(sine);
    if (half_angle > ARC_MAX_HALF_ANGLE)
        return std::nullopt;
    // Sagitta of a circular arc of chord ℓ and angle θ: (ℓ/2) tan(θ/4).
    return midpoint + 0.5 * length * std::tan(0.5 * half_angle) / direction_length * direction;
}

std::optional<SurfaceEdgePoint> surface_edge_point(const SurfaceMesh& mesh, int ei,
                                                   const FeatureThresholds& thresholds,
                                                   const SurfaceFitOptions& options) {
    const Edge& e = mesh.edge(ei);
    if (vertex_quadric(mesh, e[0], thresholds).feature == VertexFeature::smooth &&
        vertex_quadric(mesh, e[1], thresholds).feature == VertexFeature::smooth)
        if (const std::optional<Vec3> p = fitted_edge_point(mesh, ei, options))
            return SurfaceEdgePoint{*p, EdgePointRule::fitted};
    if (const std::optional<Vec3> p = arc_edge_point(mesh, ei))
        return SurfaceEdgePoint{*p, EdgePointRule::arc};
    return std::nullopt;
}

std::optional<SurfacePatch> vertex_patch(const SurfaceMesh& mesh, int vi,
                                         const SurfaceFitOptions& options) {
    if (mesh.vertex_triangles(vi).empty() || mesh.is_boundary_vertex(vi))
        return std::nullopt;
    // The one-ring alone (about 7 vertices) barely determines 6 coefficients: fit the two-ring.
    std::vector<int> ring;
    append_one_ring(mesh, vi, ring);
    std::vector<int> vertices, triangles;
    for (int w : ring) {
        append_one_ring(mesh, w, vertices);
        triangles.insert(triangles.end(), mesh.vertex_triangles(w).begin(),
                         mesh.vertex_triangles(w).end());
    }
    // Repeats only repeat the graph check; not worth removing.
    Vec3 normal = Vec3::Zero();
    for (int ti : mesh.vertex_triangles(vi))
        normal += area_vector(mesh, ti);
    if (!(normal.norm() > 0.0))
        return std::nullopt;
    return fit_surface_patch(mesh, vertices, triangles, mesh.position(vi), normal, options);
}

std::optional<Vec3> place_on_vertex_patch(const SurfacePatch& patch, const Vec3& x,
                                          const Vec3& target, const SurfaceFitOptions& options) {
    // Shift the fitted surface through the vertex itself: its residual there (about 5e-5 above
    // a sphere of radius 0.3 at ξ = 0.04) would otherwise be added on every smoothing step.
    const Vec3 point = patch.point_above(target) - (patch.point_above(x) - x);
    if ((point - target).norm() > options.max_offset_fraction * patch.radius)
        return std::nullopt;
    return point;
}

std::optional<Vec3> fitted_vertex_point(const SurfaceMesh& mesh, int vi, const Vec3& target,
                                        const SurfaceFitOptions& options) {
    const std::optional<SurfacePatch> patch = vertex_patch(mesh, vi, options);
    if (!patch)
        return std::nullopt;
    return place_on_vertex_patch(*patch, mesh.position(vi), target, options);
}

}  // namespace meniscus::tracker
