#include "tracker/topology/separate.h"

#include "common/assert.h"
#include "tracker/remesh/element_hash.h"
#include "tracker/remesh/local_safety.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <numeric>
#include <utility>

namespace meniscus::tracker {

namespace {

/// Each retry halves the nudge.
constexpr double NUDGE_REDUCTION = 0.5;

int find_root(std::vector<int>& parent, int i) {
    while (parent[static_cast<size_t>(i)] != i) {
        parent[static_cast<size_t>(i)] =
            parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
        i = parent[static_cast<size_t>(i)];
    }
    return i;
}

bool same_vertices(const Triangle& a, const Triangle& b) {
    for (int v : a)
        if (v != b[0] && v != b[1] && v != b[2])
            return false;
    return true;
}

/// Removes pairs of triangles on the same three vertices; returns how many pairs. Looks only at
/// the triangles added since the last call (the mesh's triangle marks, cleared here): a group on
/// the same vertices that none of them joined was left, the last time, with a single orientation
/// and nothing to pair.
int remove_degenerate_tetrahedra(SurfaceMesh& mesh) {
    // Two triangles on the same vertices share every edge, so a new one finds the whole group
    // among the triangles of its first edge, old members included.
    std::vector<int> duplicated;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_marked(ti) || !mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        for (int other : mesh.edge_triangles(mesh.triangle_edges(ti)[0]))
            if (other != ti && same_vertices(t, mesh.triangle(other))) {
                duplicated.push_back(ti);
                duplicated.push_back(other);
            }
    }
    mesh.clear_triangle_marks();
    std::sort(duplicated.begin(), duplicated.end());
    duplicated.erase(std::unique(duplicated.begin(), duplicated.end()), duplicated.end());
    std::map<std::array<int, 3>, std::vector<int>> by_vertices;
    for (int ti : duplicated) {
        std::array<int, 3> key = mesh.triangle(ti);
        std::sort(key.begin(), key.end());
        by_vertices[key].push_back(ti);
    }
    int removed = 0;
    for (const auto& [key, tris] : by_vertices) {
        if (tris.size() < 2)
            continue;
        // Pair each triangle with one of the opposite orientation so every edge stays balanced.
        std::vector<int> forward, backward;
        const Triangle& first = mesh.triangle(tris[0]);
        for (int ti : tris) {
            const Triangle& t = mesh.triangle(ti);
            bool same = false;
            for (int k = 0; k < 3; ++k)
                same = same || (t[k] == first[0] && t[(k + 1) % 3] == first[1]);
            (same ? forward : backward).push_back(ti);
        }
        const size_t pairs = std::min(forward.size(), backward.size());
        for (size_t k = 0; k < pairs; ++k) {
            mesh.remove_triangle(forward[k]);
            mesh.remove_triangle(backward[k]);
            ++removed;
        }
    }
    return removed;
}

/// The pairs of triangles around live edge `ei` that bound one wedge of the inside: around
/// (a, b) = its vertices, e = b − a, sorted by the angle of their third vertex about e, a
/// triangle wound a → b has the inside just clockwise of it and one wound b → a just
/// counterclockwise, so each b → a triangle pairs with the next one counterclockwise, which must
/// be wound a → b. On a manifold edge that is its two triangles. On a non-manifold edge (2k
/// triangles: two sheets that a pinch or a collapse brought together along it) it is k pairs, one
/// per sheet, so the sheets' vertices count as separate fans. Where the windings do not alternate
/// (not an oriented surface there) every triangle is paired with the first: one fan, as before.
std::vector<std::pair<int, int>> wedge_pairs(const SurfaceMesh& mesh, int ei) {
    const std::vector<int>& et = mesh.edge_triangles(ei);
    std::vector<std::pair<int, int>> pairs;
    if (et.size() <= 2) {
        if (et.size() == 2)
            pairs.emplace_back(et[0], et[1]);
        return pairs;
    }
    const Edge& edge = mesh.edge(ei);
    const Vec3& a = mesh.position(edge[0]);  // a periodic mesh's fins are read about it
    const Vec3 e = (mesh.position_near(edge[1], a) - a).normalized();
    // Any unit vector perpendicular to e, and its quarter turn about e.
    const Vec3 u = e.unitOrthogonal(), w = e.cross(u);
    struct Fin {
        double angle;
        bool a_to_b;
        int ti;
    };
    std::vector<Fin> fins;
    for (int ti : et) {
        const Triangle& t = mesh.triangle(ti);
        int c = -1;
        bool a_to_b = false;
        for (int k = 0; k < 3; ++k) {
            if (t[k] != edge[0] && t[k] != edge[1])
                c = t[k];
            a_to_b = a_to_b || (t[k] == edge[0] && t[(k + 1) % 3] == edge[1]);
        }
        const Vec3 d = mesh.position_near(c, a) - a;
        fins.push_back({std::atan2(d.dot(w), d.dot(u)), a_to_b, ti});
    }
    std::sort(fins.begin(), fins.end(),
              [](const Fin& x, const Fin& y) { return x.angle < y.angle; });
    const size_t n = fins.size();
    for (size_t k = 0; k < n; ++k)
        if (fins[k].a_to_b == fins[(k + 1) % n].a_to_b) {  // windings do not alternate
            pairs.clear();
            for (size_t j = 1; j < n; ++j)
                pairs.emplace_back(et[0], et[j]);
            return pairs;
        }
    for (size_t k = 0; k < n; ++k)
        if (!fins[k].a_to_b)
            pairs.emplace_back(fins[k].ti, fins[(k + 1) % n].ti);
    return pairs;
}

/// The fans of vi (vertex_fans()) when it is a live, interior, singular vertex; empty otherwise.
std::vector<std::vector<int>> singular_vertex_fans(const SurfaceMesh& mesh, int vi) {
    if (!mesh.vertex_alive(vi) || mesh.is_boundary_vertex(vi))
        return {};
    std::vector<std::vector<int>> fans = vertex_fans(mesh, vi);
    if (fans.size() < 2)
        fans.clear();
    return fans;
}

/// True when vi's triangles form one fan joined through manifold edges (each of its edges has
/// two triangles): the common case, which vertex_fans() would report as a single fan. Decided on
/// vi's link, from the triangles' vertices alone: each triangle (vi, a, b), in its orientation,
/// links a to b, and one consistently oriented manifold fan is exactly a link in which every
/// neighbour starts one link and ends one, all on a single cycle. (Then each edge (vi, a) lies in
/// the two triangles where a starts and ends a link, and in no other, since every triangle of
/// that edge contains vi.) A fan this misses — oriented inconsistently — only costs the caller
/// the full analysis: false is always safe.
bool one_manifold_fan(const SurfaceMesh& mesh, int vi) {
    const std::vector<int>& tris = mesh.vertex_triangles(vi);
    const size_t n = tris.size();
    if (n < 3)
        return false;
    constexpr size_t LOCAL = 16;  // valence of almost every vertex; larger fans take the heap
    std::array<int, LOCAL> from_local{}, to_local{};
    std::vector<int> from_heap, to_heap;
    int* from = from_local.data();
    int* to = to_local.data();
    if (n > LOCAL) {
        from_heap.resize(n);
        to_heap.resize(n);
        from = from_heap.data();
        to = to_heap.data();
    }
    for (size_t k = 0; k < n; ++k) {
        const Triangle& t = mesh.triangle(tris[k]);
        const int at = t[0] == vi ? 0 : t[1] == vi ? 1 : 2;
        from[k] = t[static_cast<size_t>((at + 1) % 3)];
        to[k] = t[static_cast<size_t>((at + 2) % 3)];
    }
    // Every neighbour starts exactly one link: no two links share a start (nor an end).
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j)
            if (from[i] == from[j] || to[i] == to[j])
                return false;
    // Follow the links from the first: a single cycle through all n returns after n steps.
    size_t k = 0;
    for (size_t steps = 1; steps <= n; ++steps) {
        size_t next = n;
        for (size_t j = 0; j < n; ++j)
            if (from[j] == to[k]) {
                next = j;
                break;
            }
        if (next == n)
            return false;  // a link ends where none starts: an open fan (boundary or fin)
        k = next;
        if (k == 0)
            return steps == n;
    }
    return false;
}

