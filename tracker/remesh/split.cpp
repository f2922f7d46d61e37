#include "tracker/remesh/split.h"

#include "tracker/remesh/butterfly.h"
#include "tracker/remesh/element_hash.h"
#include "tracker/remesh/local_safety.h"
#include "tracker/remesh/sizing.h"
#include "tracker/remesh/smooth.h"
#include "tracker/remesh/surface_fit.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

namespace meniscus::tracker {

namespace {

/// Length of edge ei (by the minimum image on a periodic mesh).
double edge_length(const SurfaceMesh& mesh, int ei) {
    const std::array<Vec3, 2> p = mesh.edge_positions(ei);
    return (p[0] - p[1]).norm();
}

}  // namespace

bool split_allowed(const SurfaceMesh& mesh, int ei) {
    return mesh.edge_triangles(ei).size() == 2;
}

bool split_butterfly_collides(const SurfaceMesh& mesh, const ElementHash& hash, int vi,
                              const Vec3& target) {
    PseudoMotion motion;
    motion.vertices = {vi};
    motion.x_t1 = {target};
    return pseudo_motion_collides(mesh, hash, motion);
}

bool split_midpoint_intersects(const SurfaceMesh& mesh, const ElementHash& hash, int ei,
                               const Vec3& midpoint) {
    const Edge& e = mesh.edge(ei);
    const int m = mesh.num_vertices();  // the new vertex, not yet created
    CandidateTriangles candidates;
    candidates.overrides = {{m, midpoint}};
    const std::vector<int>& replaced = mesh.edge_triangles(ei);
    for (int ti : replaced) {
        for (int end : {0, 1}) {
            Triangle child = mesh.triangle(ti);
            for (int& vi : child)
                if (vi == e[end])
                    vi = m;
            candidates.triangles.push_back(child);
        }
    }
    return candidate_triangles_intersect(mesh, hash, candidates, replaced);
}

SplitReport split_long_edges(SurfaceMesh& mesh, const RemeshOptions& options,
                             const ImproveContext& context) {
    const auto start = std::chrono::steady_clock::now();
    SplitReport report;
    const RemeshLimits limits = remesh_limits(options, context.xi);
    const double gamma = limits.max_volume_change;
    const FeatureThresholds thresholds{options.ridge_eigenvalue_ratio,
                                       options.corner_eigenvalue_ratio};
    SurfaceFitOptions fit;
    fit.max_residual_fraction = options.split_fit_residual_fraction;
    // Built on the first collision check (a pass with nothing to do never pays for it), then
    // kept current through every mutation.
    std::unique_ptr<ElementHash> hash;
    auto current_hash = [&]() -> const ElementHash& {
        if (!hash)
            hash = std::make_unique<ElementHash>(mesh, context.xi);
        return *hash;
    };

    // α per edge (lower where the surface turns or faces itself, with adaptive sizing),
    // measured once per call; new vertices are graded from their edge's endpoints. Its ratio to the length orders
    // the splits.
    EdgeSizing sizing(mesh, options, context.xi);
    for (int pass = 0; pass < options.max_split_passes; ++pass) {
        struct LongEdge {
            double excess;  ///< length / α
            double alpha;
            Edge edge;
        };
        std::vector<LongEdge> long_edges;
        for (int ei = 0; ei < mesh.num_edges(); ++ei) {
            if (!mesh.edge_alive(ei))
                continue;
            const Edge& e = mesh.edge(ei);
            const double alpha = sizing.max_length(e[0], e[1]);
            const double length = edge_length(mesh, ei);
            if (length > alpha)
                long_edges.push_back({length / alpha, alpha, e});
        }
        if (long_edges.empty())
            break;
        ++report.passes;
        std::sort(long_edges.begin(), long_edges.end(),
                  [](const LongEdge& a, const LongEdge& b) { return a.excess > b.excess; });
        int splits_this_pass = 0;
        for (const auto& [excess, alpha, e] : long_edges) {
            context.cancel.throw_if_requested("edge splitting");
            const int ei = mesh.find_edge(e[0], e[1]);
            if (ei == INVALID_INDEX || edge_length(mesh, ei) <= alpha)
                continue;
            if (mesh.is_boundary_edge(ei)) {
                ++report.skipped_boundary;
                continue;
            }
            if (!split_allowed(mesh, ei)) {
                ++report.skipped_nonmanifold;
                continue;
            }
            // Where the new vertex goes (named for the paper's rule, which is the last resort).
            std::optional<Vec3> butterfly;
            if (options.split_on_fitted_surface)
                if (const auto on_surface = surface_edge_point(mesh, ei, thresholds, fit)) {
                    butterfly = on_surface->point;
                    ++(on_surface->rule == EdgePointRule::fitted ? report.fitted : report.arc);
                }
            if (!butterfly)
                butterfly = butterfly_point(mesh, ei);
            const Vec3 midpoint = edge_midpoint(mesh, ei);
            // The midpoint is on the edge in exact arithmetic only: rounded, it can land on a
            // vertex that another sheet placed at the same rounded midpoint (a neck pinching
            // at edges near ξ/10: a merge rebuilt an edge that an earlier split had halved).
            if (context.collision_safety &&
                split_midpoint_intersects(mesh, current_hash(), ei, midpoint)) {
                ++report.refused_midpoint;
                continue;
            }
            std::vector<int> touched = {e[0], e[1]};
            for (int ti : mesh.edge_triangles(ei))
                touched.push_back(mesh.opposite_vertex(ti, ei));
            if (hash)
                hash->begin_update(mesh, touched);
            // On a periodic mesh the midpoint and the target are at the minimum image of the
            // edge's first vertex: stored wrapped into the fundamental box.
            const int vi = mesh.split_edge(ei, mesh.periods().wrap(midpoint), 0.5);
            sizing.inherit(mesh, vi, e[0], e[1]);
            touched.push_back(vi);
            if (hash)
                hash->refresh(mesh, touched);
            ++report.splits;
            ++splits_this_pass;
            if (!butterfly) {
                ++report.butterfly_unavailable;
                continue;
            }
            // The offset from the midpoint changes the volume by exactly g · offset (the volume
            // is linear in one vertex); beyond γ it is scaled back to γ. On a smooth surface the
            // offset's volume is about h⁴κ/10, far below γ; it binds at folds much thinner than
            // an edge, where the butterfly stencil reaches across the fold (A4 curl noise:
            // splits there added 1 % volume by t = 9.5).
            const double volume_change = vertex_volume_gradient(mesh, vi).dot(*butterfly - midpoint);
            if (std::abs(volume_change) > gamma) {
                *butterfly = midpoint + gamma / std::abs(volume_change) * (*butterfly - midpoint);
                ++report.volume_limited;
            }
            if (context.collision_safety &&
                split_butterfly_collides(mesh, current_hash(), vi, *butterfly)) {
                ++report.butterfly_collides;
                continue;
            }
            mesh.set_position(vi, mesh.periods().wrap(*butterfly));
            if (hash) {
                hash->begin_update(mesh, {vi});
                hash->refresh(mesh, {vi});
            }
        }
        if (splits_this_pass == 0)
            break;
    }
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

}  // namespace meniscus::tracker
