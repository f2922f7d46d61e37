#include "tracker/crease_snap.h"

#include "tracker/implicit_mesher.h"
#include "tracker/mesh_measures.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace meniscus::tracker {

namespace {

constexpr double DEGREES_TO_RADIANS = M_PI / 180.0;
/// A group of normals is one face of a crease when its normals stay within this fraction of
/// the angle between the groups' means (a smooth, strongly curved patch spreads evenly).
constexpr double MAX_GROUP_SPREAD_FRACTION = 1.0 / 3.0;
/// A vertex this close to its feature point (fraction of its shortest edge) is on the crease.
constexpr double ON_CREASE_FRACTION = 1e-3;
/// An edge whose midpoint is within this fraction of its length of the surface is not flipped.
constexpr double FLIP_MIN_DEVIATION_FRACTION = 1e-6;
/// Minimum valence kept by flips on a closed mesh.
constexpr int MIN_VALENCE = 3;

Vec3 unit_normal(const ImplicitShape& shape, const Vec3& x) {
    const Vec3 g = shape.gradient(x);
    const double n = g.norm();
    return n > 0.0 ? Vec3(g / n) : Vec3::Zero();
}

double angle_between(const Vec3& a, const Vec3& b) {
    return std::atan2(a.cross(b).norm(), a.dot(b));
}

/// Number of groups (2: crease, 3: corner; 0: none) the normals fall into: groups whose means
/// turn by more than `angle` from each other and whose members stay within
/// MAX_GROUP_SPREAD_FRACTION of that turn of their own mean.
int feature_rank(const std::vector<Vec3>& normals, double angle) {
    const size_t n = normals.size();
    // Seeds: the two normals farthest apart.
    size_t s0 = 0, s1 = 0;
    double widest = -1.0;
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j) {
            const double a = angle_between(normals[i], normals[j]);
            if (a > widest) {
                widest = a;
                s0 = i;
                s1 = j;
            }
        }
    if (!(widest > angle))
        return 0;
    std::vector<Vec3> seeds = {normals[s0], normals[s1]};
    for (int groups = 2; groups <= 3; ++groups) {
        // Two rounds of assigning to the nearest mean and recomputing the means.
        std::vector<int> group(n, 0);
        for (int round = 0; round < 2; ++round) {
            std::vector<Vec3> sum(seeds.size(), Vec3::Zero());
            for (size_t i = 0; i < n; ++i) {
                int best = 0;
                for (int g = 1; g < static_cast<int>(seeds.size()); ++g)
                    if (normals[i].dot(seeds[static_cast<size_t>(g)]) >
                        normals[i].dot(seeds[static_cast<size_t>(best)]))
                        best = g;
                group[i] = best;
                sum[static_cast<size_t>(best)] += normals[i];
            }
            for (size_t g = 0; g < seeds.size(); ++g)
                if (sum[g].norm() > 0.0)
                    seeds[g] = sum[g].normalized();
        }
        double separation = M_PI, spread = 0.0;
        for (size_t g = 0; g < seeds.size(); ++g)
            for (size_t h = g + 1; h < seeds.size(); ++h)
                separation = std::min(separation, angle_between(seeds[g], seeds[h]));
        double farthest = 0.0;  // the member farthest from its own mean
        size_t outlier = 0;
        for (size_t i = 0; i < n; ++i) {
            const double a = angle_between(normals[i], seeds[static_cast<size_t>(group[i])]);
            spread = std::max(spread, a);
            if (a > farthest) {
                farthest = a;
                outlier = i;
            }
        }
        if (separation > angle && spread < MAX_GROUP_SPREAD_FRACTION * separation)
            return groups;
        if (groups == 3 || !(farthest > angle))
            return 0;
        seeds.push_back(normals[outlier]);  // try a corner
    }
    return 0;
}

