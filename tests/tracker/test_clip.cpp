// Cutting the mesh with a plane (topology/clip.h) and the polygon triangulation that closes the
// cut (polygon_triangulation.h): the result is closed, intersection-free and on the near side,
// and the volume removed is the volume lost, exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_intersections.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"
#include "tracker/polygon_triangulation.h"
#include "tracker/topology/clip.h"

namespace meniscus::tracker {
namespace {

using Vec2 = Eigen::Vector2d;

double triangle_area(const std::vector<Vec2>& p, const std::array<int, 3>& t) {
    const Vec2 a = p[static_cast<size_t>(t[1])] - p[static_cast<size_t>(t[0])];
    const Vec2 b = p[static_cast<size_t>(t[2])] - p[static_cast<size_t>(t[0])];
    return 0.5 * (a.x() * b.y() - a.y() * b.x());
}

/// A loop of n points on a wobbly circle (a star-shaped, non-convex polygon), appended to `p`.
std::vector<int> wobbly_loop(std::vector<Vec2>& p, const Vec2& centre, double radius, int n,
                             double wobble, bool clockwise, std::mt19937& rng) {
    std::uniform_real_distribution<double> jitter(-wobble, wobble);
    std::vector<int> loop;
    for (int i = 0; i < n; ++i) {
        const double angle = 2.0 * M_PI * (clockwise ? -i : i) / n;
        const double r = radius * (1.0 + jitter(rng) + 0.3 * (i % 2));
        loop.push_back(static_cast<int>(p.size()));
        p.push_back(centre + r * Vec2(std::cos(angle), std::sin(angle)));
    }
    return loop;
}

TEST(PolygonTriangulation, SquareWithASquareHole) {
    const std::vector<Vec2> p = {{0, 0}, {4, 0}, {4, 4}, {0, 4}, {1, 1}, {1, 3}, {3, 3}, {3, 1}};
    PolygonWithHoles polygon{{0, 1, 2, 3}, {{4, 5, 6, 7}}};
    const PolygonTriangulation t = triangulate_polygon(p, polygon);
    ASSERT_TRUE(t.ok) << t.failure;
    EXPECT_EQ(t.triangles.size(), 8u);  // n − 2 + 2 · holes
    double area = 0.0;
    for (const auto& tri : t.triangles) {
        EXPECT_GT(triangle_area(p, tri), 0.0);
        area += triangle_area(p, tri);
    }
    EXPECT_DOUBLE_EQ(area, 16.0 - 4.0);
}

TEST(PolygonTriangulation, NonConvexPolygonsWithHolesAreCoveredExactly) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 20; ++trial) {
        std::vector<Vec2> p;
        PolygonWithHoles polygon;
        polygon.outer = wobbly_loop(p, {0, 0}, 10.0, 60, 0.1, false, rng);
        polygon.holes.push_back(wobbly_loop(p, {-3.5, 0.5}, 1.5, 17, 0.1, true, rng));
        polygon.holes.push_back(wobbly_loop(p, {3.0, -1.0}, 1.8, 23, 0.1, true, rng));
        polygon.holes.push_back(wobbly_loop(p, {0.2, 4.0}, 1.0, 9, 0.1, true, rng));
        const PolygonTriangulation t = triangulate_polygon(p, polygon);
        ASSERT_TRUE(t.ok) << t.failure;
        EXPECT_EQ(t.triangles.size(), 60u + 17u + 23u + 9u - 2u + 6u);
        double area = 0.0;
        for (const auto& tri : t.triangles) {
            ASSERT_GT(triangle_area(p, tri), 0.0);
            area += triangle_area(p, tri);
            // Every triangle inside the polygon: its centroid inside the outer loop, outside holes.
            const Vec2 centroid = (p[static_cast<size_t>(tri[0])] + p[static_cast<size_t>(tri[1])] +
                                   p[static_cast<size_t>(tri[2])]) /
                                  3.0;
            EXPECT_TRUE(point_in_loop(p, polygon.outer, centroid));
            for (const std::vector<int>& hole : polygon.holes)
                EXPECT_FALSE(point_in_loop(p, hole, centroid));
        }
        double expected = loop_signed_area(p, polygon.outer);
        for (const std::vector<int>& hole : polygon.holes)
            expected += loop_signed_area(p, hole);
        EXPECT_NEAR(area, expected, 1e-9 * expected);
    }
}

