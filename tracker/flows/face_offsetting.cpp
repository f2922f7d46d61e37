#include "tracker/flows/face_offsetting.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

namespace {

/// |(b − a) × (c − a)| below this times the squared longest edge counts as degenerate.
constexpr double DEGENERATE_AREA_RATIO = 1e-14;
/// Dihedral angles (radians) below this count as flat: neither convex nor concave.
constexpr double FLAT_DIHEDRAL = 1e-9;
/// Step reduction applied per retry in face_offset_step() when displacements are not linear in
/// Δt (null-space smoothing on).
constexpr double RETRY_REDUCTION = 0.5;

double longest_edge_squared(const Vec3& a, const Vec3& b, const Vec3& c) {
    return std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
}

bool is_degenerate(const Vec3& area_vector, const Vec3& a, const Vec3& b, const Vec3& c) {
    return area_vector.norm() <= DEGENERATE_AREA_RATIO * longest_edge_squared(a, b, c);
}

/// Interior angle at corner p of triangle (p, q, r), radians.
double corner_angle(const Vec3& p, const Vec3& q, const Vec3& r) {
    const Vec3 u = q - p, v = r - p;
    return std::atan2(u.cross(v).norm(), u.dot(v));
}

/// For each vertex slot, the signed dihedral angle (radians, in [−π, π]) of its incident edge
/// with the largest |angle|: positive where the surface is convex there (the far vertex of one
/// triangle lies behind the other's plane), negative where concave. Only edges with exactly two
/// live, non-degenerate triangles count; 0 where there is none.
std::vector<double> dominant_dihedral_angles(const SurfaceMesh& mesh) {
    std::vector<double> dominant(static_cast<size_t>(mesh.num_vertices()), 0.0);
    auto unit_normal = [&mesh](int ti, Vec3& n) {
        const Triangle& t = mesh.triangle(ti);
        const Vec3& a = mesh.position(t[0]);
        const Vec3& b = mesh.position(t[1]);
        const Vec3& c = mesh.position(t[2]);
        const Vec3 area_vector = (b - a).cross(c - a);
        if (is_degenerate(area_vector, a, b, c))
            return false;
        n = area_vector.normalized();
        return true;
    };
    for (int ei = 0; ei < mesh.num_edges(); ++ei) {
        if (!mesh.edge_alive(ei) || mesh.edge_triangles(ei).size() != 2)
            continue;
        const int t0 = mesh.edge_triangles(ei)[0], t1 = mesh.edge_triangles(ei)[1];
        Vec3 n0, n1;
        if (!unit_normal(t0, n0) || !unit_normal(t1, n1))
            continue;
        const Edge& e = mesh.edge(ei);
        const Vec3 far1 = mesh.position(mesh.opposite_vertex(t1, ei)) - mesh.position(e[0]);
        const double angle = std::atan2(n0.cross(n1).norm(), n0.dot(n1));
        const double signed_angle = far1.dot(n0) <= 0.0 ? angle : -angle;
        for (int vi : e) {
            double& d = dominant[static_cast<size_t>(vi)];
            if (std::abs(signed_angle) > std::abs(d))
                d = signed_angle;
        }
    }
    return dominant;
}

/// Smallest τ in (0, ∞) with c0 + c1 τ + c2 τ² = 0, given c0 > 0; +∞ if there is none.
double smallest_positive_root(double c0, double c1, double c2) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    double best = inf;
    auto consider = [&best](double r) {
        if (r > 0.0 && r < best)
            best = r;
    };
    if (c2 == 0.0) {
        if (c1 < 0.0)
            consider(-c0 / c1);
        return best;
    }
    const double discriminant = c1 * c1 - 4.0 * c2 * c0;
    if (discriminant < 0.0)
        return best;
    const double q = -0.5 * (c1 + std::copysign(std::sqrt(discriminant), c1));
    if (q != 0.0) {
        consider(q / c2);
        consider(c0 / q);
    }
    return best;
}

}  // namespace

