// A periodic mesh unrolled into its images around the box, and cut at the box's faces (issue 39).
#include "coupling/periodic_images.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace meniscus::coupling {
namespace {

using tracker::Vec3;

/// A column along x through a box periodic along x (period 1), meshed periodic.
tracker::SurfaceMesh periodic_column() {
    tracker::ImplicitMeshOptions options;
    options.edge_length = 0.05;
    options.periods.length.x() = 1.0;
    return tracker::mesh_implicit_shape(
        *tracker::make_cylinder(Vec3(0.5, 0.5, 0.5), Vec3::UnitX(), 0.2, 3.0), options);
}

/// Directed edges used once without their reverse (the open rim).
std::vector<std::pair<int, int>> rim_edges(const tracker::SurfaceMesh& mesh) {
    std::map<std::pair<int, int>, int> directed;
    for (int t = 0; t < mesh.num_triangles(); ++t)
        if (mesh.triangle_alive(t))
            for (int k = 0; k < 3; ++k)
                ++directed[{mesh.triangle(t)[k], mesh.triangle(t)[(k + 1) % 3]}];
    std::vector<std::pair<int, int>> rim;
    for (const auto& [e, n] : directed)
        if (!directed.count({e.second, e.first}))
            rim.push_back(e);
    return rim;
}

TEST(PeriodicImages, UnrolledColumnReachesPastTheFacesByTheMargin) {
    const tracker::SurfaceMesh column = periodic_column();
    const double margin = 0.2;
    const UnrolledMesh unrolled = unroll_periodic_mesh(column, margin);
    EXPECT_FALSE(unrolled.mesh.periodic());
    double lo = 1e9, hi = -1e9;
    for (int v = 0; v < unrolled.mesh.num_vertices(); ++v) {
        lo = std::min(lo, unrolled.mesh.position(v).x());
        hi = std::max(hi, unrolled.mesh.position(v).x());
        // Each vertex is an image of its source: the same point but for whole periods along x.
        const Vec3 d = unrolled.mesh.position(v) -
                       column.position(unrolled.source_vertex[static_cast<size_t>(v)]);
        EXPECT_NEAR(d.y(), 0.0, 1e-15);
        EXPECT_NEAR(d.z(), 0.0, 1e-15);
        EXPECT_NEAR(d.x(), std::round(d.x()), 1e-12);
    }
    EXPECT_LT(lo, -margin + 0.06);
    EXPECT_GT(hi, 1.0 + margin - 0.06);
    // An open tube: the rim is only at the ends, beyond the margin.
    for (const auto& e : rim_edges(unrolled.mesh)) {
        const double x = unrolled.mesh.position(e.first).x();
        EXPECT_TRUE(x < -margin + 0.06 || x > 1.0 + margin - 0.06) << x;
    }
    // Its area is the periodic column's times the length it covers.
    EXPECT_GT(tracker::surface_area(unrolled.mesh), 1.3 * tracker::surface_area(column));
}

TEST(PeriodicImages, CutAtTheBoxGivesOneTileOpenExactlyAtTheFaces) {
    const tracker::SurfaceMesh column = periodic_column();
    const UnrolledMesh unrolled = unroll_periodic_mesh(column, 0.0);
    std::vector<Vec3> values(static_cast<size_t>(unrolled.mesh.num_vertices()));
    for (int v = 0; v < unrolled.mesh.num_vertices(); ++v)
        values[static_cast<size_t>(v)] = unrolled.mesh.position(v);  // a linear field
    const tracker::SurfaceMesh tile = cut_at_box(unrolled.mesh, column.periods(), &values);
    ASSERT_EQ(values.size(), static_cast<size_t>(tile.num_vertices()));
    for (int v = 0; v < tile.num_vertices(); ++v) {
        EXPECT_GE(tile.position(v).x(), 0.0);
        EXPECT_LE(tile.position(v).x(), 1.0);
        EXPECT_NEAR((values[static_cast<size_t>(v)] - tile.position(v)).norm(), 0.0, 1e-12);
    }
    // The tile has the periodic column's area exactly (it is the same surface, cut once around).
    EXPECT_NEAR(tracker::surface_area(tile), tracker::surface_area(column),
                1e-12 * tracker::surface_area(column));
    // Open only at the faces, and there along the whole circumference on both ends.
    double rim_length[2] = {0.0, 0.0};
    for (const auto& e : rim_edges(tile)) {
        const Vec3 a = tile.position(e.first), b = tile.position(e.second);
        ASSERT_TRUE((a.x() == 0.0 && b.x() == 0.0) || (a.x() == 1.0 && b.x() == 1.0))
            << a.transpose() << " " << b.transpose();
        rim_length[a.x() == 0.0 ? 0 : 1] += (b - a).norm();
    }
    for (double l : rim_length)
        EXPECT_NEAR(l, 2.0 * M_PI * 0.2, 0.02);
    // Not periodic: nothing to cut.
    const tracker::SurfaceMesh plain =
        cut_at_box(tracker::SurfaceMesh({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, {{0, 1, 2}}),
                   tracker::MeshPeriods{});
    EXPECT_EQ(plain.num_triangles(), 1);
}

}  // namespace
}  // namespace meniscus::coupling