TEST(PolygonTriangulation, RefusesLoopsOfTheWrongOrientation) {
    const std::vector<Vec2> p = {{0, 0}, {4, 0}, {4, 4}, {0, 4}, {1, 1}, {3, 1}, {3, 3}, {1, 3}};
    EXPECT_FALSE(triangulate_polygon(p, {{3, 2, 1, 0}, {}}).ok);  // clockwise outer loop
    EXPECT_FALSE(
        triangulate_polygon(p, {{0, 1, 2, 3}, {{4, 5, 6, 7}}}).ok);  // counter-clockwise hole
}

/// The plane across `axis` removing `side` (1: x > cut) with the cut in [near, far].
ClipPlane plane_at(int axis, int side, double near, double far) {
    ClipPlane plane;
    plane.axis = axis;
    plane.side = side;
    plane.near = near;
    plane.far = far;
    return plane;
}

SurfaceMesh mesh_of(const ShapePtr& shape, double edge) {
    ImplicitMeshOptions options;
    options.edge_length = edge;
    return mesh_implicit_shape(*shape, options);
}

/// The checks every clip must pass: a closed, valid, intersection-free mesh on the near side,
/// whose volume went down by exactly the volume the report removed.
void expect_clean_clip(SurfaceMesh& mesh, const ClipPlane& plane, int expected_components,
                       ClipReport* report = nullptr) {
    const double before = enclosed_volume(mesh);
    const ClipReport r = clip_mesh(mesh, plane);
    if (report)
        *report = r;
    ASSERT_TRUE(r.clipped) << r.deferred;
    EXPECT_TRUE(r.deferred.empty());
    EXPECT_TRUE(validate_mesh(mesh).empty()) << to_string(validate_mesh(mesh).front().kind) << ": "
                                             << validate_mesh(mesh).front().message;
    EXPECT_TRUE(is_intersection_free(mesh));
    const double dir = plane.side == 1 ? 1.0 : -1.0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (mesh.vertex_alive(vi)) {
            EXPECT_LE(dir * mesh.position(vi)[plane.axis], dir * r.position);
        }
    }
    double removed = 0.0;
    for (const ClippedComponent& c : r.components)
        removed += c.removed_volume;
    EXPECT_NEAR(enclosed_volume(mesh), before - removed, 1e-12 * std::abs(before));
    EXPECT_EQ(triangle_components(mesh).count, expected_components);
}

TEST(ClipMesh, SphereLosesItsCapAndIsClosedByADisc) {
    SurfaceMesh mesh = mesh_of(make_sphere({0, 0, 0}, 1.0), 0.1);
    const double before = enclosed_volume(mesh);
    ClipPlane plane = plane_at(0, 1, 0.45, 0.55);
    ClipReport r;
    expect_clean_clip(mesh, plane, 1, &r);
    // The removed cap of height h = 1 − x: π h² (3 − h) / 3, to the mesh's resolution.
    const double h = 1.0 - r.position;
    EXPECT_NEAR(before - enclosed_volume(mesh), M_PI * h * h * (3.0 - h) / 3.0, 0.01);
    EXPECT_EQ(euler_characteristic(mesh), 2);
}

TEST(ClipMesh, NothingBeyondTheRangeChangesNothing) {
    SurfaceMesh mesh = mesh_of(make_sphere({0, 0, 0}, 1.0), 0.2);
    const int triangles = mesh.count_live_triangles();
    ClipPlane plane = plane_at(2, 1, 1.1, 1.3);
    const ClipReport r = clip_mesh(mesh, plane);
    EXPECT_FALSE(r.clipped);
    EXPECT_TRUE(r.deferred.empty());
    EXPECT_EQ(mesh.count_live_triangles(), triangles);
}

TEST(ClipMesh, AComponentWhollyBeyondIsRemovedWithItsVolume) {
    SurfaceMesh mesh =
        mesh_of(make_union({make_sphere({0, 0, 0}, 0.5), make_sphere({2, 0, 0}, 0.3)}), 0.08);
    const std::vector<double> volumes = component_volumes(mesh, triangle_components(mesh));
    ClipPlane plane = plane_at(0, 1, 1.0, 1.5);
    const ClipReport r = clip_mesh(mesh, plane);
    ASSERT_TRUE(r.clipped);
    EXPECT_EQ(r.components_removed, 1);
    ASSERT_EQ(r.components.size(), 1u);
    EXPECT_EQ(r.components[0].kept_vertex, INVALID_INDEX);
    EXPECT_EQ(r.cap_triangles, 0);
    const double small = std::min(volumes[0], volumes[1]);
    EXPECT_NEAR(r.components[0].removed_volume, small, 1e-14);
    EXPECT_EQ(triangle_components(mesh).count, 1);
}