void FaceOffsettingOptions::validate() const {
    if (!(primary_eigenvalue_ratio > 0.0 && primary_eigenvalue_ratio < 1.0))
        throw std::invalid_argument("primary_eigenvalue_ratio: expected a number in (0, 1), got " +
                                    std::to_string(primary_eigenvalue_ratio));
    if (!(max_offset_ratio >= 1.0) || !std::isfinite(max_offset_ratio))
        throw std::invalid_argument("max_offset_ratio: expected a finite number >= 1, got " +
                                    std::to_string(max_offset_ratio));
    if (!(smooth_dihedral_degrees >= 0.0 && smooth_dihedral_degrees < 180.0))
        throw std::invalid_argument("smooth_dihedral_degrees: expected a number in [0, 180), got " +
                                    std::to_string(smooth_dihedral_degrees));
    if (!(null_space_smoothing >= 0.0 && null_space_smoothing <= 1.0))
        throw std::invalid_argument("null_space_smoothing: expected a number in [0, 1], got " +
                                    std::to_string(null_space_smoothing));
}

void InversionLimitOptions::validate() const {
    if (!(min_area_fraction >= 0.0 && min_area_fraction < 1.0))
        throw std::invalid_argument("min_area_fraction: expected a number in [0, 1), got " +
                                    std::to_string(min_area_fraction));
}

void NormalTurnLimit::validate() const {
    if (!(max_angle_degrees > 0.0 && max_angle_degrees < 180.0))
        throw std::invalid_argument("max_angle_degrees: expected a number in (0, 180), got " +
                                    std::to_string(max_angle_degrees));
}