/// The mean of the fan's vertices other than vi; on a periodic mesh of their images nearest vi
/// (so near vi, possibly outside the box).
Vec3 fan_centroid(const SurfaceMesh& mesh, const std::vector<int>& fan, int vi) {
    const Vec3& x = mesh.position(vi);
    Vec3 sum = Vec3::Zero();
    int count = 0;
    for (int ti : fan)
        for (int v : mesh.triangle(ti))
            if (v != vi) {
                sum += mesh.position_near(v, x);
                ++count;
            }
    return sum / count;
}

/// p as a vertex position: wrapped into the box on a periodic mesh.
Vec3 stored_position(const SurfaceMesh& mesh, const Vec3& p) {
    return mesh.periodic() ? mesh.periods().wrap(p) : p;
}

}  // namespace

std::vector<std::vector<int>> vertex_fans(const SurfaceMesh& mesh, int vi) {
    const std::vector<int>& tris = mesh.vertex_triangles(vi);
    std::vector<int> parent(tris.size());
    std::iota(parent.begin(), parent.end(), 0);
    auto local = [&](int ti) {
        return static_cast<int>(std::find(tris.begin(), tris.end(), ti) - tris.begin());
    };
    const auto join = [&](int t0, int t1) {
        const int a = find_root(parent, local(t0));
        const int b = find_root(parent, local(t1));
        parent[static_cast<size_t>(a)] = b;
    };
    for (int ei : mesh.vertex_edges(vi)) {
        const std::vector<int>& et = mesh.edge_triangles(ei);
        if (et.size() == 2)
            join(et[0], et[1]);  // manifold: the common case, without sorting
        else if (et.size() > 2)
            for (const auto& [t0, t1] : wedge_pairs(mesh, ei))
                join(t0, t1);
    }
    // The common case, one fan, without grouping.
    const int first_root = tris.empty() ? 0 : find_root(parent, 0);
    bool single_fan = true;
    for (size_t k = 1; k < tris.size() && single_fan; ++k)
        single_fan = find_root(parent, static_cast<int>(k)) == first_root;
    if (single_fan)
        return tris.empty() ? std::vector<std::vector<int>>{} : std::vector<std::vector<int>>{tris};
    std::map<int, std::vector<int>> groups;
    for (size_t k = 0; k < tris.size(); ++k)
        groups[find_root(parent, static_cast<int>(k))].push_back(tris[k]);
    std::vector<std::vector<int>> fans;
    for (auto& [root, fan] : groups)
        fans.push_back(std::move(fan));
    return fans;
}

