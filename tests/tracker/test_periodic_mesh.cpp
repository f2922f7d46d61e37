// Periodic meshes (issue 39): the box a mesh wraps around and the minimum-image accessors.
#include "periodic_meshes.h"

#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_validate.h"

#include <gtest/gtest.h>

#include <cmath>

namespace meniscus::tracker {
namespace {

TEST(MeshPeriods, WrapAndNearestImage) {
    MeshPeriods p;
    p.origin = Vec3(-1.0, 0.0, 0.0);
    p.length = Vec3(2.0, 0.0, 0.5);
    const Vec3 w = p.wrap(Vec3(1.25, 7.0, -0.1));
    EXPECT_NEAR(w.x(), -0.75, 1e-15);
    EXPECT_EQ(w.y(), 7.0);  // y does not wrap
    EXPECT_NEAR(w.z(), 0.4, 1e-15);
    // The image of (0.9, ., 0.45) nearest (-0.9, ., 0.05) is one period lower on both axes.
    const Vec3 n = p.nearest_image(Vec3(0.9, 3.0, 0.45), Vec3(-0.9, 0.0, 0.05));
    EXPECT_NEAR(n.x(), -1.1, 1e-15);
    EXPECT_EQ(n.y(), 3.0);
    EXPECT_NEAR(n.z(), -0.05, 1e-15);
    EXPECT_NEAR(p.difference(Vec3(0.9, 0, 0.45), Vec3(-0.9, 0, 0.05)).norm(), std::hypot(0.2, 0.1),
                1e-15);
    // A point exactly on the upper face wraps to the origin's face.
    EXPECT_EQ(p.wrap(Vec3(1.0, 0.0, 0.5)).x(), -1.0);
    EXPECT_EQ(p.wrap(Vec3(1.0, 0.0, 0.5)).z(), 0.0);
}

TEST(MeshPeriods, ValidateNamesTheField) {
    MeshPeriods p;
    p.length.y() = -1.0;
    try {
        p.validate();
        FAIL() << "a negative period was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("periods/length/y"), std::string::npos) << e.what();
    }
}

TEST(PeriodicMesh, TubeIsClosedAndItsSeamElementsAreShort) {
    const double length = 1.0;
    SurfaceMesh mesh = testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 2, length, 16, 20);
    EXPECT_TRUE(mesh.periodic());
    EXPECT_TRUE(validate_mesh(mesh).empty());
    for (int e = 0; e < mesh.num_edges(); ++e)
        EXPECT_EQ(mesh.edge_triangles(e).size(), 2u);  // closed: no boundary edge
    // Every edge and triangle read by the minimum image is as short as the mesh spacing, those
    // across the seam included (their raw positions are a period apart).
    int seam_edges = 0;
    for (int e = 0; e < mesh.num_edges(); ++e) {
        const auto ends = mesh.edge_positions(e);
        EXPECT_LT((ends[1] - ends[0]).norm(), 0.1);
        if ((mesh.position(mesh.edge(e)[1]) - mesh.position(mesh.edge(e)[0])).norm() > 0.5)
            ++seam_edges;
    }
    EXPECT_EQ(seam_edges, 16 * 2);  // two edges per vertex of a ring join ring 19 to ring 0
    for (int t = 0; t < mesh.num_triangles(); ++t) {
        const auto c = mesh.triangle_positions(t);
        const Vec3 n = (c[1] - c[0]).cross(c[2] - c[0]);
        const Vec3 mid = (c[0] + c[1] + c[2]) / 3.0;
        Vec3 radial = mid - Vec3(0.5, 0.5, mid.z());
        EXPECT_GT(n.dot(radial), 0.0) << "triangle " << t << " points into the column";
    }
}

TEST(PeriodicMesh, WrapPositionsAfterAMotionAcrossTheSeam) {
    SurfaceMesh mesh = testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 2, 1.0, 12, 10);
    std::vector<Vec3> moved = mesh.positions();
    for (Vec3& p : moved)
        p.z() += 0.37;
    mesh.set_positions(moved);
    mesh.wrap_positions();
    for (int v = 0; v < mesh.num_vertices(); ++v) {
        EXPECT_GE(mesh.position(v).z(), 0.0);
        EXPECT_LT(mesh.position(v).z(), 1.0);
    }
    for (int e = 0; e < mesh.num_edges(); ++e) {
        const auto ends = mesh.edge_positions(e);
        EXPECT_LT((ends[1] - ends[0]).norm(), 0.2);
    }
}