FaceOffset face_offset_displacements(const SurfaceMesh& mesh,
                                     const std::vector<double>& triangle_speeds, double dt,
                                     const FaceOffsettingOptions& options) {
    options.validate();
    if (triangle_speeds.size() != static_cast<size_t>(mesh.num_triangles()))
        throw std::invalid_argument("triangle_speeds: expected one speed per triangle slot (" +
                                    std::to_string(mesh.num_triangles()) + "), got " +
                                    std::to_string(triangle_speeds.size()));
    if (!std::isfinite(dt))
        throw std::invalid_argument("dt: expected a finite number");

    const size_t nv = static_cast<size_t>(mesh.num_vertices());
    std::vector<Eigen::Matrix3d> a_matrix(nv, Eigen::Matrix3d::Zero());
    std::vector<Vec3> b_vector(nv, Vec3::Zero());
    std::vector<Vec3> centroid_sum(nv, Vec3::Zero());
    std::vector<double> area_sum(nv, 0.0);
    std::vector<Vec3> normal_sum(nv, Vec3::Zero());  // Σ wᵢ nᵢ
    std::vector<double> offset_sum(nv, 0.0);         // Σ wᵢ hᵢ
    std::vector<double> weight_sum(nv, 0.0);         // Σ wᵢ
    std::vector<double> max_offset(nv, 0.0);         // maxᵢ |hᵢ|

    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        const std::array<Vec3, 3> p = {mesh.position(t[0]), mesh.position(t[1]),
                                       mesh.position(t[2])};
        const Vec3 area_vector = (p[1] - p[0]).cross(p[2] - p[0]);
        if (is_degenerate(area_vector, p[0], p[1], p[2]))
            continue;
        const double area = 0.5 * area_vector.norm();
        const Vec3 n = area_vector.normalized();
        const double offset = triangle_speeds[static_cast<size_t>(ti)] * dt;
        const Eigen::Matrix3d nn = n * n.transpose();
        const Vec3 centroid = (p[0] + p[1] + p[2]) / 3.0;
        for (int k = 0; k < 3; ++k) {
            const size_t vi = static_cast<size_t>(t[k]);
            const double w = options.weighting == OffsetWeighting::area
                                 ? area
                                 : corner_angle(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            a_matrix[vi] += w * nn;
            b_vector[vi] += w * offset * n;
            centroid_sum[vi] += area * centroid;
            area_sum[vi] += area;
            normal_sum[vi] += w * n;
            offset_sum[vi] += w * offset;
            weight_sum[vi] += w;
            max_offset[vi] = std::max(max_offset[vi], std::abs(offset));
        }
    }

    FaceOffset result;
    result.displacements.assign(nv, Vec3::Zero());
    result.primary_rank.assign(nv, 0);
    result.expanding.assign(nv, 0);
    result.capped.assign(nv, 0);
    const double smooth_dihedral = options.smooth_dihedral_degrees * M_PI / 180.0;
    // Signed dihedral angle of each vertex's sharpest incident edge (convex > 0).
    const std::vector<double> dominant_dihedral = dominant_dihedral_angles(mesh);
    for (size_t vi = 0; vi < nv; ++vi) {
        if (!mesh.vertex_alive(static_cast<int>(vi)) || area_sum[vi] <= 0.0)
            continue;
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(a_matrix[vi]);
        const Vec3 lambda = eigen.eigenvalues();  // ascending
        const Eigen::Matrix3d& e = eigen.eigenvectors();
        const double lambda_max = lambda[2];
        if (!(lambda_max > 0.0))
            continue;
        Vec3 d = Vec3::Zero();
        Eigen::Matrix3d null_projector = Eigen::Matrix3d::Zero();
        int rank = 0;
        for (int k = 2; k >= 0; --k) {
            const Vec3 ek = e.col(k);
            if (lambda[k] >= options.primary_eigenvalue_ratio * lambda_max) {
                d += (ek.dot(b_vector[vi]) / lambda[k]) * ek;
                ++rank;
            } else {
                null_projector += ek * ek.transpose();
            }
        }
        const double normal_length = normal_sum[vi].norm();
        if (options.expansion == ExpansionRule::huygens && normal_length > 0.0) {
            const Vec3 m = normal_sum[vi] / normal_length;
            const double mean_offset = offset_sum[vi] / weight_sum[vi];
            const double dihedral = dominant_dihedral[vi];
            // Convex or flat only: on a concave patch moving outward (the neck after a merge)
            // characteristics do cross, and the mean-normal move there compresses triangles
            // until the inversion limit cuts the step (A1 at ξ = 0.02: 1137 steps instead of 445).
            const bool smooth = dihedral >= 0.0 && dihedral < smooth_dihedral;
            const bool expansion =
                std::abs(dihedral) > FLAT_DIHEDRAL && mean_offset * dihedral > 0.0;
            if (smooth || expansion) {
                d = mean_offset * m;
                result.expanding[vi] = expansion ? 1 : 0;
            }
        }
        const double cap = options.max_offset_ratio * max_offset[vi];
        if (d.norm() > cap) {
            d *= cap / d.norm();
            result.capped[vi] = 1;
        }
        if (options.null_space_smoothing > 0.0) {
            const Vec3 to_centroid =
                centroid_sum[vi] / area_sum[vi] - mesh.position(static_cast<int>(vi));
            d += options.null_space_smoothing * (null_projector * to_centroid);
        }
        result.displacements[vi] = d;
        result.primary_rank[vi] = rank;
    }
    return result;
}

FaceOffset face_offset_displacements(const SurfaceMesh& mesh, double speed, double dt,
                                     const FaceOffsettingOptions& options) {
    return face_offset_displacements(
        mesh, std::vector<double>(static_cast<size_t>(mesh.num_triangles()), speed), dt, options);
}