/// Where vertex vi would go: the point nearest to it of the intersection of the tangent planes
/// around it, on φ = 0; none when they show no crease. The planes are sampled at the centroids
/// of vi's triangles moved onto φ = 0, not at vertices: a vertex already on a crease has an
/// ambiguous gradient there (a finite difference across it blends the two faces' normals).
std::optional<Vec3> feature_point(const SurfaceMesh& mesh, const ImplicitShape& shape, int vi,
                                  const CreaseSnapOptions& o) {
    std::vector<Vec3> points, normals;
    for (int ti : mesh.vertex_triangles(vi)) {
        const Triangle& t = mesh.triangle(ti);
        const Vec3 centroid =
            (mesh.position(t[0]) + mesh.position(t[1]) + mesh.position(t[2])) / 3.0;
        points.push_back(project_to_zero_set(shape, centroid, o.projection_iterations));
        normals.push_back(unit_normal(shape, points.back()));
    }
    const int rank = feature_rank(normals, o.angle);
    if (rank == 0)
        return std::nullopt;
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Vec3 b = Vec3::Zero();
    for (size_t k = 0; k < points.size(); ++k) {
        const Eigen::Matrix3d nn = normals[k] * normals[k].transpose();
        a += nn;
        b += nn * points[k];
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(a);
    const Vec3 x = mesh.position(vi);
    const Vec3 residual = b - a * x;
    Vec3 move = Vec3::Zero();
    for (int k = 3 - rank; k < 3; ++k) {  // eigenvalues ascend: the `rank` largest
        const double lambda = eigen.eigenvalues()[k];
        if (!(lambda > 0.0))
            return std::nullopt;
        const Vec3 e = eigen.eigenvectors().col(k);
        move += e * (e.dot(residual) / lambda);
    }
    return project_to_zero_set(shape, x + move, o.projection_iterations);
}

double shortest_edge(const SurfaceMesh& mesh, int vi) {
    double shortest = std::numeric_limits<double>::infinity();
    for (int ei : mesh.vertex_edges(vi))
        shortest = std::min(shortest,
                            (mesh.position(mesh.other_vertex(ei, vi)) - mesh.position(vi)).norm());
    return shortest;
}

Vec3 triangle_normal(const std::array<Vec3, 3>& p) {
    return (p[1] - p[0]).cross(p[2] - p[0]);
}

/// Smallest interior angle of a triangle (radians).
double min_angle(const std::array<Vec3, 3>& p) {
    double smallest = M_PI;
    for (int k = 0; k < 3; ++k) {
        const Vec3 u = p[static_cast<size_t>((k + 1) % 3)] - p[static_cast<size_t>(k)];
        const Vec3 v = p[static_cast<size_t>((k + 2) % 3)] - p[static_cast<size_t>(k)];
        smallest = std::min(smallest, angle_between(u, v));
    }
    return smallest;
}

/// Edge lengths (m) of snap_to_creases(): moves and flips keep edges above `min` (or no
/// shorter than they were); edges above `max` are split.
struct EdgeBounds {
    double min = 0.0, max = 0.0;
    /// Whether an edge going from `before` to `after` long stays allowed (or no worse).
    bool keeps(double before, double after) const { return after >= std::min(min, before); }
};

/// Whether moving vi to `target` keeps each of its triangles within the allowed turn and area,
/// its smallest angle at least min(its old one, min_angle_degrees), and its edges in bounds.
bool move_keeps_triangles(const SurfaceMesh& mesh, int vi, const Vec3& target,
                          const CreaseSnapOptions& o, const EdgeBounds& bounds) {
    for (int ei : mesh.vertex_edges(vi)) {
        const Vec3& other = mesh.position(mesh.other_vertex(ei, vi));
        if (!bounds.keeps((other - mesh.position(vi)).norm(), (other - target).norm()))
            return false;
    }
    const double cos_turn = std::cos(o.max_normal_turn_degrees * DEGREES_TO_RADIANS);
    const double angle_floor = o.min_angle_degrees * DEGREES_TO_RADIANS;
    for (int ti : mesh.vertex_triangles(vi)) {
        const Triangle& t = mesh.triangle(ti);
        std::array<Vec3, 3> before, after;
        for (int k = 0; k < 3; ++k) {
            before[static_cast<size_t>(k)] = mesh.position(t[static_cast<size_t>(k)]);
            after[static_cast<size_t>(k)] =
                t[static_cast<size_t>(k)] == vi ? target : before[static_cast<size_t>(k)];
        }
        const Vec3 n0 = triangle_normal(before), n1 = triangle_normal(after);
        const double a0 = n0.norm(), a1 = n1.norm();
        if (!(a1 > o.min_area_fraction * a0) || !(n0.dot(n1) >= cos_turn * a0 * a1))
            return false;
        if (min_angle(after) < std::min(min_angle(before), angle_floor))
            return false;
    }
    return true;
}

int snap_pass(SurfaceMesh& mesh, const ImplicitShape& shape, const CreaseSnapOptions& o,
              const EdgeBounds& bounds) {
    struct Candidate {
        double distance;
        int vi;
    };
    std::vector<Candidate> candidates;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi) || mesh.vertex_triangles(vi).empty())
            continue;
        const std::optional<Vec3> p = feature_point(mesh, shape, vi, o);
        if (p)
            candidates.push_back({(*p - mesh.position(vi)).norm(), vi});
    }
    // Nearest first: the vertices already closest to a crease define it.
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
        return a.distance != b.distance ? a.distance < b.distance : a.vi < b.vi;
    });
    int snaps = 0;
    for (const Candidate& c : candidates) {
        const std::optional<Vec3> p = feature_point(mesh, shape, c.vi, o);  // neighbours moved
        if (!p)
            continue;
        const double move = (*p - mesh.position(c.vi)).norm();
        const double shortest = shortest_edge(mesh, c.vi);
        if (move <= ON_CREASE_FRACTION * shortest || move > o.max_move_fraction * shortest ||
            !move_keeps_triangles(mesh, c.vi, *p, o, bounds))
            continue;
        mesh.set_position(c.vi, *p);
        ++snaps;
    }
    return snaps;
}

