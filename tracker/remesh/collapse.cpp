#include "tracker/remesh/collapse.h"

#include "tracker/quadric.h"
#include "tracker/remesh/butterfly.h"
#include "tracker/remesh/local_safety.h"
#include "tracker/remesh/sizing.h"
#include "tracker/remesh/surface_fit.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace meniscus::tracker {

namespace {

constexpr double PI = 3.14159265358979323846;
/// A triangle whose doubled area is below this fraction of its longest edge squared counts as
/// degenerate (validate_mesh's default tolerance).
constexpr double DEGENERATE_AREA_FRACTION = 1e-12;

/// Length of edge ei (by the minimum image on a periodic mesh).
double edge_length(const SurfaceMesh& mesh, int ei) {
    const std::array<Vec3, 2> p = mesh.edge_positions(ei);
    return (p[0] - p[1]).norm();
}

void sort_unique(std::vector<int>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
}

std::vector<int> neighbours(const SurfaceMesh& mesh, int vi) {
    std::vector<int> n;
    for (int ei : mesh.vertex_edges(vi))
        n.push_back(mesh.other_vertex(ei, vi));
    sort_unique(n);
    return n;
}

/// Triangles incident to either endpoint, each once.
std::vector<int> star_triangles(const SurfaceMesh& mesh, const CollapsePlan& plan) {
    std::vector<int> tris = mesh.vertex_triangles(plan.kept);
    const auto& other = mesh.vertex_triangles(plan.removed);
    tris.insert(tris.end(), other.begin(), other.end());
    sort_unique(tris);
    return tris;
}

bool contains(const Triangle& t, int vi) {
    return t[0] == vi || t[1] == vi || t[2] == vi;
}

/// Position of vi before the collapse. On a periodic mesh every vertex a collapse looks at is
/// read at its image nearest the kept vertex (the one reference of the operation), where
/// plan.position also is.
Vec3 before(const SurfaceMesh& mesh, const CollapsePlan& plan, int vi) {
    return mesh.position_near(vi, mesh.position(plan.kept));
}

/// Position of vi after the collapse.
Vec3 moved(const SurfaceMesh& mesh, const CollapsePlan& plan, int vi) {
    return vi == plan.kept || vi == plan.removed ? plan.position : before(mesh, plan, vi);
}

/// Parameter of `position` along the edge from kept to removed, clamped to [0, 1].
double edge_parameter(const SurfaceMesh& mesh, const CollapsePlan& plan) {
    const Vec3 d = before(mesh, plan, plan.removed) - mesh.position(plan.kept);
    const double length2 = d.squaredNorm();
    if (!(length2 > 0.0))
        return 0.0;
    return std::clamp((plan.position - mesh.position(plan.kept)).dot(d) / length2, 0.0, 1.0);
}

/// Largest volume-preserving correction as a fraction of the edge length; a larger one means a
/// nearly flat-folded star, and the uncorrected position is kept.
constexpr double MAX_VOLUME_CORRECTION_FRACTION = 0.5;

/// `plan` with its position moved along the volume gradient so that the collapse keeps the
/// enclosed volume exactly (the volume after the collapse is linear in the new position).
CollapsePlan volume_preserving(const SurfaceMesh& mesh, CollapsePlan plan) {
    const Vec3 g = collapse_volume_gradient(mesh, plan);
    const double g2 = g.squaredNorm();
    if (!(g2 > 0.0))
        return plan;
    const Vec3 correction = -collapse_volume_change(mesh, plan) / g2 * g;
    const double length = (mesh.position(plan.kept) - before(mesh, plan, plan.removed)).norm();
    if (correction.norm() <= MAX_VOLUME_CORRECTION_FRACTION * length)
        plan.position += correction;
    return plan;
}

/// Trajectory end points to try, preferred first, then towards the midpoint.
struct PlanCandidates {
    std::vector<CollapsePlan> plans;
    bool feature_kept = false;
    /// The rule that placed the preferred position on the smooth surface
    /// (RemeshOptions::collapse_on_fitted_surface); empty for the butterfly or midpoint.
    std::optional<EdgePointRule> on_surface;
};

PlanCandidates plan_collapse(const SurfaceMesh& mesh, int ei, const RemeshOptions& options,
                             const ImproveContext& context) {
    const Edge& e = mesh.edge(ei);
    const FeatureThresholds thresholds{options.ridge_eigenvalue_ratio,
                                       options.corner_eigenvalue_ratio};
    PlanCandidates out;
    CollapsePlan base;
    base.ei = ei;
    base.kept = e[0];
    base.removed = e[1];
    const bool boundary0 = mesh.is_boundary_vertex(e[0]) || context.is_pinned(e[0]);
    const bool boundary1 = mesh.is_boundary_vertex(e[1]) || context.is_pinned(e[1]);
    if (boundary0 || boundary1) {
        // §4.4: the boundary stays where it is; the interior endpoint moves onto it. So does a
        // pinned vertex (of two, the first stays).
        base.kept = boundary0 ? e[0] : e[1];
        base.removed = mesh.other_vertex(ei, base.kept);
        base.position = mesh.position(base.kept);
        out.plans.push_back(base);
        return out;
    }
    const VertexQuadric q0 = vertex_quadric(mesh, e[0], thresholds);
    const VertexQuadric q1 = vertex_quadric(mesh, e[1], thresholds);
    const auto f0 = static_cast<int>(q0.feature);
    const auto f1 = static_cast<int>(q1.feature);
    const bool both_corners = f0 == f1 && q0.feature == VertexFeature::corner;
    if (f0 != f1 || both_corners) {
        // The stronger feature stays put (§3.5.3); of two corners, the sharper one (larger
        // smallest eigenvalue). Moving it towards the midpoint would defeat the purpose, so
        // this is the only trajectory tried.
        const bool keep0 = f0 != f1 ? f0 > f1 : q0.eigenvalues[2] >= q1.eigenvalues[2];
        base.kept = keep0 ? e[0] : e[1];
        base.removed = mesh.other_vertex(ei, base.kept);
        base.position = mesh.position(base.kept);
        // A ridge vertex may move across its ridge to keep the volume; a corner stays exactly.
        const VertexFeature kept_feature = keep0 ? q0.feature : q1.feature;
        const bool correct =
            options.collapse_preserves_volume && kept_feature != VertexFeature::corner;
        out.plans.push_back(correct ? volume_preserving(mesh, base) : base);
        out.feature_kept = true;
        return out;
    }
    Vec3 preferred;
    if (q0.feature == VertexFeature::smooth) {
        std::optional<SurfaceEdgePoint> on_surface;
        if (options.collapse_on_fitted_surface) {
            SurfaceFitOptions fit;
            fit.max_residual_fraction = options.split_fit_residual_fraction;
            on_surface = surface_edge_point(mesh, ei, thresholds, fit);
        }
        if (on_surface) {
            preferred = on_surface->point;
            out.on_surface = on_surface->rule;
        } else {
            preferred = butterfly_point(mesh, ei).value_or(edge_midpoint(mesh, ei));
        }
    } else {
        // Both on a ridge: the butterfly stencil reaches across the feature and would round it
        // off; the midpoint stays on a straight ridge.
        preferred = edge_midpoint(mesh, ei);
    }
    const Vec3 midpoint = edge_midpoint(mesh, ei);
    // Periodic meshes: both points are at the minimum image of e[0] (butterfly.h,
    // surface_fit.h), which is base.kept here.
    const int n = options.collapse_position_attempts;
    for (int k = 0; k < n; ++k) {
        const double w = n == 1 ? 0.0 : static_cast<double>(k) / (n - 1);
        CollapsePlan plan = base;
        plan.position = (1.0 - w) * preferred + w * midpoint;
        out.plans.push_back(options.collapse_preserves_volume ? volume_preserving(mesh, plan)
                                                              : plan);
    }
    return out;
}

enum class Refusal { none, topology, normal, volume, long_edge, collision };

}  // namespace