double max_non_inverting_step_fraction(const SurfaceMesh& mesh,
                                       const std::vector<Vec3>& displacements,
                                       const InversionLimitOptions& options) {
    options.validate();
    if (displacements.size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument("displacements: expected one per vertex slot (" +
                                    std::to_string(mesh.num_vertices()) + "), got " +
                                    std::to_string(displacements.size()));
    double fraction = 1.0;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        const Vec3& a = mesh.position(t[0]);
        const Vec3& b = mesh.position(t[1]);
        const Vec3& c = mesh.position(t[2]);
        const Vec3 e1 = b - a, e2 = c - a;
        const Vec3 area_vector = e1.cross(e2);
        if (is_degenerate(area_vector, a, b, c))
            continue;
        const Vec3 n0 = area_vector.normalized();
        const Vec3& da = displacements[static_cast<size_t>(t[0])];
        const Vec3 f1 = displacements[static_cast<size_t>(t[1])] - da;
        const Vec3 f2 = displacements[static_cast<size_t>(t[2])] - da;
        // n0 · ((e1 + τ f1) × (e2 + τ f2)) = q0 + q1 τ + q2 τ²; keep it ≥ min_area_fraction·q0.
        const double q0 = area_vector.norm();
        const double q1 = n0.dot(e1.cross(f2) + f1.cross(e2));
        const double q2 = n0.dot(f1.cross(f2));
        const double root = smallest_positive_root((1.0 - options.min_area_fraction) * q0, q1, q2);
        fraction = std::min(fraction, root);
    }
    return std::max(fraction, 0.0);
}

FaceOffsetStep face_offset_step(const SurfaceMesh& mesh, const std::vector<double>& triangle_speeds,
                                double dt_max, const FaceOffsettingOptions& offsetting,
                                const InversionLimitOptions& inversion) {
    offsetting.validate();
    inversion.validate();
    if (!(dt_max > 0.0) || !std::isfinite(dt_max))
        throw std::invalid_argument("dt_max: expected a finite number > 0");
    FaceOffsetStep step;
    step.dt = dt_max;
    const bool linear_in_dt = offsetting.null_space_smoothing == 0.0;
    while (true) {
        step.displacements =
            face_offset_displacements(mesh, triangle_speeds, step.dt, offsetting).displacements;
        ++step.attempts;
        const double fraction =
            max_non_inverting_step_fraction(mesh, step.displacements, inversion);
        if (fraction >= 1.0)
            break;
        step.shortened = true;
        if (linear_in_dt || step.attempts >= MAX_STEP_ATTEMPTS) {
            // d(τ Δt) = τ d(Δt) when displacements are linear in Δt; otherwise (out of attempts)
            // scaling the last displacements back is still inversion-free along straight lines.
            for (Vec3& d : step.displacements)
                d *= fraction;
            step.dt *= fraction;
            break;
        }
        step.dt *= step.attempts == 1 ? fraction : fraction * RETRY_REDUCTION;
    }
    return step;
}

bool triangle_normal_turn_too_large(const Vec3& reference_normal, const Vec3& a, const Vec3& b,
                                    const Vec3& c, const NormalTurnLimit& limit) {
    limit.validate();
    const double reference_length = reference_normal.norm();
    if (!(reference_length > 0.0))
        throw std::invalid_argument("reference_normal: expected a nonzero vector");
    const Vec3 area_vector = (b - a).cross(c - a);
    if (is_degenerate(area_vector, a, b, c))
        return true;
    const double cosine =
        area_vector.dot(reference_normal) / (area_vector.norm() * reference_length);
    return cosine < std::cos(limit.max_angle_degrees * M_PI / 180.0);
}

bool operation_turns_normals_too_far(const std::vector<TriangleCorners>& old_triangles,
                                     const std::vector<TriangleCorners>& new_triangles,
                                     const NormalTurnLimit& limit) {
    limit.validate();
    if (old_triangles.empty())
        throw std::invalid_argument("old_triangles: expected at least one triangle");
    Vec3 mean_normal = Vec3::Zero();
    double scale = 0.0;
    for (const TriangleCorners& t : old_triangles) {
        mean_normal += (t[1] - t[0]).cross(t[2] - t[0]);
        scale = std::max(scale, longest_edge_squared(t[0], t[1], t[2]));
    }
    if (mean_normal.norm() <= DEGENERATE_AREA_RATIO * scale)
        return true;
    for (const TriangleCorners& t : new_triangles)
        if (triangle_normal_turn_too_large(mean_normal, t[0], t[1], t[2], limit))
            return true;
    return false;
}

}  // namespace meniscus::tracker
