#include "tracker/volume_constraint.h"
#include "tracker/implicit_mesher.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace meniscus::tracker {
namespace {

SurfaceMesh sphere_mesh(const Vec3& center, double radius, double h) {
    ImplicitMeshOptions o;
    o.edge_length = h;
    return mesh_implicit_shape(*make_sphere(center, radius), o);
}

// The displacements change a closed component's volume by the asked amount to first order (the
// rest is second order in their size), leave the vertices that may not move alone, and are the
// smallest that do so: proportional to ∂V/∂x_v, here the sphere's outward normals.
TEST(VolumeConstraint, RestoringDisplacementsChangeTheVolumeByTheErrorThroughMovableVertices) {
    const SurfaceMesh m = sphere_mesh({0.1, -0.2, 0.3}, 0.25, 0.04);
    const VolumeComponents c = volume_components(m);
    ASSERT_EQ(c.count, 1);
    ASSERT_TRUE(c.closed[0]);
    const size_t n = static_cast<size_t>(m.num_vertices());
    std::vector<std::uint8_t> movable(n, 1);
    for (size_t v = 0; v < n; v += 3)
        movable[v] = 0;  // a third of the vertices held
    const std::vector<double> inv_mass(n, 1.0);
    const double volume = component_volumes_at(m, c, m.positions())[0];
    EXPECT_NEAR(volume, enclosed_volume(m), 1e-14);
    for (double error : {1e-6, -1e-6, 1e-4}) {
        const std::vector<Vec3> d =
            volume_restoring_displacements(m, c, m.positions(), {error}, movable, inv_mass);
        std::vector<Vec3> x = m.positions();
        double largest = 0.0;
        for (size_t v = 0; v < n; ++v) {
            if (!movable[v])
                EXPECT_EQ(d[v], Vec3::Zero());
            else
                EXPECT_GT(d[v].dot(x[v] - Vec3(0.1, -0.2, 0.3)) * error, 0.0);
            largest = std::max(largest, d[v].norm());
            x[v] += d[v];
        }
        const double changed = component_volumes_at(m, c, x)[0] - volume;
        // Second order: the surface's area times the square of the displacement, at most.
        EXPECT_NEAR(changed, error, 4.0 * M_PI * 0.25 * 0.25 * largest * largest) << error;
    }
    EXPECT_THROW(volume_restoring_displacements(m, c, m.positions(), {}, movable, inv_mass),
                 std::invalid_argument);
}

// An open surface encloses no volume: its component is not closed and gets no displacement;
// a closed component in the same mesh is still corrected.
TEST(VolumeConstraint, OpenComponentsAreLeftAlone) {
    SurfaceMesh m = sphere_mesh({0, 0, 0}, 0.2, 0.05);
    const int offset = m.num_vertices();
    const int a = m.add_vertex({1, 0, 0});
    const int b = m.add_vertex({2, 0, 0});
    const int d = m.add_vertex({1, 1, 0});
    m.add_triangle({a, b, d});
    const VolumeComponents c = volume_components(m);
    ASSERT_EQ(c.count, 2);
    const int open = c.triangle_component[static_cast<size_t>(m.num_triangles() - 1)];
    EXPECT_FALSE(c.closed[static_cast<size_t>(open)]);
    EXPECT_TRUE(c.closed[static_cast<size_t>(1 - open)]);
    EXPECT_EQ(c.vertex_component[static_cast<size_t>(offset)], INVALID_INDEX);
    const size_t n = static_cast<size_t>(m.num_vertices());
    std::vector<double> errors(2, 1e-5);
    const std::vector<Vec3> delta = volume_restoring_displacements(
        m, c, m.positions(), errors, std::vector<std::uint8_t>(n, 1), std::vector<double>(n, 1.0));
    for (int v : {a, b, d})
        EXPECT_EQ(delta[static_cast<size_t>(v)], Vec3::Zero());
    EXPECT_GT(delta[0].norm(), 0.0);
}

}  // namespace
}  // namespace meniscus::tracker
