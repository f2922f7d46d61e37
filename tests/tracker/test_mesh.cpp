#include "tracker/mesh.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace meniscus::tracker {
namespace {

/// Regular tetrahedron with outward normals.
SurfaceMesh tetrahedron() {
    return SurfaceMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                       {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
}

/// Octahedron (every vertex valence 4) with outward normals.
SurfaceMesh octahedron() {
    return SurfaceMesh(
        {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
        {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
}

/// A latitude–longitude sphere (`rings` − 1 rings of `segments` vertices and the two poles) with
/// its vertices and triangles numbered in a shuffled order, as a long run leaves them.
SurfaceMesh shuffled_uv_sphere(int rings, int segments) {
    std::vector<Vec3> positions = {{0, 0, 1}};
    for (int r = 1; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const double theta = M_PI * r / rings, phi = 2 * M_PI * s / segments;
            positions.emplace_back(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                   std::cos(theta));
        }
    positions.emplace_back(0, 0, -1);
    const int south = static_cast<int>(positions.size()) - 1;
    const auto ring = [&](int r, int s) { return 1 + (r - 1) * segments + s % segments; };
    std::vector<Triangle> triangles;
    for (int s = 0; s < segments; ++s) {
        triangles.push_back({0, ring(1, s), ring(1, s + 1)});
        triangles.push_back({south, ring(rings - 1, s + 1), ring(rings - 1, s)});
        for (int r = 1; r + 1 < rings; ++r) {
            triangles.push_back({ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
            triangles.push_back({ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
        }
    }
    std::mt19937 random(7);
    std::vector<int> order(positions.size());
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), random);
    std::vector<Vec3> shuffled(positions.size());
    for (size_t i = 0; i < order.size(); ++i)
        shuffled[static_cast<size_t>(order[i])] = positions[i];
    for (Triangle& t : triangles)
        for (int& v : t)
            v = order[static_cast<size_t>(v)];
    std::shuffle(triangles.begin(), triangles.end(), random);
    return SurfaceMesh(shuffled, triangles);
}

/// Triangle t with its vertices renamed through `map` and rotated to start at the smallest.
Triangle renamed(const Triangle& t, const std::vector<int>& map) {
    Triangle r = {map[static_cast<size_t>(t[0])], map[static_cast<size_t>(t[1])],
                  map[static_cast<size_t>(t[2])]};
    std::rotate(r.begin(), std::min_element(r.begin(), r.end()), r.end());
    return r;
}

bool has_kind(const std::vector<MeshViolation>& v, ViolationKind kind) {
    return std::any_of(v.begin(), v.end(), [&](const MeshViolation& m) { return m.kind == kind; });
}

TEST(SurfaceMesh, BuildsAdjacency) {
    const SurfaceMesh m = tetrahedron();
    EXPECT_EQ(m.count_live_vertices(), 4);
    EXPECT_EQ(m.count_live_edges(), 6);
    EXPECT_EQ(m.count_live_triangles(), 4);
    for (int ei = 0; ei < m.num_edges(); ++ei)
        EXPECT_EQ(m.edge_triangles(ei).size(), 2u);
    for (int vi = 0; vi < 4; ++vi)
        EXPECT_EQ(m.vertex_triangles(vi).size(), 3u);
    EXPECT_TRUE(validate_mesh(m).empty());
    EXPECT_NEAR(enclosed_volume(m), 1.0 / 6.0, 1e-15);
    EXPECT_EQ(euler_characteristic(m), 2);
}

TEST(SurfaceMesh, EnclosedVolumeAtOtherPositionsLeavesTheMeshAlone) {
    const SurfaceMesh m = octahedron();  // volume 4/3
    std::vector<Vec3> scaled = m.positions();
    for (Vec3& x : scaled)
        x = 2.0 * x + Vec3(5, -3, 1);  // volume × 8, wherever it is
    EXPECT_NEAR(enclosed_volume(m, scaled), 8.0 * 4.0 / 3.0, 1e-13);
    EXPECT_NEAR(enclosed_volume(m), 4.0 / 3.0, 1e-14);
    scaled.pop_back();
    EXPECT_THROW(enclosed_volume(m, scaled), std::invalid_argument);
}

TEST(SurfaceMesh, RejectsBadTriangles) {
    EXPECT_THROW(SurfaceMesh({{0, 0, 0}, {1, 0, 0}}, {{0, 1, 2}}), std::invalid_argument);
    EXPECT_THROW(SurfaceMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 1}}),
                 std::invalid_argument);
}

TEST(SurfaceMesh, SplitKeepsClosedAndVolume) {
    SurfaceMesh m = octahedron();
    const double v0 = enclosed_volume(m);
    const int ei = m.find_edge(0, 2);
    const int vi = m.split_edge(ei, 0.5 * (m.position(0) + m.position(2)));
    EXPECT_EQ(m.find_edge(0, 2), INVALID_INDEX);
    EXPECT_NE(m.find_edge(0, vi), INVALID_INDEX);
    EXPECT_NE(m.find_edge(vi, 4), INVALID_INDEX);
    EXPECT_EQ(m.count_live_triangles(), 10);
    EXPECT_TRUE(validate_mesh(m).empty());
    EXPECT_NEAR(enclosed_volume(m), v0, 1e-14);
}

TEST(SurfaceMesh, FlipReplacesDiagonal) {
    SurfaceMesh m = octahedron();
    // Split edge (0,2) so that the flip target (vi, 4) - (0, 2) quad exists, then flip (0, 4).
    const int ei = m.find_edge(0, 4);
    const auto tris = m.edge_triangles(ei);
    const int new_edge = m.flip_edge(ei, tris[0], tris[1]);
    const Edge e = m.edge(new_edge);
    EXPECT_TRUE((e == Edge{2, 3}));
    EXPECT_EQ(m.find_edge(0, 4), INVALID_INDEX);
    EXPECT_TRUE(validate_mesh(m).empty());
    EXPECT_THROW(
        m.flip_edge(new_edge, m.edge_triangles(new_edge)[0], m.edge_triangles(new_edge)[0]),
        std::invalid_argument);
}

TEST(SurfaceMesh, CollapseAndCompactNotifyObservers) {
    struct Recorder : MeshObserver {
        int collapses = 0;
        std::vector<int> map;
        void on_edge_collapse(int, int, double) override { ++collapses; }
        void on_compact(const std::vector<int>& m) override { map = m; }
    } recorder;
    SurfaceMesh m = octahedron();
    m.split_edge(m.find_edge(0, 2), {0.5, 0.5, 0});  // vertex 6, valence 4
    m.add_observer(&recorder);
    const int ei = m.find_edge(0, 6);
    m.collapse_edge(ei, 0, m.position(0), 0.0);
    EXPECT_EQ(recorder.collapses, 1);
    EXPECT_FALSE(m.vertex_alive(6));
    EXPECT_TRUE(validate_mesh(m).empty());
    EXPECT_TRUE(m.has_dead_elements());
    m.compact();
    EXPECT_FALSE(m.has_dead_elements());
    ASSERT_EQ(recorder.map.size(), 7u);
    EXPECT_EQ(recorder.map[6], INVALID_INDEX);
    EXPECT_EQ(recorder.map[5], 5);
    EXPECT_EQ(m.count_live_triangles(), 8);
    EXPECT_TRUE(validate_mesh(m).empty());
}

TEST(SurfaceMesh, CompactMovesOnlyTheElementsAboveTheLiveCount) {
    // compact() keeps every element below its kind's live count where it is and moves the live
    // ones above it into the dead slots below it, lowest first; what it leaves must be the same
    // mesh renumbered that way, every adjacency list complete and in its old order. The octahedron
    // is split, flipped and collapsed into a mesh with dead vertices, triangles and edges and
    // unsorted adjacency lists (removals swap with the back).
    SurfaceMesh m = octahedron();
    for (int round = 0; round < 6; ++round) {
        for (int ei = 0, n = m.num_edges(); ei < n; ei += 3)
            if (m.edge_alive(ei)) {
                const Edge e = m.edge(ei);
                // On the unit sphere, where no three vertices are collinear.
                m.split_edge(ei, (m.position(e[0]) + m.position(e[1])).normalized());
            }
        for (int ei = m.num_edges() - 1; ei >= 0; ei -= 5)
            if (m.edge_alive(ei) && m.edge_triangles(ei).size() == 2) {
                const auto& et = m.edge_triangles(ei);
                const int t0 = m.edge_orientation_in_triangle(et[0], ei) == 1 ? et[0] : et[1];
                const int t1 = t0 == et[0] ? et[1] : et[0];
                const Edge e = m.edge(ei);
                // Flip only where the other diagonal is not an edge already.
                if (m.find_edge(m.opposite_vertex(t0, ei), m.opposite_vertex(t1, ei)) ==
                        INVALID_INDEX &&
                    e[0] != e[1])
                    m.flip_edge(ei, t0, t1);
            }
        for (int ei = 0; ei < m.num_edges(); ei += 7)
            if (m.edge_alive(ei) && m.vertex_triangles(m.edge(ei)[1]).size() >= 5 &&
                m.vertex_triangles(m.edge(ei)[0]).size() >= 5) {
                const Edge e = m.edge(ei);
                // Only where the collapse keeps the mesh a manifold (the link condition).
                int common = 0;
                for (int a : m.vertex_edges(e[0]))
                    for (int b : m.vertex_edges(e[1]))
                        common += m.other_vertex(a, e[0]) == m.other_vertex(b, e[1]) ? 1 : 0;
                if (common == 2)
                    m.collapse_edge(ei, e[0], (m.position(e[0]) + m.position(e[1])).normalized(),
                                    0.5);
            }
    }
    ASSERT_TRUE(m.has_dead_elements());
    ValidationOptions connectivity_only;  // the positions are not the point here
    connectivity_only.check_degenerate_area = false;
    ASSERT_TRUE(validate_mesh(m, connectivity_only).empty());

    // The renumbering the rule gives, for one kind of element.
    const auto expected_map = [](int slots, const auto& alive) {
        std::vector<int> map(static_cast<size_t>(slots), INVALID_INDEX);
        int live = 0;
        for (int i = 0; i < slots; ++i)
            live += alive(i) ? 1 : 0;
        int hole = 0;
        for (int i = 0; i < slots; ++i) {
            if (!alive(i))
                continue;
            if (i < live) {
                map[static_cast<size_t>(i)] = i;
                continue;
            }
            while (hole < live && alive(hole))
                ++hole;
            map[static_cast<size_t>(i)] = hole++;
        }
        return map;
    };
    const std::vector<int> vmap =
        expected_map(m.num_vertices(), [&](int i) { return m.vertex_alive(i); });
    const std::vector<int> tmap =
        expected_map(m.num_triangles(), [&](int i) { return m.triangle_alive(i); });
    const std::vector<int> emap =
        expected_map(m.num_edges(), [&](int i) { return m.edge_alive(i); });
    const auto mapped = [](std::vector<int> list, const std::vector<int>& map) {
        for (int& i : list)
            i = map[static_cast<size_t>(i)];
        return list;
    };
    const SurfaceMesh before = m;

    EXPECT_EQ(m.compact(), vmap);
    EXPECT_FALSE(m.has_dead_elements());
    EXPECT_TRUE(validate_mesh(m, connectivity_only).empty());
    ASSERT_EQ(m.num_vertices(), before.count_live_vertices());
    ASSERT_EQ(m.num_triangles(), before.count_live_triangles());
    ASSERT_EQ(m.num_edges(), before.count_live_edges());
    for (int vi = 0; vi < before.num_vertices(); ++vi) {
        if (!before.vertex_alive(vi))
            continue;
        const int now = vmap[static_cast<size_t>(vi)];
        EXPECT_EQ(m.position(now), before.position(vi));
        EXPECT_EQ(m.vertex_triangles(now), mapped(before.vertex_triangles(vi), tmap)) << vi;
        EXPECT_EQ(m.vertex_edges(now), mapped(before.vertex_edges(vi), emap)) << vi;
    }
    for (int ti = 0; ti < before.num_triangles(); ++ti) {
        if (!before.triangle_alive(ti))
            continue;
        const int now = tmap[static_cast<size_t>(ti)];
        const Triangle& t = before.triangle(ti);
        EXPECT_EQ(m.triangle(now),
                  (Triangle{vmap[static_cast<size_t>(t[0])], vmap[static_cast<size_t>(t[1])],
                            vmap[static_cast<size_t>(t[2])]}));
        const std::array<int, 3>& e = before.triangle_edges(ti);
        EXPECT_EQ(m.triangle_edges(now), (std::array<int, 3>{emap[static_cast<size_t>(e[0])],
                                                             emap[static_cast<size_t>(e[1])],
                                                             emap[static_cast<size_t>(e[2])]}));
        EXPECT_EQ(m.labels(now), before.labels(ti));
    }
    for (int ei = 0; ei < before.num_edges(); ++ei) {
        if (!before.edge_alive(ei))
            continue;
        const int now = emap[static_cast<size_t>(ei)];
        const Edge& e = before.edge(ei);
        const int a = vmap[static_cast<size_t>(e[0])], b = vmap[static_cast<size_t>(e[1])];
        EXPECT_EQ(m.edge(now), (Edge{std::min(a, b), std::max(a, b)}));  // smaller index first
        EXPECT_EQ(m.edge_triangles(now), mapped(before.edge_triangles(ei), tmap)) << ei;
    }
}

TEST(SurfaceMesh, SortSpatiallyKeepsTheMeshAndBringsNeighboursTogether) {
    struct Recorder : MeshObserver {
        std::vector<int> map;
        void on_compact(const std::vector<int>& m) override { map = m; }
    } recorder;
    SurfaceMesh m = shuffled_uv_sphere(40, 80);  // 3122 vertices
    const SurfaceMesh before = m;
    EXPECT_GT(before.far_edge_fraction(), 0.5);
    m.add_observer(&recorder);
    const std::vector<int> map = m.sort_spatially();
    EXPECT_EQ(recorder.map, map);
    EXPECT_LT(m.far_edge_fraction(), 0.2);

    // The same mesh, renamed: a permutation that carries positions, triangles (orientation and
    // labels) and edges along, with consistent adjacency.
    ASSERT_EQ(map.size(), static_cast<size_t>(before.num_vertices()));
    std::vector<int> sorted_map = map;
    std::sort(sorted_map.begin(), sorted_map.end());
    std::vector<int> identity(map.size());
    std::iota(identity.begin(), identity.end(), 0);
    EXPECT_EQ(sorted_map, identity);
    for (int vi = 0; vi < before.num_vertices(); ++vi)
        EXPECT_EQ(m.position(map[static_cast<size_t>(vi)]), before.position(vi));
    std::vector<Triangle> expected, got;
    for (int ti = 0; ti < before.num_triangles(); ++ti)
        expected.push_back(renamed(before.triangle(ti), map));
    std::vector<int> all(map.size());
    std::iota(all.begin(), all.end(), 0);
    int previous_lowest = 0;
    for (int ti = 0; ti < m.num_triangles(); ++ti) {
        got.push_back(renamed(m.triangle(ti), all));
        const int lowest = got.back()[0];
        EXPECT_LE(previous_lowest, lowest) << ti;  // triangles follow their smallest vertex
        previous_lowest = lowest;
    }
    std::sort(expected.begin(), expected.end());
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, expected);
    std::vector<int> old_of(map.size());
    for (size_t vi = 0; vi < map.size(); ++vi)
        old_of[static_cast<size_t>(map[vi])] = static_cast<int>(vi);
    ASSERT_EQ(m.num_edges(), before.num_edges());
    for (int ei = 0; ei < m.num_edges(); ++ei) {
        const Edge& e = m.edge(ei);
        EXPECT_LT(e[0], e[1]);  // smaller index first
        EXPECT_NE(
            before.find_edge(old_of[static_cast<size_t>(e[0])], old_of[static_cast<size_t>(e[1])]),
            INVALID_INDEX);
    }
    EXPECT_TRUE(validate_mesh(m).empty());

    m.remove_triangle(0);
    EXPECT_THROW(m.sort_spatially(), std::logic_error);
}

TEST(SurfaceMesh, DuplicateVertexSeparatesFans) {
    // Two tetrahedra sharing only vertex 0: a singular vertex. Duplicating one fan separates them.
    SurfaceMesh m(
        {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}},
        {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}, {0, 5, 4}, {0, 4, 6}, {0, 6, 5}, {4, 5, 6}});
    EXPECT_EQ(triangle_components(m).count, 2);
    EXPECT_EQ(euler_characteristic(m), 3);  // one vertex shared: 7 − 12 + 8
    const std::vector<int> fan = {4, 5, 6};
    m.duplicate_vertex(0, fan, {-1e-3, -1e-3, -1e-3});
    EXPECT_EQ(euler_characteristic(m), 4);
    EXPECT_TRUE(validate_mesh(m).empty());
}

TEST(SurfaceMesh, MarksFollowConnectivityChangesAndCompaction) {
    // Built meshes start marked; a flip marks exactly the four vertices of its two triangles and
    // the two new triangles; compaction carries the marks to the new indices.
    SurfaceMesh m = octahedron();
    for (int vi = 0; vi < m.num_vertices(); ++vi)
        EXPECT_TRUE(m.vertex_marked(vi));
    for (int ti = 0; ti < m.num_triangles(); ++ti)
        EXPECT_TRUE(m.triangle_marked(ti));
    for (int vi = 0; vi < m.num_vertices(); ++vi)
        m.clear_vertex_mark(vi);
    m.clear_triangle_marks();
    const int ei = m.find_edge(0, 2);  // triangles (0, 2, 4) and (2, 0, 5)
    ASSERT_NE(ei, INVALID_INDEX);
    const std::vector<int> pair = m.edge_triangles(ei);
    m.flip_edge(ei, pair[0], pair[1]);  // (0, 2) becomes (4, 5)
    for (int vi = 0; vi < m.num_vertices(); ++vi)
        EXPECT_EQ(m.vertex_marked(vi), vi == 0 || vi == 2 || vi == 4 || vi == 5) << vi;
    for (int ti = 0; ti < m.num_triangles(); ++ti)
        EXPECT_EQ(m.triangle_marked(ti), ti >= 8) << ti;
    const SurfaceMesh copy = m;
    EXPECT_TRUE(copy.vertex_marked(4) && !copy.vertex_marked(1));

    const std::vector<int> vertex_map = m.compact();  // the two dead triangles go
    ASSERT_EQ(m.num_triangles(), 8);
    for (int vi = 0; vi < 6; ++vi)
        EXPECT_EQ(m.vertex_marked(vertex_map[static_cast<size_t>(vi)]),
                  vi == 0 || vi == 2 || vi == 4 || vi == 5);
    const int a = vertex_map[4], b = vertex_map[5];
    for (int ti = 0; ti < m.num_triangles(); ++ti) {  // the flip's two: the ones on edge (4, 5)
        const Triangle& t = m.triangle(ti);
        const bool on_new_edge =
            std::count(t.begin(), t.end(), a) + std::count(t.begin(), t.end(), b) == 2;
        EXPECT_EQ(m.triangle_marked(ti), on_new_edge) << ti;
    }

    // A duplicated vertex and its new triangles are marked.
    m.clear_triangle_marks();
    for (int vi = 0; vi < m.num_vertices(); ++vi)
        m.clear_vertex_mark(vi);
    const int copy_vi = m.duplicate_vertex(1, {m.vertex_triangles(1)[0]}, m.position(1));
    EXPECT_TRUE(m.vertex_marked(copy_vi) && m.vertex_marked(1));
    EXPECT_TRUE(m.triangle_marked(m.num_triangles() - 1));
}

TEST(MeshValidate, ListsEveryViolation) {
    // Open, inconsistently oriented, duplicated and degenerate, all at once.
    SurfaceMesh m({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {0, 0, 1}},
                  {{0, 1, 2}, {0, 1, 4}, {2, 1, 0}, {0, 1, 3}});
    const auto v = validate_mesh(m);
    EXPECT_TRUE(has_kind(v, ViolationKind::BoundaryEdge));
    EXPECT_TRUE(has_kind(v, ViolationKind::DuplicateTriangle));
    EXPECT_TRUE(has_kind(v, ViolationKind::DegenerateTriangle));
    EXPECT_TRUE(has_kind(v, ViolationKind::InconsistentOrientation) ||
                has_kind(v, ViolationKind::OddEdgeValence) ||
                has_kind(v, ViolationKind::BoundaryEdge));
    EXPECT_GE(v.size(), 4u);
    ValidationOptions open;
    open.allow_boundary = true;
    EXPECT_FALSE(has_kind(validate_mesh(m, open), ViolationKind::BoundaryEdge));
}

TEST(MeshValidate, DetectsInconsistentOrientation) {
    SurfaceMesh m = tetrahedron();
    // Re-add one triangle reversed.
    SurfaceMesh flipped({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                        {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 3, 2}});
    EXPECT_TRUE(has_kind(validate_mesh(flipped), ViolationKind::InconsistentOrientation));
    EXPECT_TRUE(validate_mesh(m).empty());
}

TEST(MeshValidate, AcceptsEvenNonManifoldEdge) {
    // Two tetrahedra sharing edge (0,1): four triangles on it, two each way.
    SurfaceMesh m(
        {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, 0.3, 1}, {0.5, -1, 0}, {0.5, -0.3, -1}},
        {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}, {0, 1, 4}, {0, 5, 1}, {0, 4, 5}, {1, 5, 4}});
    const auto v = validate_mesh(m);
    EXPECT_TRUE(v.empty()) << v.front().message;
    EXPECT_TRUE(m.is_nonmanifold_edge(m.find_edge(0, 1)));
}

}  // namespace
}  // namespace meniscus::tracker
