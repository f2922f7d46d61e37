/// Curvature-adaptive sizing (remesh/sizing.h): the curvature estimate is 1/r on round
/// surfaces, the scale factor obeys its clamp, and split/collapse with it refine a thin handle
/// without the collapses undoing the splits. Added with the A2 dumbbell work (issue #5), where
/// a neck only a few edges around pinched late.

#include "remesh_test_meshes.h"

#include "tracker/mesh_intersections.h"
#include "tracker/mesh_validate.h"
#include "tracker/remesh/improve.h"
#include "tracker/remesh/sizing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace meniscus::tracker {
namespace {

constexpr double PI = 3.14159265358979323846;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

std::vector<double> live_values(const SurfaceMesh& mesh, const std::vector<double>& per_vertex) {
    std::vector<double> out;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            out.push_back(per_vertex[static_cast<size_t>(vi)]);
    return out;
}

TEST(RemeshSizing, TurningCurvatureIsTheInverseRadiusOnASphereAndATorusTube) {
    const SurfaceMesh sphere = testing::make_test_sphere();  // r = 0.25
    const std::vector<double> ks = live_values(sphere, vertex_turning_curvature(sphere));
    EXPECT_NEAR(median(ks), 1.0 / 0.25, 0.05 / 0.25);
    EXPECT_GT(*std::min_element(ks.begin(), ks.end()), 0.8 / 0.25);
    EXPECT_LT(*std::max_element(ks.begin(), ks.end()), 1.3 / 0.25);
    // The tube (radius 0.12) bends more than the ring (0.3 ± 0.12), and the estimate takes
    // the largest turning.
    const SurfaceMesh torus = testing::make_test_torus();
    const std::vector<double> kt = live_values(torus, vertex_turning_curvature(torus));
    EXPECT_NEAR(median(kt), 1.0 / 0.12, 0.1 / 0.12);
}

TEST(RemeshSizing, ScaleIsOneWhenOffAndClampedBetweenTheFloorAndOneWhenOn) {
    const SurfaceMesh torus = testing::make_test_torus();
    const double xi = testing::mean_edge_length(torus);
    RemeshOptions options;
    const EdgeSizing off(torus, options, xi);
    EXPECT_FALSE(off.adaptive());
    const RemeshLimits limits = remesh_limits(options, xi);
    for (int ei = 0; ei < torus.num_edges(); ++ei) {
        const Edge& e = torus.edge(ei);
        ASSERT_EQ(off.scale(e[0], e[1]), 1.0);
        ASSERT_EQ(off.max_length(e[0], e[1]), limits.max_edge_length);
    }

    // κα ≈ (1/0.12)·1.5ξ ≈ 0.9 on the tube: c = 0.45 halves α and β there.
    options.curvature_edge_fraction = 0.45;
    options.split_on_fitted_surface = true;
    const EdgeSizing on(torus, options, xi);
    EXPECT_TRUE(on.adaptive());
    std::vector<double> scales;
    for (int ei = 0; ei < torus.num_edges(); ++ei) {
        const Edge& e = torus.edge(ei);
        const double s = on.scale(e[0], e[1]);
        ASSERT_GE(s, options.min_curvature_size_fraction);
        ASSERT_LE(s, 1.0);
        ASSERT_NEAR(on.min_length(e[0], e[1]) / on.max_length(e[0], e[1]),
                    options.min_edge_fraction / options.max_edge_fraction, 1e-12);
        scales.push_back(s);
    }
    const double expected = 0.45 / ((1.0 / 0.12) * limits.max_edge_length);
    EXPECT_NEAR(median(scales), expected, 0.15 * expected);
    // Vertices created after the measurement get the nominal limits.
    EXPECT_EQ(on.scale(torus.num_vertices(), torus.num_vertices() + 1), 1.0);

    // A tiny c hits the floor everywhere.
    options.curvature_edge_fraction = 1e-3;
    options.min_curvature_size_fraction = 0.3;
    const EdgeSizing floored(torus, options, xi);
    for (int ei = 0; ei < torus.num_edges(); ++ei) {
        const Edge& e = torus.edge(ei);
        ASSERT_EQ(floored.scale(e[0], e[1]), 0.3);
    }
}

TEST(RemeshSizing, InvalidOptionsNameTheField) {
    const SurfaceMesh sphere = testing::make_test_sphere();
    RemeshOptions options;
    options.curvature_edge_fraction = -0.1;
    try {
        EdgeSizing(sphere, options, 0.06);
        FAIL() << "no throw";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("curvature_edge_fraction"), std::string::npos);
    }
    options.curvature_edge_fraction = 0.5;
    EXPECT_THROW(EdgeSizing(sphere, options, 0.06), std::invalid_argument)
        << "curvature sizing without fitted split points";
    options.split_on_fitted_surface = true;
    options.min_curvature_size_fraction = 0.0;
    try {
        EdgeSizing(sphere, options, 0.06);
        FAIL() << "no throw";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("min_curvature_size_fraction"), std::string::npos);
    }
    options.min_curvature_size_fraction = 0.25;
    EXPECT_THROW(EdgeSizing(sphere, options, 0.0), std::invalid_argument);
}