int flip_pass(SurfaceMesh& mesh, const ImplicitShape& shape, const CreaseSnapOptions& o,
              const EdgeBounds& bounds) {
    const double cos_turn = std::cos(o.max_normal_turn_degrees * DEGREES_TO_RADIANS);
    const double angle_floor = o.min_angle_degrees * DEGREES_TO_RADIANS;
    int flips = 0;
    const int edges = mesh.num_edges();  // new diagonals wait for the next pass
    for (int ei = 0; ei < edges; ++ei) {
        if (!mesh.edge_alive(ei) || mesh.edge_triangles(ei).size() != 2)
            continue;
        int t0 = mesh.edge_triangles(ei)[0], t1 = mesh.edge_triangles(ei)[1];
        if (mesh.edge_orientation_in_triangle(t0, ei) == mesh.edge_orientation_in_triangle(t1, ei))
            continue;
        if (mesh.edge_orientation_in_triangle(t0, ei) < 0)
            std::swap(t0, t1);
        // t0 = (a, b, c) traverses a→b, t1 = (b, a, d); the flip makes (c, a, d) and (d, b, c).
        const Edge e = mesh.edge(ei);
        const int a = e[0], b = e[1];
        const int c = mesh.opposite_vertex(t0, ei), d = mesh.opposite_vertex(t1, ei);
        if (c == d || mesh.find_edge(c, d) != INVALID_INDEX)
            continue;
        if (static_cast<int>(mesh.vertex_edges(a).size()) <= MIN_VALENCE ||
            static_cast<int>(mesh.vertex_edges(b).size()) <= MIN_VALENCE)
            continue;
        const Vec3 pa = mesh.position(a), pb = mesh.position(b), pc = mesh.position(c),
                   pd = mesh.position(d);
        const double off_ab = std::abs(shape.value(0.5 * (pa + pb)));
        const double off_cd = std::abs(shape.value(0.5 * (pc + pd)));
        if (!(off_ab > FLIP_MIN_DEVIATION_FRACTION * (pa - pb).norm()) ||
            !(off_cd < 0.5 * off_ab) || !bounds.keeps((pa - pb).norm(), (pc - pd).norm()))
            continue;
        // Both new triangles must lie along the surface where they sit and keep the old side.
        const Vec3 side =
            triangle_normal({pa, pb, pc}).normalized() + triangle_normal({pb, pa, pd}).normalized();
        bool along = true;
        for (const std::array<Vec3, 3>& t :
             {std::array<Vec3, 3>{pc, pa, pd}, std::array<Vec3, 3>{pd, pb, pc}}) {
            const Vec3 n = triangle_normal(t);
            const double nn = n.norm();
            const Vec3 surface = unit_normal(shape, (t[0] + t[1] + t[2]) / 3.0);
            if (!(nn > 0.0) || n.dot(surface) < cos_turn * nn || !(n.dot(side) > 0.0) ||
                min_angle(t) < std::min(angle_floor, std::min(min_angle({pa, pb, pc}),
                                                              min_angle({pb, pa, pd})))) {
                along = false;
                break;
            }
        }
        if (!along)
            continue;
        mesh.flip_edge(ei, t0, t1);
        ++flips;
    }
    return flips;
}