bool collapse_touches_boundary(const SurfaceMesh& mesh, int ei) {
    const Edge& e = mesh.edge(ei);
    return mesh.is_boundary_edge(ei) ||
           (mesh.is_boundary_vertex(e[0]) && mesh.is_boundary_vertex(e[1]));
}

bool collapse_changes_topology(const SurfaceMesh& mesh, int ei) {
    const Edge& e = mesh.edge(ei);
    std::vector<int> opposite;
    for (int ti : mesh.edge_triangles(ei))
        opposite.push_back(mesh.opposite_vertex(ti, ei));
    sort_unique(opposite);
    const std::vector<int> n0 = neighbours(mesh, e[0]);
    const std::vector<int> n1 = neighbours(mesh, e[1]);
    std::vector<int> common;
    std::set_intersection(n0.begin(), n0.end(), n1.begin(), n1.end(), std::back_inserter(common));
    if (common != opposite)
        return true;
    constexpr size_t TETRAHEDRON_VALENCE = 3;
    for (int vi : opposite)
        if (mesh.vertex_edges(vi).size() <= TETRAHEDRON_VALENCE)
            return true;
    return false;
}

bool collapse_duplicates_triangle(const SurfaceMesh& mesh, const CollapsePlan& plan) {
    for (int ti : mesh.vertex_triangles(plan.removed)) {
        Triangle t = mesh.triangle(ti);
        if (contains(t, plan.kept))
            continue;
        for (int& vi : t)
            if (vi == plan.removed)
                vi = plan.kept;
        const int existing = mesh.find_triangle(t[0], t[1], t[2]);
        if (existing == INVALID_INDEX)
            continue;
        // Same orientation when `existing` is a cyclic rotation of t.
        const Triangle& u = mesh.triangle(existing);
        for (int k = 0; k < 3; ++k)
            if (u[k] == t[0] && u[(k + 1) % 3] == t[1])
                return true;
    }
    return false;
}

