#include "tracker/mesh_intersections.h"

#include "tracker/intersection.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>

namespace meniscus::tracker {

namespace {

constexpr size_t PARALLEL_GRAIN = 512;

std::array<Vec3, 3> corners(const std::vector<Vec3>& x, const Triangle& t) {
    return {x[static_cast<size_t>(t[0])], x[static_cast<size_t>(t[1])],
            x[static_cast<size_t>(t[2])]};
}

/// Periodic meshes (issue 39): triangle t's corners at their images nearest `ref`.
std::array<Vec3, 3> corners_near(const MeshPeriods& periods, const std::vector<Vec3>& x,
                                 const Triangle& t, const Vec3& ref) {
    return {periods.nearest_image(x[static_cast<size_t>(t[0])], ref),
            periods.nearest_image(x[static_cast<size_t>(t[1])], ref),
            periods.nearest_image(x[static_cast<size_t>(t[2])], ref)};
}

bool pair_intersects(const SurfaceMesh& mesh, const std::vector<Vec3>& x, const TrianglePair& p) {
    const Triangle& a = mesh.triangle(p.ti);
    const Triangle& b = mesh.triangle(p.tj);
    if (mesh.periodic()) {
        // Both triangles by the minimum image about the first one's first corner.
        const Vec3& ref = x[static_cast<size_t>(a[0])];
        return triangles_intersect(corners_near(mesh.periods(), x, a, ref), a,
                                   corners_near(mesh.periods(), x, b, ref), b);
    }
    return triangles_intersect(corners(x, a), a, corners(x, b), b);
}

bool edge_shares_vertex(const Edge& e, const Triangle& t) {
    for (int v : t)
        if (v == e[0] || v == e[1])
            return true;
    return false;
}

void add_witnesses(const SurfaceMesh& mesh, const std::vector<Vec3>& x, int ta, int tb,
                   std::vector<EdgeTrianglePair>& out) {
    const Triangle& t = mesh.triangle(tb);
    for (int ei : mesh.triangle_edges(ta)) {
        const Edge& e = mesh.edge(ei);
        if (edge_shares_vertex(e, t))
            continue;
        if (mesh.periodic()) {
            const MeshPeriods& periods = mesh.periods();
            const Vec3& ref = x[static_cast<size_t>(e[0])];
            const std::array<Vec3, 3> c = corners_near(periods, x, t, ref);
            if (segment_triangle_intersection(
                    ref, periods.nearest_image(x[static_cast<size_t>(e[1])], ref), c[0], c[1], c[2])
                    .intersects())
                out.push_back({ei, tb});
            continue;
        }
        if (segment_triangle_intersection(
                x[static_cast<size_t>(e[0])], x[static_cast<size_t>(e[1])],
                x[static_cast<size_t>(t[0])], x[static_cast<size_t>(t[1])],
                x[static_cast<size_t>(t[2])])
                .intersects())
            out.push_back({ei, tb});
    }
}

}  // namespace

IntersectionReport find_self_intersections(const SurfaceMesh& mesh,
                                           const std::vector<Vec3>* positions) {
    const std::vector<Vec3>& x = positions ? *positions : mesh.positions();
    const BroadPhase broad(mesh, x, x, 0.0);
    const std::vector<TrianglePair> candidates = broad.triangle_pairs();
    tbb::enumerable_thread_specific<std::vector<TrianglePair>> local;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size(), PARALLEL_GRAIN),
                      [&](const tbb::blocked_range<size_t>& r) {
                          auto& out = local.local();
                          for (size_t i = r.begin(); i < r.end(); ++i)
                              if (pair_intersects(mesh, x, candidates[i]))
                                  out.push_back(candidates[i]);
                      });
    IntersectionReport report;
    for (auto& part : local)
        report.triangle_pairs.insert(report.triangle_pairs.end(), part.begin(), part.end());
    std::sort(report.triangle_pairs.begin(), report.triangle_pairs.end());
    for (const TrianglePair& p : report.triangle_pairs) {
        add_witnesses(mesh, x, p.ti, p.tj, report.edge_triangle_pairs);
        add_witnesses(mesh, x, p.tj, p.ti, report.edge_triangle_pairs);
    }
    return report;
}

bool is_intersection_free(const SurfaceMesh& mesh, const std::vector<Vec3>* positions) {
    const std::vector<Vec3>& x = positions ? *positions : mesh.positions();
    const BroadPhase broad(mesh, x, x, 0.0);
    const std::vector<TrianglePair> candidates = broad.triangle_pairs();
    std::atomic<bool> hit{false};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size(), PARALLEL_GRAIN),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t i = r.begin(); i < r.end() && !hit.load(); ++i)
                              if (pair_intersects(mesh, x, candidates[i]))
                                  hit.store(true);
                      });
    return !hit.load();
}

}  // namespace meniscus::tracker
