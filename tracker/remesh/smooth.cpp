#include "tracker/remesh/smooth.h"

#include "tracker/broadphase.h"
#include "tracker/ccd.h"
#include "tracker/quadric.h"
#include "tracker/remesh/surface_fit.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>

namespace meniscus::tracker {

namespace {

/// The smoothing pseudo-trajectory lasts one unit of pseudo-time (only displacements matter).
constexpr double PSEUDO_STEP_DURATION = 1.0;
/// Grain of the parallel loop over vertices.
constexpr int VERTICES_PER_TASK = 256;
/// Grain of the parallel CCD loop over candidate pairs.
constexpr size_t PAIRS_PER_TASK = 256;

/// Smallest interior angle (radians) of the triangles around vertex vi.
double smallest_angle_around(const SurfaceMesh& mesh, int vi) {
    double smallest = M_PI;
    for (int ti : mesh.vertex_triangles(vi)) {
        const std::array<Vec3, 3> p = mesh.triangle_positions(ti);  // minimum image
        for (int k = 0; k < 3; ++k) {
            const Vec3 a = p[(k + 1) % 3] - p[k];
            const Vec3 b = p[(k + 2) % 3] - p[k];
            smallest = std::min(smallest, std::atan2(a.cross(b).norm(), a.dot(b)));
        }
    }
    return smallest;
}

/// Holds still (x_t1 = x_t0) every moving vertex of a vertex–triangle or edge–edge pair that may
/// collide during the linear motion x_t0 → x_t1 (exact broad phase and CCD), until no pair may.
/// Each round holds at least one more vertex (a colliding pair has a moving vertex, as x_t0 is
/// intersection-free), so it ends; with every vertex held there is no motion left to collide.
void hold_colliding_vertices(const SurfaceMesh& mesh, const std::vector<Vec3>& x_t0,
                             std::vector<Vec3>& x_t1, SmoothReport& report) {
    const auto moving = [&](int v) {
        return x_t1[static_cast<size_t>(v)] != x_t0[static_cast<size_t>(v)];
    };
    // Holding a vertex shrinks its swept box to a point inside it, so the first round's
    // candidate pairs contain every later round's: the broad phase is built once.
    const BroadPhase broad(mesh, x_t0, x_t1, 0.0);
    // Periodic meshes: every vertex of a pair is shifted by whole periods to the image of its
    // start nearest the pair's first vertex, the same shift at both times (x_t1 is x_t0 plus
    // a small displacement, not wrapped).
    const bool periodic = mesh.periodic();
    const MeshPeriods& periods = mesh.periods();
    const std::vector<VertexTrianglePair> vt = broad.vertex_triangle_pairs();
    const std::vector<EdgeEdgePair> ee = broad.edge_edge_pairs();
    // Vertices held in the last round (empty: the first round, which tests every pair). A pair
    // without one kept its trajectories, so its last answer — no collision, or its moving
    // vertices would have been held — still stands.
    std::vector<std::uint8_t> held_last;
    const auto retest = [&](const std::array<int, 4>& v) {
        return held_last.empty() || held_last[static_cast<size_t>(v[0])] ||
               held_last[static_cast<size_t>(v[1])] || held_last[static_cast<size_t>(v[2])] ||
               held_last[static_cast<size_t>(v[3])];
    };
    for (;;) {
        ++report.collision_rounds;
        tbb::enumerable_thread_specific<std::vector<int>> local;
        tbb::parallel_for(
            tbb::blocked_range<size_t>(0, vt.size() + ee.size(), PAIRS_PER_TASK),
            [&](const tbb::blocked_range<size_t>& range) {
                for (size_t i = range.begin(); i < range.end(); ++i) {
                    std::array<int, 4> v;
                    if (i < vt.size()) {
                        const Triangle& t = mesh.triangle(vt[i].ti);
                        v = {vt[i].vi, t[0], t[1], t[2]};
                    } else {
                        const Edge& a = mesh.edge(ee[i - vt.size()].ei);
                        const Edge& b = mesh.edge(ee[i - vt.size()].ej);
                        v = {a[0], a[1], b[0], b[1]};
                    }
                    if (!(moving(v[0]) || moving(v[1]) || moving(v[2]) || moving(v[3])) ||
                        !retest(v))
                        continue;
                    const auto p0 = [&](int k) -> const Vec3& {
                        return x_t0[static_cast<size_t>(v[k])];
                    };
                    const auto p1 = [&](int k) -> const Vec3& {
                        return x_t1[static_cast<size_t>(v[k])];
                    };
                    if (periodic) {
                        std::array<Vec3, 4> a, b;
                        for (int k = 0; k < 4; ++k) {
                            const Vec3 shift = periods.shift_towards(p0(k), p0(0));
                            a[static_cast<size_t>(k)] = p0(k) + shift;
                            b[static_cast<size_t>(k)] = p1(k) + shift;
                        }
                        const bool collides =
                            i < vt.size()
                                ? point_triangle_ccd(a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3])
                                : edge_edge_ccd(a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]);
                        if (collides)
                            local.local().insert(local.local().end(), v.begin(), v.end());
                        continue;
                    }
                    const bool collides =
                        i < vt.size()
                            ? point_triangle_ccd(p0(0), p0(1), p0(2), p0(3), p1(0), p1(1),
                                                 p1(2), p1(3))
                            : edge_edge_ccd(p0(0), p0(1), p0(2), p0(3), p1(0), p1(1), p1(2),
                                            p1(3));
                    if (collides)
                        local.local().insert(local.local().end(), v.begin(), v.end());
                }
            });
        int held = 0;
        held_last.assign(x_t0.size(), 0);
        for (const std::vector<int>& part : local)
            for (int vi : part)
                if (moving(vi)) {
                    x_t1[static_cast<size_t>(vi)] = x_t0[static_cast<size_t>(vi)];
                    held_last[static_cast<size_t>(vi)] = 1;
                    ++held;
                }
        report.held_colliding += held;
        if (held == 0)
            return;
    }
}

}  // namespace

