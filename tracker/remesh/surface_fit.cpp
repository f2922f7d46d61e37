#include "tracker/remesh/surface_fit.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace meniscus::tracker {

namespace {

/// Design matrices whose normal matrix has an LDLT pivot below the square of this times its
/// largest (columns are scaled to the patch radius) count as rank-deficient.
constexpr double RANK_TOLERANCE = 1e-6;
constexpr int QUADRATIC_COEFFICIENTS = 6;
constexpr int CUBIC_COEFFICIENTS = 10;
constexpr int QUARTIC_COEFFICIENTS = 15;
using Coefficients = Eigen::Matrix<double, QUARTIC_COEFFICIENTS, 1>;
/// arc_edge_point(): the two vertex normals may be at most 120° apart, and the arc's half angle
/// (between the chord and each end's tangent plane) at most 60°.
constexpr double ARC_MIN_NORMAL_COSINE = -0.5;
constexpr double ARC_MAX_HALF_ANGLE = M_PI / 3.0;

/// Unit vector orthogonal to unit n.
Vec3 any_orthogonal(const Vec3& n) {
    const Vec3 axis = std::abs(n.x()) < 0.6 ? Vec3::UnitX() : Vec3::UnitY();
    return n.cross(axis).normalized();
}

/// The vertices where the mesh has them. `near(vi, reference)`: at the image nearest
/// `reference` on a periodic mesh (a stencil is read around one reference point).
struct MeshPositions {
    const SurfaceMesh& mesh;
    const Vec3& operator()(int vi) const { return mesh.position(vi); }
    Vec3 near(int vi, const Vec3& reference) const { return mesh.position_near(vi, reference); }
};
/// The vertices at given positions, one per vertex slot (read with the mesh's periods).
struct GivenPositions {
    const std::vector<Vec3>& positions;
    const MeshPeriods* periods;  ///< null when the mesh is not periodic
    const Vec3& operator()(int vi) const { return positions[static_cast<size_t>(vi)]; }
    Vec3 near(int vi, const Vec3& reference) const {
        const Vec3& p = positions[static_cast<size_t>(vi)];
        return periods ? periods->nearest_image(p, reference) : p;
    }
};

/// Area vector (twice the area, along the normal) of live triangle ti.
template <typename Positions>
Vec3 area_vector(const SurfaceMesh& mesh, const Positions& position, int ti) {
    const Triangle& t = mesh.triangle(ti);
    const Vec3& a = position(t[0]);
    return (position.near(t[1], a) - a).cross(position.near(t[2], a) - a);
}
Vec3 area_vector(const SurfaceMesh& mesh, int ti) {
    return area_vector(mesh, MeshPositions{mesh}, ti);
}

/// Appends the vertices of vi's triangles (vi included) to `out`.
void append_one_ring(const SurfaceMesh& mesh, int vi, std::vector<int>& out) {
    out.push_back(vi);
    for (int ti : mesh.vertex_triangles(vi))
        for (int w : mesh.triangle(ti))
            out.push_back(w);
}

/// `ids` without repeats, in the order of their first appearance, into `out`. A per-thread
/// stamp per vertex id makes this linear: the scan of `out` for each id it replaced was 18 % of
/// a quartic fit (the two-ring lists about 130 ids, 19 of them distinct), and sorting was 29 %
/// of A1's run time at ξ = 0.02.
void unique_in_order(const std::vector<int>& ids, std::vector<int>& out) {
    thread_local std::vector<unsigned> stamp;
    thread_local unsigned generation = 0;
    if (++generation == 0) {  // wrapped: forget every old stamp
        std::fill(stamp.begin(), stamp.end(), 0u);
        generation = 1;
    }
    out.clear();
    for (int id : ids) {
        const size_t i = static_cast<size_t>(id);
        if (i >= stamp.size())
            stamp.resize(std::max(i + 1, 2 * stamp.size()), 0u);
        if (stamp[i] != generation) {
            stamp[i] = generation;
            out.push_back(id);
        }
    }
}

/// A solved height field: scaled coefficients (zero-padded to 15) and the c of
/// h = p + c·h² they were fitted with (SurfaceFitOptions::sphere_refit; 0: none).
struct HeightField {
    Coefficients scaled;
    double height_squared = 0.0;
};

/// Least-squares height field with N coefficients (6: quadratic, 10: cubic, 15: quartic, in the
/// order of the file comment) through `local` ((s, t, h) in the patch frame), in units of the
/// patch radius, or nullopt where the design is rank-deficient or a vertex is further than
/// `max_residual_fraction` of the radius from it. FIRST = 1 leaves c₀ out (it stays 0): the fit
/// passes through the frame origin. `refit`, given the first solution, returns the c with
/// which to fit h − c·h² instead (SurfaceFitOptions::sphere_refit) or nullopt to keep it; the
/// refit reuses the factorization, since only the heights change.
template <int N, int FIRST, typename Refit>
std::optional<HeightField> solve_height_field(const std::vector<Eigen::Vector3d>& local,
                                              double radius, double max_residual_fraction,
                                              const Refit& refit) {
    constexpr int M = N - FIRST;
    const double inv = 1.0 / radius;
    using Row = Eigen::Matrix<double, M, 1>;
    const auto design_row = [inv](const Eigen::Vector3d& l) {
        const double s = l.x() * inv, t = l.y() * inv;
        const double ss = s * s, tt = t * t;
        Coefficients all;
        all << 1.0, s, t, ss, s * t, tt, ss * s, ss * t, s * tt, tt * t, ss * ss, ss * s * t,
            ss * tt, s * tt * t, tt * tt;
        return Row(all.template segment<M>(FIRST));
    };
    // Normal equations, every column O(1) in these units. Fixed-size keeps this off the heap;
    // it runs for every smooth vertex on every smoothing step. The full outer product
    // (vectorized, inlined) took 11 % less time per quartic fit than rankUpdate of the lower
    // half. The rows are kept for the residuals and the refit (per-thread scratch).
    thread_local std::vector<Row> rows;
    rows.resize(local.size());
    Eigen::Matrix<double, M, M> normal_matrix = Eigen::Matrix<double, M, M>::Zero();
    Row right = Row::Zero();
    for (size_t i = 0; i < local.size(); ++i) {
        rows[i] = design_row(local[i]);
        normal_matrix.noalias() += rows[i] * rows[i].transpose();
        right += local[i].z() * rows[i];
    }
    // Pivoted LDLT of AᵀA: its pivots bound the squared singular values of A.
    const Eigen::LDLT<Eigen::Matrix<double, M, M>> ldlt(normal_matrix);
    const Row pivots = ldlt.vectorD().cwiseAbs();
    if (ldlt.info() != Eigen::Success || !(pivots.maxCoeff() > 0.0) ||
        pivots.minCoeff() < RANK_TOLERANCE * RANK_TOLERANCE * pivots.maxCoeff())
        return std::nullopt;
    // Solves for the heights h − c·h² and checks the residuals.
    const auto solve = [&](const Row& rhs, double c) -> std::optional<HeightField> {
        const Row scaled = ldlt.solve(rhs);
        double residual = 0.0;
        for (size_t i = 0; i < local.size(); ++i) {
            const double h = local[i].z();
            residual = std::max(residual, std::abs(rows[i].dot(scaled) - (h - c * h * h)));
        }
        if (!(residual <= max_residual_fraction * radius))
            return std::nullopt;
        HeightField field;
        field.scaled = Coefficients::Zero();
        field.scaled.template segment<M>(FIRST) = scaled;
        field.height_squared = c;
        return field;
    };
    const std::optional<HeightField> first = solve(right, 0.0);
    if (!first)
        return std::nullopt;
    const std::optional<double> c = refit(first->scaled);
    if (!c)
        return first;
    Row refit_right = Row::Zero();
    for (size_t i = 0; i < local.size(); ++i) {
        const double h = local[i].z();
        refit_right += (h - *c * h * h) * rows[i];
    }
    return solve(refit_right, *c);
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
    if (degree < 2 || degree > 4)
        throw std::invalid_argument("degree: expected 2, 3 or 4, got " + std::to_string(degree));
}

namespace {

/// h of h = p + c·h² for p = `p`: the root that tends to p as c → 0.
double height_of(double p, double c) {
    const double cp = c * p;
    // 2p / (1 + sqrt(1 − 4cp)) is that root without cancellation; beyond the fold (1 − 4cp < 0)
    // the surface has no point above, and the fold's height is the nearest.
    return 2.0 * p / (1.0 + std::sqrt(std::max(0.0, 1.0 - 4.0 * cp)));
}

/// Height h, gradient and Hessian of h = p + c·h² at the frame origin from p's there:
/// h_i = p_i / (1 − 2ch), h_ij = (p_ij + 2c h_i h_j) / (1 − 2ch).
struct OriginJet {
    double h, hs, ht, hss, hst, htt;
};
OriginJet origin_jet(const SurfacePatch& patch) {
    const auto& c = patch.coefficients;
    const double k = patch.height_squared;
    OriginJet j;
    j.h = height_of(c[0], k);
    const double inv = 1.0 / (1.0 - 2.0 * k * j.h);
    j.hs = c[1] * inv;
    j.ht = c[2] * inv;
    j.hss = (2.0 * c[3] + 2.0 * k * j.hs * j.hs) * inv;
    j.hst = (c[4] + 2.0 * k * j.hs * j.ht) * inv;
    j.htt = (2.0 * c[5] + 2.0 * k * j.ht * j.ht) * inv;
    return j;
}

}  // namespace

Vec3 SurfacePatch::point_above(const Vec3& x) const {
    const Vec3 r = x - origin;
    const double s = r.dot(u), t = r.dot(v);
    const auto& c = coefficients;
    const double ss = s * s, tt = t * t;
    const double h = c[0] + c[1] * s + c[2] * t + c[3] * ss + c[4] * s * t + c[5] * tt +
                     c[6] * ss * s + c[7] * ss * t + c[8] * s * tt + c[9] * tt * t +
                     c[10] * ss * ss + c[11] * ss * s * t + c[12] * ss * tt + c[13] * s * tt * t +
                     c[14] * tt * tt;
    return origin + s * u + t * v + height_of(h, height_squared) * normal;
}

double SurfacePatch::mean_curvature() const {
    const OriginJet j = origin_jet(*this);
    const double g = 1.0 + j.hs * j.hs + j.ht * j.ht;
    return -((1.0 + j.ht * j.ht) * j.hss - 2.0 * j.hs * j.ht * j.hst + (1.0 + j.hs * j.hs) * j.htt) /
           (g * std::sqrt(g));
}

Vec3 SurfacePatch::surface_normal() const {
    const OriginJet j = origin_jet(*this);
    return (normal - j.hs * u - j.ht * v).normalized();
}

double SurfacePatch::turn() const {
    // Hessian [[a, b], [b, c]] of h at the origin.
    const OriginJet j = origin_jet(*this);
    const double a = j.hss, b = j.hst, c = j.htt;
    return radius * (0.5 * std::abs(a + c) + std::hypot(0.5 * (a - c), b));
}

namespace {

template <typename Positions>
std::optional<SurfacePatch> fit_patch(const SurfaceMesh& mesh, const Positions& position,
                                      const std::vector<int>& vertices,
                                      const std::vector<int>& triangles, const Vec3& origin,
                                      const Vec3& normal, const SurfaceFitOptions& options) {
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
        const Vec3 a = area_vector(mesh, position, ti);
        const double length = a.norm();
        if (!(length > 0.0) || a.dot(patch.normal) < min_cosine * length)
            return std::nullopt;
    }

