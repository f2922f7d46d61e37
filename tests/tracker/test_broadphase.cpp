#include "tracker/broadphase.h"
#include "tracker/implicit_mesher.h"
#include "tracker/mesh_intersections.h"
#include "tracker/mesh_io.h"

#include <gtest/gtest.h>

#include <random>

namespace meniscus::tracker {
namespace {

SurfaceMesh meshed(const ShapePtr& shape, double h) {
    ImplicitMeshOptions o;
    o.edge_length = h;
    return mesh_implicit_shape(*shape, o);
}

std::vector<Vec3> randomly_moved(const SurfaceMesh& m, double amplitude, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, amplitude);
    std::vector<Vec3> x = m.positions();
    for (Vec3& p : x)
        p += Vec3(n(rng), n(rng), n(rng));
    return x;
}

/// `count` separate random triangles in [−half_width, half_width]³ of mixed sizes: most with
/// corners within 0.1 of the first on each axis, 22 % three times that (oversized for the grids'
/// cells), 3 % `huge_scale` times that (spanning many cells).
SurfaceMesh scattered_triangles(unsigned seed, int count, double half_width, double huge_scale) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> pos(-half_width, half_width), size(-0.1, 0.1),
        coin(0.0, 1.0);
    std::vector<Vec3> positions;
    std::vector<Triangle> triangles;
    for (int k = 0; k < count; ++k) {
        const double u = coin(rng);
        const double scale = u < 0.03 ? huge_scale : u < 0.25 ? 3.0 : 1.0;
        const Vec3 a(pos(rng), pos(rng), pos(rng));
        const int base = static_cast<int>(positions.size());
        positions.push_back(a);
        positions.push_back(a + scale * Vec3(size(rng), size(rng), size(rng)));
        positions.push_back(a + scale * Vec3(size(rng), size(rng), size(rng)));
        triangles.push_back({base, base + 1, base + 2});
    }
    return SurfaceMesh(positions, triangles);
}

template <typename Pair>
bool includes(std::vector<Pair> super, std::vector<Pair> sub) {
    std::sort(super.begin(), super.end());
    std::sort(sub.begin(), sub.end());
    return std::includes(super.begin(), super.end(), sub.begin(), sub.end());
}

class BroadPhaseSuperset : public testing::TestWithParam<int> {};

TEST_P(BroadPhaseSuperset, EqualsBruteForceOnRandomMotion) {
    const int seed = GetParam();
    const SurfaceMesh m = meshed(
        make_union({make_sphere({0, 0, 0}, 0.2), make_torus({0.25, 0, 0}, {1, 1, 0}, 0.2, 0.06)}),
        0.04);
    // Step sizes from tiny to several edge lengths (boxes spanning many cells).
    const double amplitude = 0.001 * std::pow(4.0, seed % 6);
    const std::vector<Vec3> x0 = randomly_moved(m, 0.1 * amplitude, 100 + seed);
    const std::vector<Vec3> x1 = randomly_moved(m, amplitude, 200 + seed);
    const double padding = (seed % 3) * 0.01;
    const BroadPhase broad(m, x0, x1, padding);
    const auto vt = broad.vertex_triangle_pairs();
    const auto ee = broad.edge_edge_pairs();
    const auto vt_ref = brute_force_vertex_triangle_pairs(m, x0, x1, padding);
    const auto ee_ref = brute_force_edge_edge_pairs(m, x0, x1, padding);
    // A superset, and since the final filter is the same exact box test, exactly equal.
    EXPECT_TRUE(includes(vt, vt_ref));
    EXPECT_TRUE(includes(ee, ee_ref));
    EXPECT_EQ(vt.size(), vt_ref.size());
    EXPECT_EQ(ee.size(), ee_ref.size());
}

INSTANTIATE_TEST_SUITE_P(Seeds, BroadPhaseSuperset, testing::Range(0, 12));