/// Splits the edges longer than `max_length` at their midpoints moved onto φ = 0 (a snapped
/// vertex may stretch its edges; the next pass snaps the new vertices too).
int split_long_edges(SurfaceMesh& mesh, const ImplicitShape& shape, const CreaseSnapOptions& o,
                     double max_length) {
    int splits = 0;
    const int edges = mesh.num_edges();
    for (int ei = 0; ei < edges; ++ei) {
        if (!mesh.edge_alive(ei) || mesh.edge_triangles(ei).size() != 2)
            continue;
        const Edge e = mesh.edge(ei);
        const Vec3 a = mesh.position(e[0]), b = mesh.position(e[1]);
        if ((a - b).norm() <= max_length)
            continue;
        mesh.split_edge(ei, project_to_zero_set(shape, 0.5 * (a + b), o.projection_iterations));
        ++splits;
    }
    return splits;
}

}  // namespace

void CreaseSnapOptions::validate() const {
    if (!(angle > 0.0 && angle < 0.5 * M_PI))
        throw std::invalid_argument("angle: expected radians in (0, pi/2)");
    if (passes < 1)
        throw std::invalid_argument("passes: expected an integer >= 1");
    if (!(max_normal_turn_degrees > 0.0 && max_normal_turn_degrees < 90.0))
        throw std::invalid_argument("max_normal_turn_degrees: expected a number in (0, 90)");
    if (!(min_angle_degrees >= 0.0 && min_angle_degrees < 60.0))
        throw std::invalid_argument("min_angle_degrees: expected a number in [0, 60)");
    if (!(min_area_fraction >= 0.0 && min_area_fraction < 1.0))
        throw std::invalid_argument("min_area_fraction: expected a number in [0, 1)");
    if (!(max_move_fraction > 0.0) || !std::isfinite(max_move_fraction))
        throw std::invalid_argument("max_move_fraction: expected a number > 0");
    if (!(min_edge_fraction > 0.0 && min_edge_fraction < 1.0))
        throw std::invalid_argument("min_edge_fraction: expected a number in (0, 1)");
    if (!(max_edge_fraction > 1.0) || !std::isfinite(max_edge_fraction))
        throw std::invalid_argument("max_edge_fraction: expected a number > 1");
    if (projection_iterations < 0)
        throw std::invalid_argument("projection_iterations: expected an integer >= 0");
}

CreaseSnapReport snap_to_creases(SurfaceMesh& mesh, const ImplicitShape& shape,
                                 const CreaseSnapOptions& options) {
    options.validate();
    CreaseSnapReport report;
    const double mean = edge_length_stats(mesh).mean;
    const EdgeBounds bounds{options.min_edge_fraction * mean, options.max_edge_fraction * mean};
    for (int pass = 0; pass < options.passes; ++pass) {
        const int snaps = snap_pass(mesh, shape, options, bounds);
        const int flips = flip_pass(mesh, shape, options, bounds);
        const int splits = split_long_edges(mesh, shape, options, bounds.max);
        report.snaps += snaps;
        report.flips += flips;
        report.splits += splits;
        if (snaps == 0 && flips == 0 && splits == 0)
            break;
    }
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi) || mesh.vertex_triangles(vi).empty())
            continue;
        const std::optional<Vec3> p = feature_point(mesh, shape, vi, options);
        if (p && (*p - mesh.position(vi)).norm() <= ON_CREASE_FRACTION * shortest_edge(mesh, vi))
            ++report.crease_vertices;
    }
    return report;
}

}  // namespace meniscus::tracker