Vec3 vertex_volume_gradient(const SurfaceMesh& mesh, int vi) {
    Vec3 six_gradient = Vec3::Zero();
    const Vec3& x = mesh.position(vi);
    for (int ti : mesh.vertex_triangles(vi)) {
        const Triangle& t = mesh.triangle(ti);
        for (int k = 0; k < 3; ++k)
            if (t[k] == vi) {
                six_gradient += (mesh.position_near(t[(k + 1) % 3], x) - x)
                                    .cross(mesh.position_near(t[(k + 2) % 3], x) - x);
                break;
            }
    }
    return six_gradient / 6.0;
}

std::vector<Vec3> null_space_displacements(const SurfaceMesh& mesh, const RemeshOptions& options,
                                           SmoothReport* counts) {
    const FeatureThresholds thresholds{options.ridge_eigenvalue_ratio,
                                       options.corner_eigenvalue_ratio};
    const size_t n = static_cast<size_t>(mesh.num_vertices());
    std::vector<Vec3> displacement(n, Vec3::Zero());
    // What each vertex is, for the report (filled in parallel, counted after).
    enum Kind : std::uint8_t { SKIPPED, BOUNDARY, CORNER, RIDGE, SMOOTH };
    std::vector<std::uint8_t> kind(n, SKIPPED);
    const double unfitted_min_angle = options.smoothing_unfitted_min_angle_degrees * M_PI / 180.0;
    SurfaceFitOptions fit;
    fit.degree = options.smoothing_fit_degree;
    const bool turn_bounded = options.smoothing_fit_max_turn > 0.0;
    // Each vertex reads only the current positions: independent, and the fits make it worth
    // spreading over the cores.
    tbb::parallel_for(tbb::blocked_range<int>(0, mesh.num_vertices(), VERTICES_PER_TASK),
                      [&](const tbb::blocked_range<int>& range) {
        for (int vi = range.begin(); vi != range.end(); ++vi) {
            const size_t slot = static_cast<size_t>(vi);
            if (!mesh.vertex_alive(vi) || mesh.vertex_triangles(vi).empty())
                continue;
            if (mesh.is_boundary_vertex(vi)) {
                kind[slot] = BOUNDARY;
                continue;
            }
            const VertexQuadric q = vertex_quadric(mesh, vi, thresholds);
            if (q.feature == VertexFeature::corner) {
                kind[slot] = CORNER;
                continue;
            }
            kind[slot] = q.feature == VertexFeature::ridge ? RIDGE : SMOOTH;
            Vec3 weighted_centroid = Vec3::Zero();
            double total_area = 0.0;
            // Periodic meshes: the one-ring at its images nearest the vertex.
            const Vec3& here = mesh.position(vi);
            for (int ti : mesh.vertex_triangles(vi)) {
                const Triangle& t = mesh.triangle(ti);
                const Vec3 a = mesh.position_near(t[0], here), b = mesh.position_near(t[1], here),
                           c = mesh.position_near(t[2], here);
                const double area = 0.5 * (b - a).cross(c - a).norm();
                weighted_centroid += area * (a + b + c) / 3.0;
                total_area += area;
            }
            if (!(total_area > 0.0))
                continue;
            const Vec3 towards = weighted_centroid / total_area - mesh.position(vi);
            Vec3 d = options.smoothing_step_fraction * (q.null_space_projector() * towards);
            if (options.smoothing_onto_fitted_surface && q.feature == VertexFeature::smooth) {
                const Vec3& x = mesh.position(vi);
                const std::optional<SurfacePatch> patch = vertex_patch(mesh, vi, fit);
                const bool resolved =
                    patch && (!turn_bounded || patch->turn() <= options.smoothing_fit_max_turn);
                const std::optional<Vec3> p =
                    resolved ? place_on_vertex_patch(*patch, x, x + d, fit) : std::nullopt;
                if (p) {
                    displacement[slot] = *p - x;
                    continue;
                }
                // No fit here, or (with smoothing_fit_max_turn) one that turns too far over its
                // patch to be trusted: the tangent-plane move, which with a turn bound every
                // such vertex takes. Without one, a refused fit is a crease or an under-resolved
                // fillet, and the tangent-plane move would leave the surface by about δ²κ/2, so
                // it is made only to repair a poor triangle.
                if (!turn_bounded && smallest_angle_around(mesh, vi) >= unfitted_min_angle)
                    continue;
            }
            if (options.smoothing_preserves_volume) {
                const Vec3 g = vertex_volume_gradient(mesh, vi);
                const double g2 = g.squaredNorm();
                if (g2 > 0.0)
                    d -= g.dot(d) / g2 * g;
            }
            displacement[slot] = d;
        }
    });
    if (counts)
        for (std::uint8_t k : kind) {
            counts->boundary_vertices += k == BOUNDARY ? 1 : 0;
            counts->corner_vertices += k == CORNER ? 1 : 0;
            counts->ridge_vertices += k == RIDGE ? 1 : 0;
        }
    return displacement;
}