TEST(SpatialHash, InsertRemoveUpdateQuery) {
    SpatialHash h(0.5);
    h.insert(3, Box3d(Vec3(0, 0, 0), Vec3(1, 1, 1)));
    h.insert(7, Box3d(Vec3(2, 2, 2), Vec3(3, 3, 3)));
    h.insert(9, Box3d(Vec3(-1e6, -1e6, -1e6), Vec3(1e6, 1e6, 1e6)));  // oversized
    std::vector<int> out;
    h.query(Box3d(Vec3(0.9, 0.9, 0.9), Vec3(2.1, 2.1, 2.1)), out);
    EXPECT_EQ(out, (std::vector<int>{3, 7, 9}));
    h.remove(3);
    h.query(Box3d(Vec3(0.5, 0.5, 0.5), Vec3(0.6, 0.6, 0.6)), out);
    EXPECT_EQ(out, (std::vector<int>{9}));
    h.insert(7, Box3d(Vec3(0.5, 0.5, 0.5), Vec3(0.55, 0.55, 0.55)));  // moved
    h.query(Box3d(Vec3(0.5, 0.5, 0.5), Vec3(0.6, 0.6, 0.6)), out);
    EXPECT_EQ(out, (std::vector<int>{7, 9}));
    h.query(Box3d(Vec3(2, 2, 2), Vec3(3, 3, 3)), out);
    EXPECT_EQ(out, (std::vector<int>{9}));
    // Touching boxes count (closed boxes).
    h.query(Box3d(Vec3(0.55, 0.55, 0.55), Vec3(0.7, 0.7, 0.7)), out);
    EXPECT_EQ(out, (std::vector<int>{7, 9}));
}

// Random inserts, moves and removals (boxes from tiny to many cells wide, some far from the
// origin) against a brute-force list: every query must equal the brute-force answer.
TEST(SpatialHash, RandomUpdatesMatchBruteForce) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> pos(-3.0, 3.0), size(0.0, 0.4), coin(0.0, 1.0);
    SpatialHash h(0.25);
    std::vector<Box3d> boxes(300);  // empty = absent
    const auto random_box = [&]() {
        const Vec3 lo(pos(rng), pos(rng), pos(rng));
        const double scale = coin(rng) < 0.05 ? 20.0 : 1.0;  // a few oversized
        const Vec3 hi = lo + scale * Vec3(size(rng), size(rng), size(rng));
        return Box3d(lo, hi);
    };
    std::vector<int> out;
    for (int round = 0; round < 4000; ++round) {
        const int id = static_cast<int>(rng() % boxes.size());
        if (coin(rng) < 0.3) {
            h.remove(id);
            boxes[static_cast<size_t>(id)].setEmpty();
        } else {
            boxes[static_cast<size_t>(id)] = random_box();
            h.insert(id, boxes[static_cast<size_t>(id)]);
        }
        if (round % 20 != 0)
            continue;
        const Box3d q = random_box();
        h.query(q, out);
        std::vector<int> expected;
        for (size_t i = 0; i < boxes.size(); ++i)
            if (!boxes[i].isEmpty() && boxes[i].intersects(q))
                expected.push_back(static_cast<int>(i));
        ASSERT_EQ(out, expected) << "round " << round;
        for (size_t i = 0; i < boxes.size(); ++i)
            ASSERT_EQ(h.contains(static_cast<int>(i)), !boxes[i].isEmpty());
    }
}

// The loose grid's self join finds every overlapping pair exactly once, also for oversized
// elements (wider than a cell: found through the cells they cover, or by a scan when they
// cover too many) among ordinary ones. Graded meshes (A4 with thin-sheet sizing) have many
// edges a little wider than the cell. Here: separate random triangles of mixed sizes.
TEST(BroadPhaseTrianglePairs, EqualBruteForceWithOversizedTriangles) {
    const SurfaceMesh m = scattered_triangles(11, 600, 2.0, 40.0);
    const BroadPhase broad(m, 0.0);
    const std::vector<TrianglePair> found = broad.triangle_pairs();
    std::vector<TrianglePair> expected;
    const auto box = [&](int t) {
        Box3d b;
        for (int vi : m.triangle(t))
            b.extend(m.position(vi));
        return b;
    };
    for (int ti = 0; ti < m.num_triangles(); ++ti)
        for (int tj = ti + 1; tj < m.num_triangles(); ++tj)
            if (box(ti).intersects(box(tj)))
                expected.push_back({ti, tj});
    EXPECT_EQ(found, expected);
}

