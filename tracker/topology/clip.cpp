#include "tracker/topology/clip.h"

#include "tracker/mesh_measures.h"
#include "tracker/polygon_triangulation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>

namespace meniscus::tracker {

namespace {

/// An edge that crosses the plane and the point where it does.
struct Crossing {
    int v0 = INVALID_INDEX;  ///< the endpoint on the near side
    int v1 = INVALID_INDEX;  ///< the endpoint beyond
    double t = 0.0;          ///< the crossing's parameter from v0 to v1
    Vec3 point = Vec3::Zero();
    int next = -1;  ///< the next crossing along the cap's loop
    int previous = -1;
    LabelPair labels;  ///< of the triangle whose cut runs from this crossing to `next`
    int component = -1;
};

/// Cut positions tried per range (the widest gaps first) before the cut is deferred.
constexpr size_t MAX_CUTS_TRIED = 6;
/// Where no cut in the range will do, the search goes on beyond it over this many range widths.
constexpr double FURTHER_RANGES = 2.0;

/// Six times the signed volume of the tetrahedron (o, a, b, c).
double tet6(const Vec3& o, const Vec3& a, const Vec3& b, const Vec3& c) {
    return (a - o).dot((b - o).cross(c - o));
}

/// Candidate cuts (in t = ±x[axis], larger t beyond) within [t_lo, t_hi]: the middles of the
/// gaps between the vertices' coordinates there, widest gap first, at most `count`.
std::vector<double> cut_candidates(const std::vector<double>& t_vertices, double t_lo, double t_hi,
                                   size_t count) {
    std::vector<double> t = {t_lo, t_hi};
    for (double tv : t_vertices)
        if (tv > t_lo && tv < t_hi)
            t.push_back(tv);
    std::sort(t.begin(), t.end());
    std::vector<std::pair<double, double>> gaps;  // (width, middle)
    for (size_t i = 0; i + 1 < t.size(); ++i)
        if (t[i + 1] > t[i])
            gaps.push_back({t[i + 1] - t[i], 0.5 * (t[i] + t[i + 1])});
    std::stable_sort(gaps.begin(), gaps.end(),
                     [](const auto& x, const auto& y) { return x.first > y.first; });
    std::vector<double> cuts;
    for (size_t i = 0; i < gaps.size() && i < count; ++i)
        cuts.push_back(gaps[i].second);
    return cuts;
}

/// A cut planned at one position with everything needed to make it; the mesh is not changed.
struct ClipPlan {
    double position = 0.0;  ///< x[axis] of the plane
    std::vector<double> s;  ///< per vertex: > 0 beyond the plane
    bool any_beyond = false;
    std::vector<Crossing> crossings;
    struct Cap {
        std::vector<std::array<int, 3>> triangles;  ///< of crossings
        LabelPair labels;
    };
    std::vector<Cap> caps;
    std::vector<double> removed;  ///< per component: signed volume removed
    std::vector<int> kept_vertex;
    std::vector<char> touched;
    std::vector<LabelPair> labels;
    std::string failure;  ///< why the cut cannot be made here (empty: it can)
};

/// Plans the cut at t_cut (see the file comment), components in `gone` going whole.
ClipPlan plan_clip(const SurfaceMesh& mesh, int a, double dir, double t_cut,
                   const Components& components, const std::vector<char>& gone) {
    const int b = (a + 1) % 3;
    const int c = (a + 2) % 3;
    const int n_vertices = mesh.num_vertices();
    ClipPlan plan;
    plan.position = dir * t_cut;
    std::vector<double>& s = plan.s;
    s.assign(static_cast<size_t>(n_vertices), -1.0);
    for (int vi = 0; vi < n_vertices; ++vi)
        if (mesh.vertex_alive(vi))
            s[static_cast<size_t>(vi)] = dir * mesh.position(vi)[a] - t_cut;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        if (mesh.triangle_alive(ti) &&
            gone[static_cast<size_t>(components.triangle_component[static_cast<size_t>(ti)])])
            for (int v : mesh.triangle(ti))
                s[static_cast<size_t>(v)] = std::max(s[static_cast<size_t>(v)], 1.0);
    plan.any_beyond = std::any_of(s.begin(), s.end(), [](double si) { return si > 0.0; });
    if (!plan.any_beyond)
        return plan;

    // The crossing edges (each must have two triangles) and their crossing points.
    std::vector<Crossing>& crossings = plan.crossings;
    std::map<std::pair<int, int>, int> crossing_of;  // (near vertex, far vertex) → crossing
    for (int ei = 0; ei < mesh.num_edges(); ++ei) {
        if (!mesh.edge_alive(ei))
            continue;
        const Edge& e = mesh.edge(ei);
        const double s0 = s[static_cast<size_t>(e[0])], s1 = s[static_cast<size_t>(e[1])];
        if ((s0 > 0.0) == (s1 > 0.0))
            continue;
        if (mesh.edge_triangles(ei).size() != 2) {
            plan.failure = "an edge crossing the plane has " +
                           std::to_string(mesh.edge_triangles(ei).size()) + " triangles";
            return plan;
        }
        Crossing x;
        x.v0 = s0 > 0.0 ? e[1] : e[0];
        x.v1 = s0 > 0.0 ? e[0] : e[1];
        const double sn = s[static_cast<size_t>(x.v0)], sf = s[static_cast<size_t>(x.v1)];
        x.t = sn / (sn - sf);
        const Vec3& p0 = mesh.position(x.v0);
        const Vec3& p1 = mesh.position(x.v1);
        x.point = p0 + x.t * (p1 - p0);
        x.point[a] = plan.position;  // exactly on the plane
        crossing_of[{x.v0, x.v1}] = static_cast<int>(crossings.size());
        crossings.push_back(x);
    }

    // The triangles: the removed part's volume per component (about a point on the plane, so
    // the caps add nothing), and the cap's directed segments (from the crossing where the
    // triangle's boundary comes back to the near side to the one where it leaves it).
    Vec3 origin = Vec3::Zero();
    for (const Crossing& x : crossings)
        origin += x.point;
    origin =
        crossings.empty() ? Vec3::Zero() : Vec3(origin / static_cast<double>(crossings.size()));
    origin[a] = plan.position;
    const size_t count = static_cast<size_t>(components.count);
    plan.removed.assign(count, 0.0);
    plan.kept_vertex.assign(count, INVALID_INDEX);
    plan.touched.assign(count, 0);
    plan.labels.assign(count, LabelPair{});
    const auto crossing = [&](int u, int v) {
        const auto it =
            crossing_of.find(s[static_cast<size_t>(u)] > 0.0 ? std::pair{v, u} : std::pair{u, v});
        return it->second;
    };
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& tri = mesh.triangle(ti);
        const size_t comp =
            static_cast<size_t>(components.triangle_component[static_cast<size_t>(ti)]);
        plan.labels[comp] = mesh.labels(ti);
        int beyond = 0;
        for (int v : tri)
            beyond += s[static_cast<size_t>(v)] > 0.0 ? 1 : 0;
        if (beyond < 3)
            for (int v : tri)
                if (s[static_cast<size_t>(v)] < 0.0)
                    plan.kept_vertex[comp] = v;
        if (beyond == 0)
            continue;
        plan.touched[comp] = 1;
        // The part beyond, in the triangle's order: its vertices beyond and its crossings.
        std::vector<Vec3> part;
        int in = -1, out = -1;
        for (int k = 0; k < 3; ++k) {
            const int u = tri[static_cast<size_t>(k)], v = tri[static_cast<size_t>((k + 1) % 3)];
            const bool u_beyond = s[static_cast<size_t>(u)] > 0.0;
            const bool v_beyond = s[static_cast<size_t>(v)] > 0.0;
            if (u_beyond)
                part.push_back(mesh.position(u));
            if (u_beyond != v_beyond) {
                const int x = crossing(u, v);
                part.push_back(crossings[static_cast<size_t>(x)].point);
                (v_beyond ? out : in) = x;
            }
        }
        for (size_t k = 1; k + 1 < part.size(); ++k)
            plan.removed[comp] += tet6(origin, part[0], part[k], part[k + 1]) / 6.0;
        if (beyond == 3)
            continue;
        Crossing& from = crossings[static_cast<size_t>(in)];
        Crossing& to = crossings[static_cast<size_t>(out)];
        if (from.next != -1 || to.previous != -1) {
            plan.failure = "the triangles along a crossing edge are not consistently oriented";
            return plan;
        }
        from.next = out;
        to.previous = in;
        from.labels = mesh.labels(ti);
        from.component = static_cast<int>(comp);
    }