SeparationReport separate(SurfaceMesh& mesh, const SeparationOptions& options,
                          bool collision_safety, double xi) {
    const auto start = std::chrono::steady_clock::now();
    SeparationReport report;
    report.degenerate_tetrahedra_removed = remove_degenerate_tetrahedra(mesh);
    // Only marked vertices can have lost their triangles or their single fan (mesh.h): the
    // others were found regular by an earlier pass and their triangles have not changed since.
    std::vector<int> marked;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_marked(vi))
            continue;
        if (mesh.vertex_alive(vi) && mesh.vertex_triangles(vi).empty()) {
            mesh.remove_vertex(vi);
            ++report.orphan_vertices_removed;
        }
        marked.push_back(vi);
    }

    std::unique_ptr<ElementHash> hash;
    // Splitting a singular vertex rewires only its own triangles, whose edges to a vertex with
    // one manifold fan stay manifold: such a vertex stays regular, and only the others (found in
    // parallel) need the full fan analysis, in index order. Their marks stay set (a split marks
    // its vertices again, and one left joined is tried again next time); the regular lose theirs.
    std::vector<std::uint8_t> regular(marked.size(), 0);
    tbb::parallel_for(size_t{0}, marked.size(), [&](size_t m) {
        const int vi = marked[m];
        regular[m] = !mesh.vertex_alive(vi) || one_manifold_fan(mesh, vi) ? 1 : 0;
    });
    for (size_t m = 0; m < marked.size(); ++m)
        if (regular[m])
            mesh.clear_vertex_mark(marked[m]);
    for (size_t m = 0; m < marked.size(); ++m) {
        if (regular[m])
            continue;
        const int vi = marked[m];
        const std::vector<std::vector<int>> fans = singular_vertex_fans(mesh, vi);
        if (fans.empty())
            continue;
        if (collision_safety && !hash)
            hash = std::make_unique<ElementHash>(mesh, xi);
        std::vector<Vec3> centroids;
        for (const auto& fan : fans)
            centroids.push_back(fan_centroid(mesh, fan, vi));
        const Vec3 x = mesh.position(vi);
        // Fan 0 keeps vi; fan k > 0 gets a copy, named num_vertices() + k - 1 in the candidates.
        double fraction = options.nudge_fraction;
        bool accepted = false;
        std::vector<Vec3> nudged(fans.size());
        for (int attempt = 0; attempt <= options.max_nudge_halvings; ++attempt) {
            // Towards each fan's centroid, read about x; wrapped back on a periodic mesh.
            for (size_t k = 0; k < fans.size(); ++k)
                nudged[k] = stored_position(mesh, x + fraction * (centroids[k] - x));
            if (!hash) {
                accepted = true;
                break;
            }
            CandidateTriangles candidates;
            std::vector<int> replaced;
            for (size_t k = 0; k < fans.size(); ++k) {
                const int name = k == 0 ? vi : mesh.num_vertices() + static_cast<int>(k) - 1;
                candidates.overrides.push_back({name, nudged[k]});
                for (int ti : fans[k]) {
                    Triangle t = mesh.triangle(ti);
                    for (int& v : t)
                        if (v == vi)
                            v = name;
                    candidates.triangles.push_back(t);
                    replaced.push_back(ti);
                }
            }
            if (!candidate_triangles_intersect(mesh, *hash, candidates, replaced)) {
                accepted = true;
                break;
            }
            fraction *= NUDGE_REDUCTION;
        }
        if (!accepted) {
            ++report.refused_intersection;
            continue;
        }
        std::vector<int> touched;
        for (const auto& fan : fans)
            for (int ti : fan)
                for (int v : mesh.triangle(ti))
                    touched.push_back(v);
        if (hash)
            hash->begin_update(mesh, touched);
        for (size_t k = 1; k < fans.size(); ++k) {
            touched.push_back(mesh.duplicate_vertex(vi, fans[k], nudged[k]));
            ++report.copies_created;
        }
        mesh.set_position(vi, nudged[0]);
        if (hash)
            hash->refresh(mesh, touched);
        ++report.singular_vertices_split;
    }
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