// Triangle pairs of the static broad phase equal brute force (self join over one grid).
TEST(BroadPhaseTrianglePairs, EqualBruteForce) {
    const SurfaceMesh m = meshed(
        make_union({make_sphere({0, 0, 0}, 0.2), make_torus({0.25, 0, 0}, {1, 1, 0}, 0.2, 0.06)}),
        0.04);
    for (double padding : {0.0, 0.01, 0.3}) {
        const BroadPhase broad(m, padding);
        std::vector<TrianglePair> expected;
        for (int ti = 0; ti < m.num_triangles(); ++ti)
            for (int tj = ti + 1; tj < m.num_triangles(); ++tj) {
                if (!m.triangle_alive(ti) || !m.triangle_alive(tj))
                    continue;
                const auto box = [&](int t) {
                    Box3d b;
                    for (int vi : m.triangle(t))
                        b.extend(m.position(vi));
                    b.min().array() -= padding;
                    b.max().array() += padding;
                    return b;
                };
                if (box(ti).intersects(box(tj)))
                    expected.push_back({ti, tj});
            }
        EXPECT_EQ(broad.triangle_pairs(), expected) << "padding " << padding;
    }
}

// The merge search's pairs (the loose grid's self join, each cell against the neighbours its
// elements reach) equal brute force: on a mesh at rest, with paddings from none to several
// edge lengths (most edges then oversized), and with `keep` applied to exactly the overlapping
// pairs.
TEST(StaticEdgeEdgePairs, EqualBruteForceAtEveryPadding) {
    const SurfaceMesh m = meshed(
        make_union({make_sphere({0, 0, 0}, 0.2), make_torus({0.25, 0, 0}, {1, 1, 0}, 0.2, 0.06)}),
        0.04);
    for (double padding : {0.0, 0.005, 0.03, 0.3}) {
        const auto expected = brute_force_edge_edge_pairs(m, m.positions(), m.positions(), padding);
        const auto found = static_edge_edge_pairs(m, padding, [](int, int) { return true; });
        EXPECT_EQ(found, expected) << "padding " << padding;
        // keep() sees each pair once, lower index first, and decides alone what is returned.
        const auto odd = static_edge_edge_pairs(m, padding, [](int a, int b) {
            EXPECT_LT(a, b);
            return (a + b) % 2 == 1;
        });
        std::vector<EdgeEdgePair> expected_odd;
        for (const EdgeEdgePair& p : expected)
            if ((p.ei + p.ej) % 2 == 1)
                expected_odd.push_back(p);
        EXPECT_EQ(odd, expected_odd) << "padding " << padding;
    }
}

// Edges of very different lengths (a few far wider than the grid's cells, found through the
// cells they cover or by a scan) among ordinary ones: still exactly the brute-force pairs.
TEST(StaticEdgeEdgePairs, EqualBruteForceWithOversizedEdges) {
    const SurfaceMesh m = scattered_triangles(5, 500, 1.0, 30.0);
    for (double padding : {0.0, 0.02}) {
        const auto expected = brute_force_edge_edge_pairs(m, m.positions(), m.positions(), padding);
        EXPECT_EQ(static_edge_edge_pairs(m, padding, [](int, int) { return true; }), expected)
            << "padding " << padding;
    }
}