TEST(PeriodicMesh, CopiesKeepThePeriods) {
    SurfaceMesh mesh = testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 2, 1.0, 12, 10);
    SurfaceMesh copy = mesh;
    EXPECT_EQ(copy.periods(), mesh.periods());
    EXPECT_TRUE(copy.periodic());
}

/// A Rayleigh–Plateau column meshed on a lattice periodic along x: the mesh is a closed tube
/// (a torus of the periodic box: χ = 0), every vertex on the perturbed radius, every element
/// short by the minimum image, the vertices in the box.
TEST(PeriodicMesh, ImplicitMesherClosesAColumnAcrossTheBox) {
    const double length = 2.0, radius = 0.25, wavelength = 1.0, amplitude = 0.05, h = 0.06;
    ShapePtr column = make_perturbed_cylinder(Vec3(1.0, 0.5, 0.5), Vec3::UnitX(), radius, 3.0,
                                              amplitude, wavelength);
    ImplicitMeshOptions options;
    options.edge_length = h;
    options.periods.length.x() = length;
    const SurfaceMesh mesh = mesh_implicit_shape(*column, options);
    ASSERT_TRUE(mesh.periodic());
    EXPECT_TRUE(validate_mesh(mesh).empty());
    int edges = 0, triangles = 0, vertices = 0;
    double longest = 0.0, worst_radius = 0.0;
    for (int e = 0; e < mesh.num_edges(); ++e) {
        if (!mesh.edge_alive(e))
            continue;
        ++edges;
        EXPECT_EQ(mesh.edge_triangles(e).size(), 2u);
        const auto ends = mesh.edge_positions(e);
        longest = std::max(longest, (ends[1] - ends[0]).norm());
    }
    for (int t = 0; t < mesh.num_triangles(); ++t)
        triangles += mesh.triangle_alive(t) ? 1 : 0;
    for (int v = 0; v < mesh.num_vertices(); ++v) {
        if (!mesh.vertex_alive(v))
            continue;
        ++vertices;
        const Vec3& p = mesh.position(v);
        EXPECT_GE(p.x(), 0.0);
        EXPECT_LT(p.x(), length);
        const double r = std::hypot(p.y() - 0.5, p.z() - 0.5);
        // The shape is centred at x = 1, so its cosine has a crest at x = 0 and x = 1.
        const double expected = radius * (1.0 + amplitude * std::cos(2.0 * M_PI * (p.x() - 1.0)));
        worst_radius = std::max(worst_radius, std::abs(r - expected));
    }
    EXPECT_EQ(vertices - edges + triangles, 0) << "a closed tube around a periodic axis is a torus";
    EXPECT_LT(longest, 2.0 * h);
    EXPECT_LT(worst_radius, 1e-3 * radius);
    // Vertices lie on both sides of the seam: the tube was not cut there.
    int near_low = 0, near_high = 0;
    for (int v = 0; v < mesh.num_vertices(); ++v) {
        near_low += mesh.position(v).x() < h ? 1 : 0;
        near_high += mesh.position(v).x() > length - h ? 1 : 0;
    }
    EXPECT_GT(near_low, 0);
    EXPECT_GT(near_high, 0);
}

TEST(PeriodicMesh, ImplicitMesherRefusesAShapeThatIsNotPeriodic) {
    // A sphere inside the box touches neither face: fine. A column that is not periodic (its
    // wavelength does not divide the period) is refused, naming the axis.
    ImplicitMeshOptions options;
    options.edge_length = 0.05;
    options.periods.length.x() = 1.0;
    EXPECT_NO_THROW(mesh_implicit_shape(*make_sphere(Vec3(0.5, 0.5, 0.5), 0.2), options));
    ShapePtr cone = make_perturbed_cylinder(Vec3(0.3, 0.5, 0.5), Vec3::UnitX(), 0.2, 3.0, 0.5, 0.7);
    try {
        mesh_implicit_shape(*cone, options);
        FAIL() << "a shape that does not repeat along x was meshed as periodic";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("not periodic along x"), std::string::npos)
            << e.what();
    }
    options.periods.length.x() = 0.3;  // 6 edges: too short a period
    EXPECT_THROW(mesh_implicit_shape(*make_sphere(Vec3(0.5, 0.5, 0.5), 0.1), options),
                 std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::tracker