/// Edges of the handle (|x| < 0.04, well inside the blends) crossing the plane x = 0.
int edges_around_handle(const SurfaceMesh& mesh) {
    int n = 0;
    for (int ei = 0; ei < mesh.num_edges(); ++ei) {
        if (!mesh.edge_alive(ei))
            continue;
        const Edge& e = mesh.edge(ei);
        const Vec3& a = mesh.position(e[0]);
        const Vec3& b = mesh.position(e[1]);
        if ((a.x() < 0.0) != (b.x() < 0.0) && std::abs(a.x()) < 0.04 && std::abs(b.x()) < 0.04)
            ++n;
    }
    return n;
}

double longest_handle_edge(const SurfaceMesh& mesh) {
    double longest = 0.0;
    for (int ei = 0; ei < mesh.num_edges(); ++ei) {
        if (!mesh.edge_alive(ei))
            continue;
        const Edge& e = mesh.edge(ei);
        if (std::abs(mesh.position(e[0]).x()) < 0.04 && std::abs(mesh.position(e[1]).x()) < 0.04)
            longest = std::max(longest, (mesh.position(e[0]) - mesh.position(e[1])).norm());
    }
    return longest;
}

TEST(RemeshSizing, ImprovementRefinesAThinHandleAndSettles) {
    // Handle radius 0.08 at ξ ≈ 0.05: about ten edges around. c = 0.3 asks for edges no
    // longer than 0.3 · 0.08, about 2π/0.3 ≈ 21 around.
    SurfaceMesh mesh = testing::make_test_dumbbell();
    const double xi = testing::mean_edge_length(mesh);
    const int before = edges_around_handle(mesh);
    RemeshOptions options;
    options.curvature_edge_fraction = 0.3;
    options.min_curvature_size_fraction = 0.1;
    options.split_on_fitted_surface = true;
    ImproveContext context;
    context.xi = xi;
    context.allow_topology_changes = false;

    int changes = 0;
    for (int k = 0; k < 8; ++k) {
        const ImproveReport r = improve_mesh(mesh, options, context);
        changes = r.split.splits + r.collapse.collapses;
    }
    // Settled: the sizing does not keep splitting what it collapses (or the reverse).
    EXPECT_LE(changes, mesh.count_live_triangles() / 100);
    const int refined = edges_around_handle(mesh);
    // A triangulated tube cut by a plane crosses two edges per triangle of the ring.
    EXPECT_GE(refined, 2 * static_cast<int>(2.0 * PI / 0.3)) << "before: " << before;
    EXPECT_LT(longest_handle_edge(mesh), 1.3 * 0.3 * 0.08);
    EXPECT_TRUE(validate_mesh(mesh).empty());
    EXPECT_TRUE(is_intersection_free(mesh));

    // Uniform sizing takes the refinement back out.
    RemeshOptions uniform;
    uniform.split_on_fitted_surface = true;
    for (int k = 0; k < 8; ++k)
        improve_mesh(mesh, uniform, context);
    EXPECT_LT(edges_around_handle(mesh), refined / 2);
    EXPECT_GT(longest_handle_edge(mesh), 0.5 * xi);
}

}  // namespace
}  // namespace meniscus::tracker