    // The loops, their nesting and the polygons to cap (outer loop and holes, by depth).
    std::vector<std::vector<int>> loops;
    std::vector<int> loop_of(crossings.size(), -1);
    for (size_t k = 0; k < crossings.size(); ++k) {
        if (loop_of[k] >= 0)
            continue;
        std::vector<int> loop;
        int x = static_cast<int>(k);
        while (x >= 0 && loop_of[static_cast<size_t>(x)] < 0) {
            loop_of[static_cast<size_t>(x)] = static_cast<int>(loops.size());
            loop.push_back(x);
            x = crossings[static_cast<size_t>(x)].next;
        }
        if (x != static_cast<int>(k)) {
            plan.failure = "the cut does not close into loops";
            return plan;
        }
        loops.push_back(std::move(loop));
    }
    std::vector<Eigen::Vector2d> plane_points(crossings.size());
    for (size_t k = 0; k < crossings.size(); ++k)
        plane_points[k] = {crossings[k].point[b], crossings[k].point[c]};
    std::vector<int> depth(loops.size(), 0), parent(loops.size(), -1);
    for (size_t i = 0; i < loops.size(); ++i)
        for (size_t j = 0; j < loops.size(); ++j)
            if (i != j && point_in_loop(plane_points, loops[j],
                                        plane_points[static_cast<size_t>(loops[i][0])]))
                ++depth[i];
    for (size_t i = 0; i < loops.size(); ++i)
        for (size_t j = 0; j < loops.size(); ++j)
            if (depth[j] == depth[i] - 1 &&
                point_in_loop(plane_points, loops[j],
                              plane_points[static_cast<size_t>(loops[i][0])]))
                parent[i] = static_cast<int>(j);
    for (size_t i = 0; i < loops.size(); ++i) {
        if (depth[i] % 2 != 0)
            continue;
        const double sign = loop_signed_area(plane_points, loops[i]) > 0.0 ? 1.0 : -1.0;
        const LabelPair labels = crossings[static_cast<size_t>(loops[i][0])].labels;
        PolygonWithHoles polygon;
        polygon.outer = loops[i];
        for (size_t j = 0; j < loops.size(); ++j)
            if (parent[j] == static_cast<int>(i))
                polygon.holes.push_back(loops[j]);
        std::vector<int> all = polygon.outer;
        for (const std::vector<int>& hole : polygon.holes)
            all.insert(all.end(), hole.begin(), hole.end());
        for (int x : all)
            if (crossings[static_cast<size_t>(x)].labels != labels) {
                plan.failure = "a loop of the cut and the loop around it carry other labels";
                return plan;
            }
        // Mirrored where the outer loop runs clockwise, so that it is counter-clockwise there.
        std::vector<Eigen::Vector2d> points = plane_points;
        for (Eigen::Vector2d& p : points)
            p.x() *= sign;
        const PolygonTriangulation cap = triangulate_polygon(points, polygon);
        if (!cap.ok) {
            plan.failure = "the cap could not be triangulated: " + cap.failure;
            return plan;
        }
        plan.caps.push_back({cap.triangles, labels});
    }
    return plan;
}

/// Makes the planned cut: splits the crossing edges, deletes what lies beyond, adds the caps.
void carry_out(SurfaceMesh& mesh, const ClipPlan& plan, ClipReport& report) {
    const int n_vertices = static_cast<int>(plan.s.size());
    std::vector<int> plane_vertex(plan.crossings.size(), INVALID_INDEX);
    for (size_t k = 0; k < plan.crossings.size(); ++k) {
        const Crossing& x = plan.crossings[k];
        const int ei = mesh.find_edge(x.v0, x.v1);
        const double t_from_first = mesh.edge(ei)[0] == x.v0 ? x.t : 1.0 - x.t;
        plane_vertex[k] = mesh.split_edge(ei, x.point, t_from_first);
        ++report.edges_split;
    }
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& tri = mesh.triangle(ti);
        const bool beyond = std::any_of(tri.begin(), tri.end(), [&](int v) {
            return v < n_vertices && plan.s[static_cast<size_t>(v)] > 0.0;
        });
        if (beyond) {
            mesh.remove_triangle(ti);
            ++report.triangles_removed;
        }
    }
    for (int vi = 0; vi < n_vertices; ++vi)
        if (mesh.vertex_alive(vi) && plan.s[static_cast<size_t>(vi)] > 0.0) {
            mesh.remove_vertex(vi);
            ++report.vertices_removed;
        }
    for (const ClipPlan::Cap& cap : plan.caps)
        for (const std::array<int, 3>& t : cap.triangles) {
            mesh.add_triangle(
                {plane_vertex[static_cast<size_t>(t[0])], plane_vertex[static_cast<size_t>(t[1])],
                 plane_vertex[static_cast<size_t>(t[2])]},
                cap.labels);
            ++report.cap_triangles;
        }
    report.clipped = true;
    report.position = plan.position;
    for (size_t comp = 0; comp < plan.touched.size(); ++comp) {
        if (!plan.touched[comp])
            continue;
        ClippedComponent piece;
        piece.kept_vertex = plan.kept_vertex[comp];
        piece.removed_volume = plan.removed[comp];
        piece.labels = plan.labels[comp];
        report.components_removed += piece.kept_vertex == INVALID_INDEX ? 1 : 0;
        report.components.push_back(piece);
    }
}

}  // namespace