// The loose grid finds cells through a dense table when the occupied cells fill a compact block
// (the tests above) and through a hash when they are spread out: two small spheres a hundred
// radii apart give the same pairs as brute force, for the self join and for the queries.
TEST(StaticEdgeEdgePairs, EqualBruteForceWhenTheCellsAreSpreadOut) {
    const SurfaceMesh m = meshed(
        make_union({make_sphere({0, 0, 0}, 0.1), make_sphere({10.0, 3.0, -7.0}, 0.1)}), 0.03);
    for (double padding : {0.0, 0.01}) {
        const auto expected = brute_force_edge_edge_pairs(m, m.positions(), m.positions(), padding);
        EXPECT_EQ(static_edge_edge_pairs(m, padding, [](int, int) { return true; }), expected)
            << "padding " << padding;
        const std::vector<Vec3> x1 = randomly_moved(m, 0.01, 7);
        const BroadPhase broad(m, m.positions(), x1, padding);
        EXPECT_EQ(broad.vertex_triangle_pairs().size(),
                  brute_force_vertex_triangle_pairs(m, m.positions(), x1, padding).size());
        EXPECT_EQ(broad.edge_edge_pairs().size(),
                  brute_force_edge_edge_pairs(m, m.positions(), x1, padding).size());
    }
}

TEST(MeshIntersections, GeneratedMeshesAreIntersectionFree) {
    for (const auto& shape :
         {make_sphere({0, 0, 0}, 0.3), make_torus({0, 0, 0}, {0, 0, 1}, 0.3, 0.05),
          make_dumbbell({0, 0, 0}, 0.4, 1.0, 0.2, 0.05),
          make_union({make_sphere({-0.25, 0, 0}, 0.2), make_sphere({0.25, 0, 0}, 0.2)})}) {
        const SurfaceMesh m = meshed(shape, 0.03);
        const IntersectionReport r = find_self_intersections(m);
        EXPECT_TRUE(r.intersection_free()) << r.triangle_pairs.size() << " intersecting pairs";
        EXPECT_TRUE(is_intersection_free(m));
    }
}

TEST(MeshIntersections, FindsInterpenetratingSpheres) {
    // Two separately meshed spheres overlapping: the union of their meshes intersects itself.
    const SurfaceMesh a = meshed(make_sphere({0, 0, 0}, 0.2), 0.04);
    const SurfaceMesh b = meshed(make_sphere({0.3, 0, 0}, 0.2), 0.04);
    std::vector<Vec3> x = a.positions();
    std::vector<Triangle> t;
    for (int ti = 0; ti < a.num_triangles(); ++ti)
        t.push_back(a.triangle(ti));
    const int offset = static_cast<int>(x.size());
    x.insert(x.end(), b.positions().begin(), b.positions().end());
    for (int ti = 0; ti < b.num_triangles(); ++ti) {
        Triangle tb = b.triangle(ti);
        for (int& v : tb)
            v += offset;
        t.push_back(tb);
    }
    const SurfaceMesh both(x, t);
    const IntersectionReport r = find_self_intersections(both);
    EXPECT_FALSE(r.intersection_free());
    EXPECT_FALSE(r.edge_triangle_pairs.empty());
    EXPECT_FALSE(is_intersection_free(both));
    // Every reported pair mixes the two spheres.
    for (const TrianglePair& p : r.triangle_pairs)
        EXPECT_NE(p.ti < a.num_triangles(), p.tj < a.num_triangles());
    // Moving b away removes every intersection.
    std::vector<Vec3> apart = both.positions();
    for (size_t i = static_cast<size_t>(offset); i < apart.size(); ++i)
        apart[i].x() += 0.2;
    EXPECT_TRUE(is_intersection_free(both, &apart));
}

TEST(MeshIntersections, FoldedNeighbourCounts) {
    // Two triangles on a shared edge folded flat onto each other intersect.
    const SurfaceMesh m({{0, 0, 0}, {1, 0, 0}, {0.3, 1, 0}, {0.6, 1, 0}}, {{0, 1, 2}, {1, 0, 3}});
    EXPECT_FALSE(is_intersection_free(m));
    const SurfaceMesh ok({{0, 0, 0}, {1, 0, 0}, {0.3, 1, 0}, {0.6, -1, 0}}, {{0, 1, 2}, {1, 0, 3}});
    EXPECT_TRUE(is_intersection_free(ok));
}

}  // namespace
}  // namespace meniscus::tracker