TEST(ClipMesh, ComponentsWhollyBeyondGoneGoWholeWhereverTheCutFalls) {
    // Three drops: one wholly past `gone` but short of the cut's range (goes whole), one across
    // `gone` and short of the range (stays as it is), one far inside (stays).
    SurfaceMesh mesh =
        mesh_of(make_union({make_sphere({1.3, 0, 0}, 0.2), make_sphere({1.0, 1, 0}, 0.2),
                            make_sphere({0, 0, 0}, 0.3)}),
                0.05);
    const std::vector<double> volumes = component_volumes(mesh, triangle_components(mesh));
    const int triangles = mesh.count_live_triangles();
    ClipPlane plane = plane_at(0, 1, 1.6, 1.8);
    plane.gone = 1.05;
    const ClipReport r = clip_mesh(mesh, plane);
    ASSERT_TRUE(r.clipped) << r.deferred;
    EXPECT_EQ(r.components_removed, 1);
    EXPECT_EQ(r.edges_split, 0);
    EXPECT_EQ(r.cap_triangles, 0);
    ASSERT_EQ(r.components.size(), 1u);
    EXPECT_NEAR(r.components[0].removed_volume, *std::min_element(volumes.begin(), volumes.end()),
                1e-12);
    EXPECT_EQ(triangle_components(mesh).count, 2);
    EXPECT_LT(mesh.count_live_triangles(), triangles);
    EXPECT_TRUE(validate_mesh(mesh).empty());
    plane.gone = std::numeric_limits<double>::infinity();
    EXPECT_THROW(plane.validate(), std::invalid_argument);
}

/// The four outward-facing triangles of the tetrahedron (p[i], p[j], p[k], p[l]).
std::vector<Triangle> tetrahedron(const std::vector<Vec3>& p, int i, int j, int k, int l) {
    const bool outward = (p[static_cast<size_t>(j)] - p[static_cast<size_t>(i)])
                             .cross(p[static_cast<size_t>(k)] - p[static_cast<size_t>(i)])
                             .dot(p[static_cast<size_t>(l)] - p[static_cast<size_t>(i)]) < 0.0;
    if (!outward)
        std::swap(j, k);
    return {{i, j, k}, {i, l, j}, {j, l, k}, {i, k, l}};
}

TEST(ClipMesh, AnEdgeWithFourTrianglesMovesTheCutElsewhere) {
    // Two tetrahedra touching along the edge from x = 0.3 to 0.7 (four triangles on it, as two
    // sheets mid-merge). In the range [0.35, 0.9] the widest gap's middle, 0.525, would cut that
    // edge; the cut goes to the next gap's, 0.8, where only two-triangle edges cross.
    const std::vector<Vec3> p = {{0.3, 0, 0},   {0.7, 0, 0},  {1.0, 1, 0},
                                 {0.5, 0.5, 1}, {1.0, -1, 0}, {0.5, -0.5, -1}};
    std::vector<Triangle> triangles = tetrahedron(p, 0, 1, 2, 3);
    for (const Triangle& t : tetrahedron(p, 0, 1, 4, 5))
        triangles.push_back(t);
    SurfaceMesh mesh(p, triangles);
    ASSERT_EQ(mesh.edge_triangles(mesh.find_edge(0, 1)).size(), 4u);
    ASSERT_GT(enclosed_volume(mesh), 0.0);
    ClipPlane plane = plane_at(0, 1, 0.35, 0.9);
    const double before = enclosed_volume(mesh);
    const ClipReport r = clip_mesh(mesh, plane);
    ASSERT_TRUE(r.clipped) << r.deferred;
    EXPECT_DOUBLE_EQ(r.position, 0.8);
    EXPECT_EQ(r.edges_split, 6);
    EXPECT_EQ(r.cap_triangles, 2);
    EXPECT_EQ(mesh.edge_triangles(mesh.find_edge(0, 1)).size(), 4u);  // untouched
    EXPECT_TRUE(validate_mesh(mesh).empty());
    EXPECT_TRUE(is_intersection_free(mesh));
    double removed = 0.0;
    for (const ClippedComponent& c : r.components)
        removed += c.removed_volume;
    EXPECT_NEAR(enclosed_volume(mesh), before - removed, 1e-14);
    // Where every position crosses that edge (all of the range and beyond lies along it), the
    // mesh is left as it was and the report says why.
    SurfaceMesh again(p, triangles);
    plane.near = 0.32;
    plane.far = 0.34;  // beyond: up to 0.38, still along the edge
    const ClipReport refused = clip_mesh(again, plane);
    EXPECT_FALSE(refused.clipped);
    EXPECT_EQ(refused.deferred, "an edge crossing the plane has 4 triangles");
    EXPECT_EQ(enclosed_volume(again), before);
}