bool collapse_inverts_normal(const SurfaceMesh& mesh, const CollapsePlan& plan,
                             double max_normal_change_degrees) {
    const double min_cos = std::cos(max_normal_change_degrees * PI / 180.0);
    for (int ti : star_triangles(mesh, plan)) {
        const Triangle& t = mesh.triangle(ti);
        if (contains(t, plan.kept) && contains(t, plan.removed))
            continue;  // deleted by the collapse
        const Vec3 p0 = before(mesh, plan, t[0]), p1 = before(mesh, plan, t[1]),
                   p2 = before(mesh, plan, t[2]);
        const Vec3 q0 = moved(mesh, plan, t[0]), q1 = moved(mesh, plan, t[1]),
                   q2 = moved(mesh, plan, t[2]);
        const Vec3 n_before = (p1 - p0).cross(p2 - p0);
        const Vec3 n_after = (q1 - q0).cross(q2 - q0);
        const double longest =
            std::max({(q1 - q0).squaredNorm(), (q2 - q1).squaredNorm(), (q0 - q2).squaredNorm()});
        if (n_after.norm() <= DEGENERATE_AREA_FRACTION * longest)
            return true;
        if (!(n_before.normalized().dot(n_after.normalized()) >= min_cos))
            return true;
    }
    return false;
}

double collapse_volume_change(const SurfaceMesh& mesh, const CollapsePlan& plan) {
    // Σ over the star of (after − before) signed tetrahedra against a local origin; triangles on
    // the edge vanish (their "after" is flat). Both endpoints move, so both stars count.
    const Vec3 origin = mesh.position(plan.kept);
    double six_change = 0.0;
    for (int ti : star_triangles(mesh, plan)) {
        const Triangle& t = mesh.triangle(ti);
        const Vec3 p0 = before(mesh, plan, t[0]) - origin, p1 = before(mesh, plan, t[1]) - origin,
                   p2 = before(mesh, plan, t[2]) - origin;
        six_change -= p0.dot(p1.cross(p2));
        if (contains(t, plan.kept) && contains(t, plan.removed))
            continue;
        const Vec3 q0 = moved(mesh, plan, t[0]) - origin, q1 = moved(mesh, plan, t[1]) - origin,
                   q2 = moved(mesh, plan, t[2]) - origin;
        six_change += q0.dot(q1.cross(q2));
    }
    return six_change / 6.0;
}

