// Periodic meshes (issue 39): the box a mesh wraps around and the minimum-image accessors.
#include "periodic_meshes.h"

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
    EXPECT_NEAR(p.difference(Vec3(0.9, 0, 0.45), Vec3(-0.9, 0, 0.05)).norm(),
                std::hypot(0.2, 0.1), 1e-15);
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

TEST(PeriodicMesh, CopiesKeepThePeriodsAndLoadStateKeepsTheTargets) {
    SurfaceMesh mesh = testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 2, 1.0, 12, 10);
    SurfaceMesh copy = mesh;
    EXPECT_EQ(copy.periods(), mesh.periods());
    EXPECT_TRUE(copy.periodic());
}

}  // namespace
}  // namespace meniscus::tracker