EdgeManifoldReport make_edge_manifold(SurfaceMesh& mesh) {
    EdgeManifoldReport report;
    std::vector<int> nonmanifold;
    for (int ei = 0; ei < mesh.num_edges(); ++ei)
        if (mesh.edge_alive(ei) && mesh.is_nonmanifold_edge(ei))
            nonmanifold.push_back(ei);
    report.nonmanifold_edges = static_cast<int>(nonmanifold.size());
    // 1. Midpoints of the non-manifold edges. Splitting one replaces its triangles by halves
    //    that keep every other edge of theirs, so the others stay alive and non-manifold.
    for (int ei : nonmanifold) {
        MENISCUS_ASSERT(mesh.edge_alive(ei) && mesh.is_nonmanifold_edge(ei),
                        "a non-manifold edge vanished while splitting another");
        const Edge e = mesh.edge(ei);
        const Vec3& p0 = mesh.position(e[0]);
        const int m = mesh.split_edge(
            ei, stored_position(mesh, 0.5 * (p0 + mesh.position_near(e[1], p0))), 0.5);
        report.added.push_back({m, e[0], e[1], 0.5});
    }
    // 2. One copy per fan of every singular vertex.
    const int vertex_count = mesh.num_vertices();
    for (int vi = 0; vi < vertex_count; ++vi) {
        const std::vector<std::vector<int>> fans = singular_vertex_fans(mesh, vi);
        if (fans.empty())
            continue;
        for (size_t k = 1; k < fans.size(); ++k)
            report.added.push_back(
                {mesh.duplicate_vertex(vi, fans[k], mesh.position(vi)), vi, vi, 0.0});
        ++report.vertices_split;
    }
    return report;
}

}  // namespace meniscus::tracker
