#include "tracker/topology/merge.h"

#include "tracker/broadphase.h"
#include "tracker/distance.h"
#include "tracker/remesh/local_safety.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <memory>
#include <numeric>
#include <tuple>
#include <utility>

namespace meniscus::tracker {

namespace {

constexpr int LOOP_SIZE = 4;

/// Loop b reversed and rotated by `shift`, so that vertex i faces a.loop[i].
std::array<int, 4> facing_loop(const EdgeHole& b, int shift) {
    std::array<int, 4> out{};
    for (int i = 0; i < LOOP_SIZE; ++i)
        out[static_cast<size_t>(i)] =
            b.loop[static_cast<size_t>(((shift - i) % LOOP_SIZE + LOOP_SIZE) % LOOP_SIZE)];
    return out;
}

double alignment_cost(const SurfaceMesh& mesh, const EdgeHole& a, const EdgeHole& b, int shift) {
    const std::array<int, 4> f = facing_loop(b, shift);
    // A periodic mesh's two loops are read about one reference (loop a's first vertex).
    const Vec3& ref = mesh.position(a.loop[0]);
    double cost = 0.0;
    for (size_t i = 0; i < LOOP_SIZE; ++i)
        cost += (mesh.position_near(a.loop[i], ref) - mesh.position_near(f[i], ref)).squaredNorm();
    return cost;
}

/// The squared distance between two points, between their nearest images on a periodic mesh.
double squared_separation(const SurfaceMesh& mesh, const Vec3& p, const Vec3& q) {
    return mesh.periodic() ? mesh.periods().difference(p, q).squaredNorm() : (p - q).squaredNorm();
}

/// A proximal edge pair, by vertices (edge indices change as merges rewire the mesh).
struct Candidate {
    double distance;
    Edge a, b;
    Vec3 midpoint;  ///< between the two closest points
};

}  // namespace

bool edge_hole(const SurfaceMesh& mesh, int ei, EdgeHole& hole) {
    const auto& et = mesh.edge_triangles(ei);
    if (et.size() != 2)
        return false;
    int forward = et[0], backward = et[1];
    if (mesh.edge_orientation_in_triangle(forward, ei) != 1)
        std::swap(forward, backward);
    if (mesh.edge_orientation_in_triangle(forward, ei) != 1 ||
        mesh.edge_orientation_in_triangle(backward, ei) != -1)
        return false;
    const Edge& e = mesh.edge(ei);
    // Removed: (e0, e1, c) and (e1, e0, d); their outer edges run e1→c→e0→d→e1.
    hole.triangles = {forward, backward};
    hole.loop = {e[1], mesh.opposite_vertex(forward, ei), e[0], mesh.opposite_vertex(backward, ei)};
    return true;
}

bool merge_touches_boundary(const SurfaceMesh& mesh, const EdgeHole& a, const EdgeHole& b) {
    for (const EdgeHole* h : {&a, &b})
        for (size_t i = 0; i < LOOP_SIZE; ++i) {
            const int ei = mesh.find_edge(h->loop[i], h->loop[(i + 1) % LOOP_SIZE]);
            if (ei == INVALID_INDEX || mesh.edge_triangles(ei).size() < 2)
                return true;
        }
    return false;
}

bool merge_shares_vertex(const EdgeHole& a, const EdgeHole& b) {
    for (int u : a.loop)
        for (int v : b.loop)
            if (u == v)
                return true;
    return a.loop[1] == a.loop[3] || b.loop[1] == b.loop[3];
}

std::vector<Triangle> zipper_triangles(const SurfaceMesh& mesh, const EdgeHole& a,
                                       const EdgeHole& b, int shift) {
    const std::array<int, 4> f = facing_loop(b, shift);
    const Vec3& ref = mesh.position(a.loop[0]);  // a periodic mesh's loops are read about it
    const auto x = [&](int v) { return mesh.position_near(v, ref); };
    std::vector<Triangle> band;
    for (size_t i = 0; i < LOOP_SIZE; ++i) {
        const size_t j = (i + 1) % LOOP_SIZE;
        const int a_i = a.loop[i], a_j = a.loop[j], b_i = f[i], b_j = f[j];
        // Loop a is used as a_i → a_j and loop b as b_j → b_i, as the removed triangles did.
        const double diagonal_ab = (x(a_i) - x(b_j)).squaredNorm();
        const double diagonal_ba = (x(a_j) - x(b_i)).squaredNorm();
        if (diagonal_ab <= diagonal_ba) {
            band.push_back({a_i, a_j, b_j});
            band.push_back({b_j, b_i, a_i});
        } else {
            band.push_back({a_i, a_j, b_i});
            band.push_back({a_j, b_j, b_i});
        }
    }
    return band;
}

bool merge_creates_existing_edge(const SurfaceMesh& mesh, const EdgeHole& a,
                                 const std::vector<Triangle>& band) {
    auto on_loop_a = [&](int v) {
        return std::find(a.loop.begin(), a.loop.end(), v) != a.loop.end();
    };
    for (const Triangle& t : band)
        for (size_t k = 0; k < 3; ++k) {
            const int u = t[k], v = t[(k + 1) % 3];
            if (on_loop_a(u) != on_loop_a(v) && mesh.find_edge(u, v) != INVALID_INDEX)
                return true;
        }
    return false;
}

bool merge_intersects(const SurfaceMesh& mesh, const ElementHash& hash, const EdgeHole& a,
                      const EdgeHole& b, const std::vector<Triangle>& band) {
    CandidateTriangles candidates;
    candidates.triangles = band;
    return candidate_triangles_intersect(
        mesh, hash, candidates, {a.triangles[0], a.triangles[1], b.triangles[0], b.triangles[1]});
}

MergeReport merge_proximal_edges(SurfaceMesh& mesh, const TopologyOptions& options,
                                 const TopologyContext& context) {
    const auto start = std::chrono::steady_clock::now();
    MergeReport report;
    const double merge_distance = options.merge_distance_fraction * context.xi;

    // Pairs of manifold edges closer than the merge distance: boxes padded by half of it
    // overlap for every such pair, and the exact distance is tested inside the parallel join.
    // On a periodic mesh both edges are read about the first edge's first vertex (the broad
    // phase reports pairs across the seam too).
    const auto ends = [&mesh](int ei, int ej) {
        const Edge& a = mesh.edge(ei);
        const Edge& b = mesh.edge(ej);
        const Vec3& ref = mesh.position(a[0]);
        return std::array<Vec3, 4>{ref, mesh.position_near(a[1], ref),
                                   mesh.position_near(b[0], ref), mesh.position_near(b[1], ref)};
    };
    const auto proximity = [&ends](int ei, int ej) {
        const std::array<Vec3, 4> x = ends(ei, ej);
        return edge_edge_proximity(x[0], x[1], x[2], x[3]);
    };
    const std::vector<EdgeEdgePair> close =
        static_edge_edge_pairs(mesh, 0.5 * merge_distance, [&](int ei, int ej) {
            return mesh.edge_triangles(ei).size() == 2 && mesh.edge_triangles(ej).size() == 2 &&
                   proximity(ei, ej).distance < merge_distance;
        });
    std::vector<Candidate> candidates;
    candidates.reserve(close.size());
    for (const EdgeEdgePair& pair : close) {
        const Edge& a = mesh.edge(pair.ei);
        const Edge& b = mesh.edge(pair.ej);
        const std::array<Vec3, 4> x = ends(pair.ei, pair.ej);
        const EdgeEdgeProximity p = edge_edge_proximity(x[0], x[1], x[2], x[3]);
        const Vec3 on_a = (1.0 - p.s) * x[0] + p.s * x[1];
        const Vec3 on_b = (1.0 - p.u) * x[2] + p.u * x[3];
        const Vec3 midpoint = 0.5 * (on_a + on_b);
        candidates.push_back(
            {p.distance, a, b, mesh.periodic() ? mesh.periods().wrap(midpoint) : midpoint});
    }
    report.candidates = static_cast<int>(candidates.size());
    if (candidates.empty()) {
        report.seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return report;
    }
    // Nearest first, for real (§3.7); ties by vertex indices so the order is reproducible.
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
        if (x.distance != y.distance)
            return x.distance < y.distance;
        return std::tie(x.a, x.b) < std::tie(y.a, y.b);
    });

    // The exact intersection test's hash, built when the first candidate gets that far: most
    // candidates are refused by the cheap checks before it (a merge nearby, a shared vertex, an
    // existing edge), and a step with only such candidates never builds it. No merge happens
    // before it is built, so it sees the same mesh as one built here.
    std::unique_ptr<ElementHash> hash;

    const double spacing = options.merge_spacing_fraction * context.xi;
    std::vector<Vec3> merged_at;
    for (const Candidate& c : candidates) {
        context.cancel.throw_if_requested("merging");
        const bool near_merge = std::any_of(merged_at.begin(), merged_at.end(), [&](const Vec3& m) {
            return squared_separation(mesh, m, c.midpoint) < spacing * spacing;
        });
        if (near_merge) {
            ++report.deferred_near_merge;
            continue;
        }
        const int ea = mesh.find_edge(c.a[0], c.a[1]);
        const int eb = mesh.find_edge(c.b[0], c.b[1]);
        EdgeHole hole_a, hole_b;
        if (ea == INVALID_INDEX || eb == INVALID_INDEX || !edge_hole(mesh, ea, hole_a) ||
            !edge_hole(mesh, eb, hole_b)) {
            ++report.stale;
            continue;
        }
        if (merge_shares_vertex(hole_a, hole_b)) {
            ++report.refused_shared_vertex;
            continue;
        }
        if (merge_touches_boundary(mesh, hole_a, hole_b)) {
            ++report.refused_boundary;
            continue;
        }
        std::array<int, 4> shifts{0, 1, 2, 3};
        std::sort(shifts.begin(), shifts.end(), [&](int x, int y) {
            return alignment_cost(mesh, hole_a, hole_b, x) <
                   alignment_cost(mesh, hole_a, hole_b, y);
        });
        std::vector<Triangle> band;
        bool existing_edge = false, found = false;
        for (int k = 0; k < options.max_zipper_alignments && !found; ++k) {
            band = zipper_triangles(mesh, hole_a, hole_b, shifts[static_cast<size_t>(k)]);
            if (merge_creates_existing_edge(mesh, hole_a, band)) {
                existing_edge = true;
                continue;
            }
            if (context.collision_safety && !hash)
                hash = std::make_unique<ElementHash>(mesh, context.xi);
            if (hash && merge_intersects(mesh, *hash, hole_a, hole_b, band))
                continue;
            found = true;
        }
        if (!found) {
            ++(existing_edge ? report.refused_existing_edge : report.refused_intersection);
            continue;
        }
        std::vector<int> touched(hole_a.loop.begin(), hole_a.loop.end());
        touched.insert(touched.end(), hole_b.loop.begin(), hole_b.loop.end());
        if (hash)
            hash->begin_update(mesh, touched);
        const LabelPair labels = mesh.labels(hole_a.triangles[0]);
        for (int ti :
             {hole_a.triangles[0], hole_a.triangles[1], hole_b.triangles[0], hole_b.triangles[1]})
            mesh.remove_triangle(ti);
        for (const Triangle& t : band)
            mesh.add_triangle(t, labels);
        if (hash)
            hash->refresh(mesh, touched);
        ++report.merges;
        merged_at.push_back(c.midpoint);
    }
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

}  // namespace meniscus::tracker
