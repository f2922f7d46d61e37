/// Curvature-adaptive sizing (remesh/sizing.h): the curvature estimate is 1/r on round
/// surfaces, the scale factor obeys its clamp, and split/collapse with it refine a thin handle
/// without the collapses undoing the splits. Added with the A2 dumbbell work (issue #5), where
/// a neck only a few edges around pinched late. Thin-sheet sizing (the facing distance and the
/// sag bound) was added with the A4 curl-noise work, where the two discretized sides of sheets
/// thinner than their chord sag met and were held apart.

#include "remesh_test_meshes.h"

#include "tracker/mesh_intersections.h"
#include "tracker/mesh_measures.h"
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

/// The sphere with its triangles reversed: a spherical cavity, concave everywhere.
SurfaceMesh make_cavity() {
    const SurfaceMesh sphere = testing::make_test_sphere();
    std::vector<Triangle> triangles;
    for (int ti = 0; ti < sphere.num_triangles(); ++ti) {
        const Triangle& t = sphere.triangle(ti);
        triangles.push_back({t[0], t[2], t[1]});
    }
    return SurfaceMesh(sphere.positions(), triangles);
}

TEST(RemeshSizing, ConvexOnlyCurvatureIsZeroInACavityAndTheTubeCurvatureOnATorus) {
    const SurfaceMesh cavity = make_cavity();
    const std::vector<Vec3> normals = area_weighted_vertex_normals(cavity);
    const std::vector<double> magnitude = live_values(cavity, vertex_turning_curvature(cavity));
    const std::vector<double> convex =
        live_values(cavity, vertex_turning_curvature(cavity, normals, true));
    EXPECT_NEAR(median(magnitude), 1.0 / 0.25, 0.05 / 0.25);
    EXPECT_EQ(*std::max_element(convex.begin(), convex.end()), 0.0);

    const SurfaceMesh sphere = testing::make_test_sphere();
    const std::vector<double> ks = live_values(
        sphere, vertex_turning_curvature(sphere, area_weighted_vertex_normals(sphere), true));
    EXPECT_NEAR(median(ks), 1.0 / 0.25, 0.05 / 0.25);
    EXPECT_GT(*std::min_element(ks.begin(), ks.end()), 0.8 / 0.25);
    // The torus's tube bends convexly everywhere, its inner ring concavely: the tube wins.
    const SurfaceMesh torus = testing::make_test_torus();
    const std::vector<double> kt = live_values(
        torus, vertex_turning_curvature(torus, area_weighted_vertex_normals(torus), true));
    EXPECT_NEAR(median(kt), 1.0 / 0.12, 0.1 / 0.12);

    // Sizing: with a c that refines the cavity everywhere, convex_only leaves it nominal.
    const double xi = testing::mean_edge_length(cavity);
    RemeshOptions options;
    options.curvature_edge_fraction = 1e-3;
    options.split_on_fitted_surface = true;
    const EdgeSizing both(cavity, options, xi);
    options.curvature_sizing_convex_only = true;
    const EdgeSizing convex_sizing(cavity, options, xi);
    for (int ei = 0; ei < cavity.num_edges(); ++ei) {
        const Edge& e = cavity.edge(ei);
        ASSERT_EQ(both.scale(e[0], e[1]), options.min_curvature_size_fraction);
        ASSERT_EQ(convex_sizing.scale(e[0], e[1]), 1.0);
    }
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

/// A spherical shell: make_test_sphere (radius 0.25, ξ ≈ 0.06) and, inside it, a rotated
/// copy scaled to radius 0.25 − thickness with its orientation reversed (normals point into the
/// hollow), so the two sides face each other across a sheet with vertices that do not line up.
SurfaceMesh make_shell(double thickness) {
    const SurfaceMesh outer = testing::make_test_sphere();
    std::vector<Vec3> positions = outer.positions();
    std::vector<Triangle> triangles;
    for (int ti = 0; ti < outer.num_triangles(); ++ti)
        triangles.push_back(outer.triangle(ti));
    const int n = outer.num_vertices();
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(0.3, Vec3(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
    const double scale = (0.25 - thickness) / 0.25;
    for (int vi = 0; vi < n; ++vi)
        positions.push_back(scale * (rotation * outer.position(vi)));
    const int m = static_cast<int>(triangles.size());
    for (int k = 0; k < m; ++k) {
        const Triangle& t = triangles[static_cast<size_t>(k)];
        triangles.push_back({t[0] + n, t[2] + n, t[1] + n});
    }
    return SurfaceMesh(positions, triangles);
}

/// Thin-sheet sizing with sag at most a quarter of the thickness, down to s = 0.1.
RemeshOptions thin_sheet_options() {
    RemeshOptions options;
    options.thin_sheet_sag_fraction = 0.25;
    options.split_on_fitted_surface = true;
    options.min_curvature_size_fraction = 0.1;
    return options;
}

TEST(RemeshSizing, FacingDistanceIsTheSheetThicknessAndSkipsTheSameSide) {
    constexpr double THICKNESS = 0.004;
    const SurfaceMesh shell = make_shell(THICKNESS);
    const std::vector<Vec3> normals = area_weighted_vertex_normals(shell);
    const std::vector<double> radius(static_cast<size_t>(shell.num_vertices()), 0.05);
    const std::vector<double> h = vertex_facing_distance(shell, normals, radius);
    // Outer vertices lie on the outer sphere; the inner triangles lie inside the inner sphere
    // by at most their chord sag ℓ²/(8r) ≈ 0.06²/(8 · 0.246) ≈ 1.8e-3 (ℓ up to about 1.5ξ
    // would give 4e-3). Inner vertices see the outer triangles, whose chords come nearer.
    const int half = shell.num_vertices() / 2;
    for (int vi = 0; vi < shell.num_vertices(); ++vi) {
        const double d = h[static_cast<size_t>(vi)];
        ASSERT_TRUE(std::isfinite(d)) << vi;
        if (vi < half) {
            ASSERT_GE(d, THICKNESS - 1e-12) << vi;
            ASSERT_LE(d, THICKNESS + 4e-3) << vi;
        } else {
            ASSERT_LE(d, THICKNESS + 1e-12) << vi;
            ASSERT_GE(d, 0.0) << vi;
        }
    }
    // On a lone sphere nothing within the radius faces a vertex (the far side is 0.5 away),
    // and a radius of 0 skips the vertex.
    const SurfaceMesh sphere = testing::make_test_sphere();
    const std::vector<double> lone = vertex_facing_distance(
        sphere, area_weighted_vertex_normals(sphere),
        std::vector<double>(static_cast<size_t>(sphere.num_vertices()), 0.1));
    for (double d : lone)
        ASSERT_TRUE(std::isinf(d));
    const std::vector<double> skipped = vertex_facing_distance(
        shell, normals, std::vector<double>(static_cast<size_t>(shell.num_vertices()), 0.0));
    for (double d : skipped)
        ASSERT_TRUE(std::isinf(d));
}

TEST(RemeshSizing, ThinSheetSizingKeepsTheChordSagBelowAFractionOfTheThickness) {
    constexpr double THICKNESS = 0.004;
    const SurfaceMesh shell = make_shell(THICKNESS);
    const double xi = testing::mean_edge_length(shell);
    RemeshOptions options = thin_sheet_options();
    const EdgeSizing sizing(shell, options, xi);
    ASSERT_TRUE(sizing.adaptive());
    const double alpha = sizing.limits().max_edge_length;
    // s = sqrt(8 f h / κ) / α with κ ≈ 1/0.25 and h between the thickness and the thickness
    // plus the inner chord sag (previous test).
    const double low = std::sqrt(8.0 * 0.25 * THICKNESS * 0.25) / alpha;
    const double high = std::sqrt(8.0 * 0.25 * (THICKNESS + 2e-3) * 0.25) / alpha;
    ASSERT_LT(high, 1.0) << "the case must refine";
    std::vector<double> outer_scales;
    for (int ei = 0; ei < shell.num_edges(); ++ei) {
        const Edge& e = shell.edge(ei);
        if (e[0] < shell.num_vertices() / 2)
            outer_scales.push_back(sizing.scale(e[0], e[1]));
    }
    const double m = median(outer_scales);
    EXPECT_GT(m, 0.8 * low);
    EXPECT_LT(m, 1.1 * high);
    // The same options leave a lone sphere (nothing faces it) and a thick shell (sag below
    // f·h) at the nominal limits.
    for (const SurfaceMesh& mesh : {testing::make_test_sphere(), make_shell(0.05)}) {
        const EdgeSizing nominal(mesh, options, xi);
        for (int ei = 0; ei < mesh.num_edges(); ++ei) {
            const Edge& e = mesh.edge(ei);
            ASSERT_EQ(nominal.scale(e[0], e[1]), 1.0);
        }
    }

    // Improvement refines the thin shell to the sizing and keeps it valid and apart.
    SurfaceMesh refined = shell;
    ImproveContext context;
    context.xi = xi;
    context.allow_topology_changes = false;
    for (int k = 0; k < 4; ++k)
        improve_mesh(refined, options, context);
    EXPECT_GT(refined.count_live_triangles(), 2 * shell.count_live_triangles());
    EXPECT_TRUE(validate_mesh(refined).empty());
    EXPECT_TRUE(is_intersection_free(refined));

    options.thin_sheet_sag_fraction = -1.0;
    try {
        EdgeSizing(shell, options, xi);
        FAIL() << "no throw";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("thin_sheet_sag_fraction"), std::string::npos);
    }
    options.thin_sheet_sag_fraction = 0.25;
    options.split_on_fitted_surface = false;
    EXPECT_THROW(EdgeSizing(shell, options, xi), std::invalid_argument);
}

TEST(RemeshSizing, TargetLengthIsGradedAwayFromARefinedSpot) {
    // Curvature sizing on the torus refines the whole tube; a shell thin only near one pole
    // refines a spot. In both the target length s α may rise by at most SIZE_GRADING per metre
    // along each edge (s of an edge's endpoints, through scale(v, v)).
    SurfaceMesh shell = make_shell(0.05);
    const int half = shell.num_vertices() / 2;
    for (int vi = half; vi < shell.num_vertices(); ++vi) {
        const Vec3 x = shell.position(vi);
        if (x.z() > 0.15)  // pull the inner sphere's cap up to 3 mm below the outer one
            shell.set_position(vi, x * (0.247 / x.norm()));
    }
    const double xi = testing::mean_edge_length(shell);
    RemeshOptions options = thin_sheet_options();
    const EdgeSizing sizing(shell, options, xi);
    const double alpha = sizing.limits().max_edge_length;
    int refined = 0, graded = 0;
    for (int ei = 0; ei < shell.num_edges(); ++ei) {
        const Edge& e = shell.edge(ei);
        const double ha = sizing.scale(e[0], e[0]) * alpha;
        const double hb = sizing.scale(e[1], e[1]) * alpha;
        const double length = (shell.position(e[0]) - shell.position(e[1])).norm();
        ASSERT_LE(std::abs(ha - hb), SIZE_GRADING * length * (1.0 + 1e-12)) << ei;
        refined += ha < 0.5 * alpha;
        graded += ha < alpha && shell.position(e[0]).z() < 0.1;
    }
    EXPECT_GT(refined, 0) << "the thin cap refines";
    EXPECT_GT(graded, 0) << "the grading reaches past the cap";
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