Vec3 collapse_volume_gradient(const SurfaceMesh& mesh, const CollapsePlan& plan) {
    // Every surviving triangle of the star holds exactly one endpoint, so the volume after the
    // collapse is linear in plan.position: Σ (u − o) × (w − o) / 6 over those triangles (p, u, w).
    Vec3 six_gradient = Vec3::Zero();
    const Vec3& origin = plan.position;
    for (int ti : star_triangles(mesh, plan)) {
        const Triangle& t = mesh.triangle(ti);
        if (contains(t, plan.kept) && contains(t, plan.removed))
            continue;
        for (int k = 0; k < 3; ++k)
            if (t[k] == plan.kept || t[k] == plan.removed) {
                six_gradient += (before(mesh, plan, t[(k + 1) % 3]) - origin)
                                    .cross(before(mesh, plan, t[(k + 2) % 3]) - origin);
                break;
            }
    }
    return six_gradient / 6.0;
}

bool collapse_changes_volume_too_much(const SurfaceMesh& mesh, const CollapsePlan& plan,
                                      double gamma) {
    return std::abs(collapse_volume_change(mesh, plan)) > gamma;
}

bool collapse_creates_long_edge(const SurfaceMesh& mesh, const CollapsePlan& plan, double alpha) {
    for (int vi : {plan.kept, plan.removed}) {
        for (int ei : mesh.vertex_edges(vi)) {
            const int n = mesh.other_vertex(ei, vi);
            if (n == plan.kept || n == plan.removed)
                continue;
            const double after = (plan.position - before(mesh, plan, n)).norm();
            if (after > alpha && after > edge_length(mesh, ei))
                return true;
        }
    }
    return false;
}

bool collapse_collides(const SurfaceMesh& mesh, const ElementHash& hash, const CollapsePlan& plan) {
    PseudoMotion motion;
    motion.vertices = {plan.kept, plan.removed};
    motion.x_t1 = {plan.position, plan.position};
    motion.identified = {plan.kept, plan.removed};
    return pseudo_motion_collides(mesh, hash, motion);
}