    // A few dozen ids with many repeats, kept in their order (the fit sums its rows in it).
    // Per-thread scratch: a fit runs for every vertex on every step, and these two
    // allocations were 5 % of an A2 run at ξ = 0.01.
    thread_local std::vector<int> ids;
    thread_local std::vector<Eigen::Vector3d> local;
    unique_in_order(vertices, ids);
    if (ids.size() < static_cast<size_t>(QUADRATIC_COEFFICIENTS))
        return std::nullopt;

    local.resize(ids.size());
    double radius_squared = 0.0;
    for (size_t i = 0; i < ids.size(); ++i) {
        const Vec3 r = position.near(ids[i], origin) - origin;
        local[i] = {r.dot(patch.u), r.dot(patch.v), r.dot(patch.normal)};
        radius_squared =
            std::max(radius_squared, local[i].x() * local[i].x() + local[i].y() * local[i].y());
    }
    patch.radius = std::sqrt(radius_squared);
    if (!(patch.radius > 0.0))
        return std::nullopt;
    const double inv = 1.0 / patch.radius;
    // Back from units of the patch radius: a term of degree k scales by inv^k.
    const double inv2 = inv * inv;
    const double power[5] = {1.0, inv, inv2, inv2 * inv, inv2 * inv2};
    const auto unscale = [&patch, &power](const Coefficients& c) {
        static constexpr int TERM_DEGREE[QUARTIC_COEFFICIENTS] = {0, 1, 1, 2, 2, 2, 3, 3,
                                                                  3, 3, 4, 4, 4, 4, 4};
        for (int k = 0; k < QUARTIC_COEFFICIENTS; ++k)
            patch.coefficients[k] = c[k] * power[TERM_DEGREE[k]];
        return patch.coefficients.allFinite();
    };
    // sphere_refit: c = −κ/4 of the first fit (SurfaceFitOptions::sphere_refit); the patch's
    // height_squared is still 0 here, so mean_curvature() is the first fit's.
    const auto refit = [&](const Coefficients& scaled) -> std::optional<double> {
        if (!options.sphere_refit || !unscale(scaled))
            return std::nullopt;
        return -0.25 * patch.mean_curvature();
    };
    // The highest degree asked for that the patch supports, falling back one degree at a time.
    std::optional<HeightField> field;
    const auto solve = [&](auto coefficients) {
        constexpr int n = decltype(coefficients)::value;
        return options.through_origin
                   ? solve_height_field<n, 1>(local, patch.radius, options.max_residual_fraction,
                                              refit)
                   : solve_height_field<n, 0>(local, patch.radius, options.max_residual_fraction,
                                              refit);
    };
    // A degree is fitted only where more vertices than its unknowns constrain it: an
    // interpolant has no residual to refuse a crease by, and its coefficients swing with every
    // vertex (a quartic through a valence-4 vertex and its 14 neighbours moved its κ by up to
    // 6e5 per metre a neighbour moved; see fitted_mean_curvature_normals()). Through the
    // origin, a vertex at the origin constrains nothing.
    const int fixed = options.through_origin ? 1 : 0;
    int constraining = 0;
    for (const Eigen::Vector3d& l : local)
        constraining += fixed == 0 || l.x() != 0.0 || l.y() != 0.0;
    const auto fits = [&](int degree, int coefficients) {
        return !field && options.degree >= degree && constraining > coefficients - fixed;
    };
    if (fits(4, QUARTIC_COEFFICIENTS)) {
        field = solve(std::integral_constant<int, QUARTIC_COEFFICIENTS>{});
        patch.degree = 4;
    }
    if (fits(3, CUBIC_COEFFICIENTS)) {
        field = solve(std::integral_constant<int, CUBIC_COEFFICIENTS>{});
        patch.degree = 3;
    }
    if (fits(2, QUADRATIC_COEFFICIENTS)) {
        field = solve(std::integral_constant<int, QUADRATIC_COEFFICIENTS>{});
        patch.degree = 2;
    }
    if (!field || !unscale(field->scaled))
        return std::nullopt;
    patch.height_squared = field->height_squared;
    return patch;
}

template <typename Positions>
std::optional<SurfacePatch> vertex_patch_at(const SurfaceMesh& mesh, const Positions& position,
                                            int vi, const SurfaceFitOptions& options) {
    if (mesh.vertex_triangles(vi).empty() || mesh.is_boundary_vertex(vi))
        return std::nullopt;
    // The one-ring alone (about 7 vertices) barely determines 6 coefficients: fit the two-ring.
    thread_local std::vector<int> one_ring, ring, vertices, triangles;  // per-thread scratch
    one_ring.clear();
    vertices.clear();
    triangles.clear();
    append_one_ring(mesh, vi, one_ring);
    // Each neighbour appears once per triangle it shares with vi: expand it once. Its later
    // repeats only repeated ids already listed (the fit's vertex order is unchanged) and
    // tripled the work of every fit.
    unique_in_order(one_ring, ring);
    for (int w : ring) {
        append_one_ring(mesh, w, vertices);
        triangles.insert(triangles.end(), mesh.vertex_triangles(w).begin(),
                         mesh.vertex_triangles(w).end());
    }
    // Triangles shared by neighbours repeat only the graph check; not worth removing.
    Vec3 normal = Vec3::Zero();
    for (int ti : mesh.vertex_triangles(vi))
        normal += area_vector(mesh, position, ti);
    if (!(normal.norm() > 0.0))
        return std::nullopt;
    return fit_patch(mesh, position, vertices, triangles, position(vi), normal, options);
}

}  // namespace

