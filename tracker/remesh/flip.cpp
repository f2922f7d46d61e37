#include "tracker/remesh/flip.h"

#include "tracker/intersection.h"
#include "tracker/remesh/local_safety.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

namespace meniscus::tracker {

namespace {

constexpr double PI = 3.14159265358979323846;
/// A quad whose angles opposite the edge exceed π by this much (two angles above 112.5°) is
/// far enough from Delaunay to flip across any fold (slivers of thin features, §3.6).
constexpr double ALWAYS_FLIP_EXCESS = PI / 4.0;
/// A new triangle whose doubled area is below this fraction of its longest edge squared is
/// treated as degenerate (the same scale-free tolerance validate_mesh uses by default).
constexpr double DEGENERATE_AREA_FRACTION = 1e-12;

double angle_at(const Vec3& apex, const Vec3& p, const Vec3& q) {
    const Vec3 u = p - apex, v = q - apex;
    return std::atan2(u.cross(v).norm(), u.dot(v));
}

Vec3 normal_of(const Vec3& a, const Vec3& b, const Vec3& c) {
    return (b - a).cross(c - a);
}

bool degenerate(const Vec3& a, const Vec3& b, const Vec3& c) {
    const double longest =
        std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    return normal_of(a, b, c).norm() <= DEGENERATE_AREA_FRACTION * longest;
}

/// The stencil's four vertices; on a periodic mesh at their images nearest a (the minimum image,
/// one reference for the whole stencil).
struct StencilPositions {
    Vec3 a, b, c, d;
};
StencilPositions positions_of(const SurfaceMesh& mesh, const FlipStencil& s) {
    const Vec3& a = mesh.position(s.a);
    return {a, mesh.position_near(s.b, a), mesh.position_near(s.c, a), mesh.position_near(s.d, a)};
}

FlipStencil make_stencil(const SurfaceMesh& mesh, int ei, int t_forward, int t_backward) {
    FlipStencil s;
    s.ei = ei;
    s.t0 = t_forward;
    s.t1 = t_backward;
    s.a = mesh.edge(ei)[0];
    s.b = mesh.edge(ei)[1];
    s.c = mesh.opposite_vertex(t_forward, ei);
    s.d = mesh.opposite_vertex(t_backward, ei);
    return s;
}

/// The oppositely oriented triangle pair of edge ei whose flip shortens the edge most, if any
/// pair should flip at all.
bool best_stencil(const SurfaceMesh& mesh, int ei, const RemeshOptions& options,
                  FlipStencil& best) {
    const auto& et = mesh.edge_triangles(ei);
    double best_length = 0.0;
    bool found = false;
    for (int tf : et) {
        if (mesh.edge_orientation_in_triangle(tf, ei) != 1)
            continue;
        for (int tb : et) {
            if (mesh.edge_orientation_in_triangle(tb, ei) != -1)
                continue;
            const FlipStencil s = make_stencil(mesh, ei, tf, tb);
            if (s.c == s.d || !flip_improves(mesh, s, options))
                continue;
            const StencilPositions p = positions_of(mesh, s);
            const double length = (p.c - p.d).norm();
            if (!found || length < best_length) {
                best = s;
                best_length = length;
                found = true;
            }
        }
    }
    return found;
}

}  // namespace

bool flip_improves(const SurfaceMesh& mesh, const FlipStencil& s, const RemeshOptions& options) {
    const auto [a, b, c, d] = positions_of(mesh, s);
    const double old_length = (a - b).norm();
    const double new_length = (c - d).norm();
    if (!(new_length < (1.0 - options.min_flip_length_decrease_fraction) * old_length))
        return false;
    const double required_excess =
        std::min(options.flip_fold_weight * flip_fold_angle(mesh, s), ALWAYS_FLIP_EXCESS);
    return angle_at(c, a, b) + angle_at(d, a, b) > PI + required_excess;
}

double flip_fold_angle(const SurfaceMesh& mesh, const FlipStencil& s) {
    const auto [a, b, c, d] = positions_of(mesh, s);
    const Vec3 n0 = normal_of(a, b, c);
    const Vec3 n1 = normal_of(b, a, d);
    return std::atan2(n0.cross(n1).norm(), n0.dot(n1));
}

bool flip_creates_existing_edge(const SurfaceMesh& mesh, const FlipStencil& s) {
    return s.c == s.d || mesh.find_edge(s.c, s.d) != INVALID_INDEX;
}

bool flip_changes_volume_too_much(const SurfaceMesh& mesh, const FlipStencil& s, double gamma) {
    const auto [a, b, c, d] = positions_of(mesh, s);
    const double six_volume = (b - a).dot((c - a).cross(d - a));
    return std::abs(six_volume) / 6.0 > gamma;
}

bool flip_changes_normals_too_much(const SurfaceMesh& mesh, const FlipStencil& s,
                                   const RemeshOptions& options) {
    const auto [a, b, c, d] = positions_of(mesh, s);
    if (degenerate(c, a, d) || degenerate(d, b, c))
        return true;
    const double min_cos = std::cos(options.max_normal_change_degrees * PI / 180.0);
    const Vec3 old_normals[2] = {normal_of(a, b, c).normalized(), normal_of(b, a, d).normalized()};
    const Vec3 new_normals[2] = {normal_of(c, a, d).normalized(), normal_of(d, b, c).normalized()};
    for (const Vec3& n_new : new_normals)
        for (const Vec3& n_old : old_normals)
            if (!(n_new.dot(n_old) >= min_cos))
                return true;
    return false;
}

bool flip_intersects(const SurfaceMesh& mesh, const ElementHash& hash, const FlipStencil& s) {
    CandidateTriangles candidates;
    candidates.triangles = {{s.c, s.a, s.d}, {s.d, s.b, s.c}};
    return candidate_triangles_intersect(mesh, hash, candidates, {s.t0, s.t1});
}

bool flip_sweeps_vertex(const SurfaceMesh& mesh, const ElementHash& hash, const FlipStencil& s) {
    const auto [a, b, c, d] = positions_of(mesh, s);
    Box3d box(a);
    box.extend(b);
    box.extend(c);
    box.extend(d);
    std::vector<int> found;
    hash.query_vertices(box, found);
    for (int vi : found) {
        if (!mesh.vertex_alive(vi) || vi == s.a || vi == s.b || vi == s.c || vi == s.d)
            continue;
        if (point_in_tetrahedron(mesh.position_near(vi, a), a, b, c, d))
            return true;
    }
    return false;
}

FlipReport flip_edges(SurfaceMesh& mesh, const RemeshOptions& options,
                      const ImproveContext& context) {
    const auto start = std::chrono::steady_clock::now();
    FlipReport report;
    const double gamma = remesh_limits(options, context.xi).max_volume_change;
    // Built on the first collision check (a pass with nothing to do never pays for it), then
    // kept current through every mutation.
    std::unique_ptr<ElementHash> hash;
    auto current_hash = [&]() -> const ElementHash& {
        if (!hash)
            hash = std::make_unique<ElementHash>(mesh, context.xi);
        return *hash;
    };

    for (int sweep = 0; sweep < options.max_flip_sweeps; ++sweep) {
        context.cancel.throw_if_requested("edge flipping");
        ++report.sweeps;
        int flips_this_sweep = 0;
        const int edge_count = mesh.num_edges();
        for (int ei = 0; ei < edge_count; ++ei) {
            if (!mesh.edge_alive(ei) || mesh.is_boundary_edge(ei))
                continue;
            FlipStencil s;
            if (!best_stencil(mesh, ei, options, s))
                continue;
            if (flip_creates_existing_edge(mesh, s)) {
                ++report.refused_existing_edge;
                continue;
            }
            if (flip_changes_volume_too_much(mesh, s, gamma)) {
                ++report.refused_volume;
                continue;
            }
            if (flip_changes_normals_too_much(mesh, s, options)) {
                ++report.refused_normal;
                continue;
            }
            if (context.collision_safety && flip_intersects(mesh, current_hash(), s)) {
                ++report.refused_intersection;
                continue;
            }
            if (context.collision_safety && flip_sweeps_vertex(mesh, current_hash(), s)) {
                ++report.refused_point_in_tetrahedron;
                continue;
            }
            const std::vector<int> touched = {s.a, s.b, s.c, s.d};
            if (hash)
                hash->begin_update(mesh, touched);
            mesh.flip_edge(ei, s.t0, s.t1);
            if (hash)
                hash->refresh(mesh, touched);
            ++report.flips;
            ++flips_this_sweep;
        }
        if (flips_this_sweep == 0)
            break;
    }
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

}  // namespace meniscus::tracker