CollapseReport collapse_short_edges(SurfaceMesh& mesh, const RemeshOptions& options,
                                    const ImproveContext& context) {
    const auto start = std::chrono::steady_clock::now();
    CollapseReport report;
    // Built on the first collision check (a pass with nothing to do never pays for it), then
    // kept current through every mutation.
    std::unique_ptr<ElementHash> hash;
    auto current_hash = [&]() -> const ElementHash& {
        if (!hash)
            hash = std::make_unique<ElementHash>(mesh, context.xi);
        return *hash;
    };

    // β (and the α no new edge may exceed) per edge, lower where the surface turns or faces
    // itself with adaptive sizing; measured once per call (a collapse keeps one endpoint).
    const EdgeSizing sizing(mesh, options, context.xi);
    // α and β as sizing.h sets them (on a periodic mesh at most the smallest period over
    // MeshPeriods::PERIOD_TO_EDGE_RATIO); remesh_limits() otherwise.
    const RemeshLimits& limits = sizing.limits();
    // Vertices of the stars the last pass's collapses changed. Every check of a collapse reads
    // only the stars of the edge's endpoints (and, for collisions, what is near them), so a
    // short edge refused in one pass is tried again in the next only when an endpoint's star
    // changed; a refusal that something farther away might lift waits for the next step.
    // Empty: every short edge is tried (the first pass).
    std::vector<std::uint8_t> dirty;
    for (int pass = 0; pass < options.max_collapse_passes; ++pass) {
        struct ShortEdge {
            double fraction;  ///< length / β
            double scale;     ///< sizing factor s of β and α
            Edge edge;
        };
        std::vector<ShortEdge> short_edges;
        for (int ei = 0; ei < mesh.num_edges(); ++ei) {
            if (!mesh.edge_alive(ei))
                continue;
            const Edge& e = mesh.edge(ei);
            if (!dirty.empty() && !dirty[static_cast<size_t>(e[0])] &&
                !dirty[static_cast<size_t>(e[1])])
                continue;
            const double scale = sizing.scale(e[0], e[1]);
            const double length = edge_length(mesh, ei);
            if (length < limits.min_edge_length * scale)
                short_edges.push_back({length / (limits.min_edge_length * scale), scale, e});
        }
        if (short_edges.empty())
            break;
        ++report.passes;
        std::sort(short_edges.begin(), short_edges.end(),
                  [](const ShortEdge& a, const ShortEdge& b) { return a.fraction < b.fraction; });
        int collapses_this_pass = 0;
        std::vector<std::uint8_t> changed(static_cast<size_t>(mesh.num_vertices()), 0);
        for (const auto& [fraction, scale, e] : short_edges) {
            context.cancel.throw_if_requested("edge collapsing");
            const int ei = mesh.find_edge(e[0], e[1]);
            if (ei == INVALID_INDEX || edge_length(mesh, ei) >= limits.min_edge_length * scale)
                continue;
            if (collapse_touches_boundary(mesh, ei)) {
                ++report.skipped_boundary;
                continue;
            }
            if (mesh.edge_triangles(ei).size() != 2) {
                ++report.skipped_nonmanifold;
                continue;
            }
            if (!context.allow_topology_changes && collapse_changes_topology(mesh, ei)) {
                ++report.refused_topology;
                continue;
            }
            const PlanCandidates candidates = plan_collapse(mesh, ei, options, context);
            Refusal refusal = Refusal::none;
            int chosen = -1;
            for (size_t k = 0; k < candidates.plans.size(); ++k) {
                const CollapsePlan& plan = candidates.plans[k];
                if (collapse_duplicates_triangle(mesh, plan))
                    refusal = Refusal::topology;
                else if (collapse_inverts_normal(mesh, plan, options.max_normal_change_degrees))
                    refusal = Refusal::normal;
                else if (collapse_changes_volume_too_much(mesh, plan, limits.max_volume_change))
                    refusal = Refusal::volume;
                else if (collapse_creates_long_edge(mesh, plan, limits.max_edge_length * scale))
                    refusal = Refusal::long_edge;
                else if (context.collision_safety && collapse_collides(mesh, current_hash(), plan))
                    refusal = Refusal::collision;
                else {
                    chosen = static_cast<int>(k);
                    break;
                }
            }
            if (chosen < 0) {
                switch (refusal) {
                    case Refusal::topology:
                        ++report.refused_topology;
                        break;
                    case Refusal::normal:
                        ++report.refused_normal;
                        break;
                    case Refusal::volume:
                        ++report.refused_volume;
                        break;
                    case Refusal::long_edge:
                        ++report.refused_long_edge;
                        break;
                    case Refusal::collision:
                        ++report.refused_collision;
                        break;
                    case Refusal::none:
                        break;
                }
                continue;
            }
            const CollapsePlan& plan = candidates.plans[static_cast<size_t>(chosen)];
            std::vector<int> touched;
            for (int ti : star_triangles(mesh, plan))
                for (int vi : mesh.triangle(ti))
                    touched.push_back(vi);
            sort_unique(touched);
            for (int vi : touched)
                changed[static_cast<size_t>(vi)] = 1;
            if (hash)
                hash->begin_update(mesh, touched);
            // plan.position is at the minimum image of the kept vertex: stored wrapped.
            mesh.collapse_edge(ei, plan.kept, mesh.periods().wrap(plan.position),
                               edge_parameter(mesh, plan));
            if (hash)
                hash->refresh(mesh, touched);
            ++report.collapses;
            ++collapses_this_pass;
            report.retries_towards_midpoint += chosen > 0 ? 1 : 0;
            report.feature_vertex_kept += candidates.feature_kept && chosen == 0 ? 1 : 0;
            if (candidates.on_surface && chosen == 0)
                ++(*candidates.on_surface == EdgePointRule::fitted ? report.fitted : report.arc);
        }
        if (collapses_this_pass == 0)
            break;
        dirty = std::move(changed);
    }
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

}  // namespace meniscus::tracker