void ClipPlane::validate() const {
    if (axis < 0 || axis > 2)
        throw std::invalid_argument("ClipPlane.axis: expected 0, 1 or 2");
    if (side != 0 && side != 1)
        throw std::invalid_argument("ClipPlane.side: expected 0 (min) or 1 (max)");
    if (!std::isfinite(near) || !std::isfinite(far) || near == far)
        throw std::invalid_argument("ClipPlane.near, far: expected two different finite numbers");
    if (std::isinf(gone))
        throw std::invalid_argument("ClipPlane.gone: expected a finite number or NaN");
}

ClipReport clip_mesh(SurfaceMesh& mesh, const ClipPlane& plane) {
    plane.validate();
    ClipReport report;
    const int a = plane.axis;
    const double dir = plane.side == 1 ? 1.0 : -1.0;
    const double t_near = std::min(dir * plane.near, dir * plane.far);
    const double t_far = std::max(dir * plane.near, dir * plane.far);
    const double t_gone = std::isnan(plane.gone) ? t_near : std::min(dir * plane.gone, t_near);

    std::vector<double> t_vertices;
    bool reaches = false;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi) || mesh.vertex_triangles(vi).empty())
            continue;
        t_vertices.push_back(dir * mesh.position(vi)[a]);
        reaches = reaches || t_vertices.back() > t_gone;
    }
    if (!reaches)
        return report;
    // Components wholly beyond t_gone count as beyond the cut throughout.
    const Components components = triangle_components(mesh);
    std::vector<char> gone(static_cast<size_t>(components.count), 1);
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        if (mesh.triangle_alive(ti))
            for (int v : mesh.triangle(ti))
                if (dir * mesh.position(v)[a] <= t_gone)
                    gone[static_cast<size_t>(
                        components.triangle_component[static_cast<size_t>(ti)])] = 0;
    // The widest gaps in the range first; where none will do (an edge crossing with four
    // triangles where two sheets touch, say), further out as far again and again.
    std::vector<double> candidates = cut_candidates(t_vertices, t_near, t_far, MAX_CUTS_TRIED);
    const std::vector<double> further = cut_candidates(
        t_vertices, t_far, t_far + FURTHER_RANGES * (t_far - t_near), MAX_CUTS_TRIED);
    candidates.insert(candidates.end(), further.begin(), further.end());
    for (const double t_cut : candidates) {
        const ClipPlan plan = plan_clip(mesh, a, dir, t_cut, components, gone);
        if (!plan.any_beyond)
            return report;  // nothing reaches past the widest gap yet
        if (plan.failure.empty()) {
            carry_out(mesh, plan, report);
            report.deferred.clear();
            return report;
        }
        if (report.deferred.empty())
            report.deferred = plan.failure;
    }
    if (report.deferred.empty())
        report.deferred = "no room for the cut between the vertices in the range";
    return report;
}

}  // namespace meniscus::tracker