TEST(ClipMesh, TorusCutAcrossItsHoleGetsAnAnnulus) {
    // Axis along x: the plane x = c (through the ring's centre circle) meets the torus in two
    // concentric circles; the cap is the annulus between them (the inner loop a hole of the
    // outer one), and what is left is still a ring.
    SurfaceMesh mesh = mesh_of(make_torus({0, 0, 0}, {1, 0, 0}, 1.0, 0.4), 0.08);
    ClipPlane plane = plane_at(0, 0, 0.05, -0.05);  // remove x < cut
    expect_clean_clip(mesh, plane, 1);
    EXPECT_EQ(euler_characteristic(mesh), 0);  // the half of the tube on x > c, still a ring
}

TEST(ClipMesh, TorusCutThroughBothArmsGetsTwoDiscs) {
    SurfaceMesh mesh = mesh_of(make_torus({0, 0, 0}, {0, 0, 1}, 1.0, 0.4), 0.08);
    ClipPlane plane = plane_at(1, 1, -0.1, 0.1);
    expect_clean_clip(mesh, plane, 1);
    EXPECT_EQ(euler_characteristic(mesh), 2);  // a bent tube capped at both ends
}

TEST(ClipMesh, ShellCutOpenBecomesACup) {
    // A drop with a bubble inside (outer sphere outward, inner sphere inward): the cut through
    // both is capped by an annulus that joins them into one closed cup.
    SurfaceMesh mesh =
        mesh_of(make_difference(make_sphere({0, 0, 0}, 1.0), make_sphere({0, 0, 0}, 0.6)), 0.08);
    ASSERT_EQ(triangle_components(mesh).count, 2);
    ClipPlane plane = plane_at(2, 1, 0.1, 0.2);
    expect_clean_clip(mesh, plane, 1);
    EXPECT_EQ(euler_characteristic(mesh), 2);
}

TEST(ClipMesh, InvertedBubbleIsCappedWithItsOwnOrientation) {
    // A bubble whose triangles face into the gas (enclosed volume negative): the loop runs the
    // other way round and the cap faces the other way.
    SurfaceMesh mesh = mesh_of(make_sphere({0, 0, 0}, 1.0), 0.1);
    const int triangles = mesh.num_triangles();
    for (int ti = 0; ti < triangles; ++ti) {
        Triangle t = mesh.triangle(ti);
        std::swap(t[1], t[2]);
        mesh.remove_triangle(ti);
        mesh.add_triangle(t, {0, 1});
    }
    mesh.compact();
    ASSERT_LT(enclosed_volume(mesh), 0.0);
    ClipPlane plane = plane_at(1, 1, -0.2, 0.0);
    expect_clean_clip(mesh, plane, 1);
    EXPECT_LT(enclosed_volume(mesh), 0.0);
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (mesh.triangle_alive(ti)) {
            EXPECT_EQ(mesh.labels(ti), (LabelPair{0, 1}));
        }
    }
}

TEST(ClipMesh, RepeatedCutsEatADropSliceBySlice) {
    SurfaceMesh mesh = mesh_of(make_sphere({0, 0, 0}, 1.0), 0.1);
    const double start = enclosed_volume(mesh);
    double removed = 0.0;
    for (int slice = 0; slice < 12; ++slice) {
        const ClipPlane plane = plane_at(0, 1, 0.9 - 0.2 * slice, 0.95 - 0.2 * slice);
        const ClipReport r = clip_mesh(mesh, plane);
        ASSERT_TRUE(r.deferred.empty()) << r.deferred;
        for (const ClippedComponent& c : r.components)
            removed += c.removed_volume;
        ASSERT_TRUE(validate_mesh(mesh).empty()) << "slice " << slice;
        ASSERT_TRUE(is_intersection_free(mesh)) << "slice " << slice;
        mesh.compact();
    }
    EXPECT_EQ(mesh.count_live_triangles(), 0);
    EXPECT_NEAR(removed, start, 1e-12 * start);
}

TEST(ClipPlane, ValidateNamesTheField) {
    ClipPlane plane;
    plane.near = plane.far = 1.0;
    EXPECT_THROW(plane.validate(), std::invalid_argument);
    plane.far = 2.0;
    plane.axis = 3;
    EXPECT_THROW(plane.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::tracker
