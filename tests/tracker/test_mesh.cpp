#include "tracker/mesh.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"

#include <gtest/gtest.h>

#include <algorithm>

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

TEST(SurfaceMesh, CompactEqualsRebuildingFromTheLiveElements) {
    // compact() renumbers in place; what it leaves must be exactly the mesh that the
    // constructor builds from the live positions, triangles and labels (edge numbering,
    // adjacency order and all), so that every later operation behaves as it did when compact()
    // was that rebuild. The octahedron is split, flipped and collapsed into a mesh with dead
    // vertices, triangles and edges and unsorted adjacency lists (removals swap with the back).
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
    std::vector<Vec3> positions;
    for (int vi = 0; vi < m.num_vertices(); ++vi)
        if (m.vertex_alive(vi))
            positions.push_back(m.position(vi));
    std::vector<int> map(static_cast<size_t>(m.num_vertices()), INVALID_INDEX);
    for (int vi = 0, next = 0; vi < m.num_vertices(); ++vi)
        if (m.vertex_alive(vi))
            map[static_cast<size_t>(vi)] = next++;
    std::vector<Triangle> triangles;
    std::vector<LabelPair> labels;
    for (int ti = 0; ti < m.num_triangles(); ++ti)
        if (m.triangle_alive(ti)) {
            Triangle t = m.triangle(ti);
            for (int& v : t)
                v = map[static_cast<size_t>(v)];
            triangles.push_back(t);
            labels.push_back(m.labels(ti));
        }
    const SurfaceMesh rebuilt(positions, triangles, labels);
    EXPECT_EQ(m.compact(), map);
    ASSERT_EQ(m.num_vertices(), rebuilt.num_vertices());
    ASSERT_EQ(m.num_triangles(), rebuilt.num_triangles());
    ASSERT_EQ(m.num_edges(), rebuilt.num_edges());
    EXPECT_FALSE(m.has_dead_elements());
    for (int vi = 0; vi < m.num_vertices(); ++vi) {
        EXPECT_EQ(m.position(vi), rebuilt.position(vi));
        EXPECT_EQ(m.vertex_triangles(vi), rebuilt.vertex_triangles(vi)) << "vertex " << vi;
        EXPECT_EQ(m.vertex_edges(vi), rebuilt.vertex_edges(vi)) << "vertex " << vi;
    }
    for (int ti = 0; ti < m.num_triangles(); ++ti) {
        EXPECT_EQ(m.triangle(ti), rebuilt.triangle(ti));
        EXPECT_EQ(m.triangle_edges(ti), rebuilt.triangle_edges(ti));
        EXPECT_EQ(m.labels(ti).inside, rebuilt.labels(ti).inside);
        EXPECT_EQ(m.labels(ti).outside, rebuilt.labels(ti).outside);
    }
    for (int ei = 0; ei < m.num_edges(); ++ei) {
        EXPECT_EQ(m.edge(ei), rebuilt.edge(ei));
        EXPECT_EQ(m.edge_triangles(ei), rebuilt.edge_triangles(ei)) << "edge " << ei;
    }
    EXPECT_TRUE(validate_mesh(m, connectivity_only).empty());
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
    for (int ti = 0; ti < m.num_triangles(); ++ti)
        EXPECT_EQ(m.triangle_marked(ti), ti >= 6) << ti;  // the flip's two, last in order

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