SmoothReport smooth_null_space(SurfaceMesh& mesh, const RemeshOptions& options,
                               const ImproveContext& context) {
    const auto start = std::chrono::steady_clock::now();
    SmoothReport report;
    for (int it = 0; it < options.smoothing_iterations; ++it) {
        context.cancel.throw_if_requested("null-space smoothing");
        SmoothReport counts;
        const std::vector<Vec3> displacement = null_space_displacements(mesh, options, &counts);
        report.ridge_vertices = counts.ridge_vertices;
        report.corner_vertices = counts.corner_vertices;
        report.boundary_vertices = counts.boundary_vertices;
        const std::vector<Vec3> x_t0 = mesh.positions();
        std::vector<Vec3> x_t1 = x_t0;
        for (size_t vi = 0; vi < x_t1.size(); ++vi) {
            if (context.is_pinned(static_cast<int>(vi)))
                continue;  // held in place, like an open surface's boundary
            x_t1[vi] += displacement[vi];
            report.vertices_moved += displacement[vi].squaredNorm() > 0.0 ? 1 : 0;
        }
        ++report.iterations;
        if (context.collision_safety && options.smoothing_holds_colliding_vertices) {
            hold_colliding_vertices(mesh, x_t0, x_t1, report);
        } else if (context.collision_safety) {
            // Collision response must not move the open boundary either (§4.4), nor pinned
            // vertices.
            std::vector<std::uint8_t> pinned(x_t0.size(), 0);
            for (int vi = 0; vi < mesh.num_vertices(); ++vi)
                pinned[static_cast<size_t>(vi)] =
                    mesh.vertex_alive(vi) && (mesh.is_boundary_vertex(vi) || context.is_pinned(vi))
                        ? 1
                        : 0;
            report.collisions = resolve_collisions(mesh, x_t0, x_t1, PSEUDO_STEP_DURATION,
                                                   context.collision, nullptr, &pinned);
            if (!report.collisions.collision_free) {
                ++report.refused_collision;
                continue;
            }
        }
        mesh.set_positions(x_t1);
        mesh.wrap_positions();  // periodic meshes: back into the fundamental box
    }
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

}  // namespace meniscus::tracker