std::optional<SurfacePatch> fit_surface_patch(const SurfaceMesh& mesh,
                                              const std::vector<int>& vertices,
                                              const std::vector<int>& triangles, const Vec3& origin,
                                              const Vec3& normal,
                                              const SurfaceFitOptions& options) {
    return fit_patch(mesh, MeshPositions{mesh}, vertices, triangles, origin, normal, options);
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
    // Periodic meshes: the edge (and the fit, through fit_patch) at the minimum image of e[0].
    const std::array<Vec3, 2> ends = mesh.edge_positions(ei);
    const Vec3 midpoint = 0.5 * (ends[0] + ends[1]);
    const std::optional<SurfacePatch> patch =
        fit_surface_patch(mesh, vertices, triangles, midpoint, normal, options);
    if (!patch)
        return std::nullopt;
    // The least-squares surface misses the endpoints by its residuals there (a quadratic fitted
    // to a sphere cap sits above it in the middle): shift it by their mean so that it
    // interpolates the edge's ends on average.
    const Vec3 residual = 0.5 * (patch->point_above(ends[0]) - ends[0] +
                                 patch->point_above(ends[1]) - ends[1]);
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
    const auto [p0, p1] = mesh.edge_positions(ei);  // periodic: at the minimum image of e[0]
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
    return vertex_patch_at(mesh, MeshPositions{mesh}, vi, options);
}

std::optional<SurfacePatch> vertex_patch(const SurfaceMesh& mesh,
                                         const std::vector<Vec3>& positions, int vi,
                                         const SurfaceFitOptions& options) {
    if (positions.size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument("positions: expected one per vertex slot");
    return vertex_patch_at(
        mesh, GivenPositions{positions, mesh.periodic() ? &mesh.periods() : nullptr}, vi,
        options);
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
