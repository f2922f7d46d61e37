#include "tracker/topology/separate.h"

#include "tracker/remesh/element_hash.h"
#include "tracker/remesh/local_safety.h"

#include <algorithm>
#include <chrono>
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

/// Removes pairs of triangles on the same three vertices; returns how many pairs.
int remove_degenerate_tetrahedra(SurfaceMesh& mesh) {
    std::map<std::array<int, 3>, std::vector<int>> by_vertices;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
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

Vec3 fan_centroid(const SurfaceMesh& mesh, const std::vector<int>& fan, int vi) {
    Vec3 sum = Vec3::Zero();
    int count = 0;
    for (int ti : fan)
        for (int v : mesh.triangle(ti))
            if (v != vi) {
                sum += mesh.position(v);
                ++count;
            }
    return sum / count;
}

}  // namespace

std::vector<std::vector<int>> vertex_fans(const SurfaceMesh& mesh, int vi) {
    const std::vector<int>& tris = mesh.vertex_triangles(vi);
    std::vector<int> parent(tris.size());
    std::iota(parent.begin(), parent.end(), 0);
    auto local = [&](int ti) {
        return static_cast<int>(std::find(tris.begin(), tris.end(), ti) - tris.begin());
    };
    for (int ei : mesh.vertex_edges(vi)) {
        const auto& et = mesh.edge_triangles(ei);
        for (size_t k = 1; k < et.size(); ++k) {
            const int a = find_root(parent, local(et[0]));
            const int b = find_root(parent, local(et[k]));
            parent[static_cast<size_t>(a)] = b;
        }
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
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (mesh.vertex_alive(vi) && mesh.vertex_triangles(vi).empty()) {
            mesh.remove_vertex(vi);
            ++report.orphan_vertices_removed;
        }
    }

    std::unique_ptr<ElementHash> hash;
    const int vertex_count = mesh.num_vertices();
    for (int vi = 0; vi < vertex_count; ++vi) {
        if (!mesh.vertex_alive(vi) || mesh.is_boundary_vertex(vi))
            continue;
        const std::vector<std::vector<int>> fans = vertex_fans(mesh, vi);
        if (fans.size() < 2)
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
            for (size_t k = 0; k < fans.size(); ++k)
                nudged[k] = x + fraction * (centroids[k] - x);
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

}  // namespace meniscus::tracker
