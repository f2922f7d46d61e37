// Exact solutions and error measures of the geometric flows (docs/validation.md A1).
#include "tests/tracker/flow_test_meshes.h"

#include "tracker/flows/flow_errors.h"
#include "tracker/flows/mean_curvature.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace meniscus::tracker {
namespace {

using namespace testing;

TEST(TwoSphereNormalFlow, ExactDistanceAtKnownPoints) {
    const TwoSphereNormalFlow flow;
    const double tol = 1e-14;
    // t = 0: two disjoint spheres of radius 0.2.
    EXPECT_NEAR(flow.signed_distance(Vec3(0.45, 0, 0), 0.0), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0.25, 0, 0), 0.0), -0.2, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, 0), 0.0), 0.05, tol);
    // t = 0.5: radius 0.3, merged; ring at x = 0 of radius sqrt(0.3² − 0.25²).
    const double ring05 = std::sqrt(0.09 - 0.0625);
    EXPECT_NEAR(flow.signed_distance(Vec3(0.55, 0, 0), 0.5), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, ring05, 0), 0.5), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, 0), 0.5), -ring05, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0.25, 0, 0), 0.5), -0.3, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(1, 0, 0), 0.5), 0.45, tol);
    // t = 1: radius 0.4.
    const double ring1 = std::sqrt(0.16 - 0.0625);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, ring1), 1.0), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, 0), 1.0), -ring1, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(-0.65, 0, 0), 1.0), 0.0, tol);
    // t = 1.5: eroded by 0.1.
    EXPECT_NEAR(flow.signed_distance(Vec3(0.55, 0, 0), 1.5), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, 0), 1.5), 0.1 - ring1, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, ring1, 0), 1.5), 0.1, tol);
    // t = 2: eroded by 0.2 — the neck stays, of radius ring1 − 0.2 (not two r = 0.2 spheres).
    EXPECT_NEAR(flow.signed_distance(Vec3(0.45, 0, 0), 2.0), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, ring1 - 0.2, 0), 2.0), 0.0, tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0, 0), 2.0), 0.2 - ring1, tol);
    EXPECT_LT(flow.signed_distance(Vec3(0, 0, 0), 2.0), 0.0);  // inside: merged
    // (0, 0.3, 0) is inside U but within 0.2 of the ring: outside at t = 2.
    EXPECT_NEAR(flow.signed_distance(Vec3(0, 0.3, 0), 2.0), 0.2 - (ring1 - 0.3), tol);
    EXPECT_NEAR(flow.signed_distance(Vec3(0.25, 0, 0), 2.0), -0.2, tol);
    EXPECT_EQ(flow.normal_speed(0.5), 0.2);
    EXPECT_EQ(flow.normal_speed(1.5), -0.2);
    EXPECT_THROW(flow.signed_distance(Vec3::Zero(), -0.1), std::invalid_argument);
}

TEST(TwoSphereNormalFlow, UnionDistanceMatchesBruteForceOverTheBoundary) {
    // Dense samples of ∂U (sphere points outside the other ball, plus the ring).
    const Vec3 c0(-0.25, 0, 0), c1(0.25, 0, 0);
    const double r = 0.4;
    std::vector<Vec3> boundary;
    const int n = 60000;
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (const Vec3* c : {&c0, &c1}) {
        const Vec3& other = c == &c0 ? c1 : c0;
        for (int i = 0; i < n; ++i) {
            const double z = 1.0 - 2.0 * (i + 0.5) / n, rho = std::sqrt(1.0 - z * z);
            const Vec3 p = *c + r * Vec3(z, rho * std::cos(golden * i), rho * std::sin(golden * i));
            if ((p - other).norm() >= r)
                boundary.push_back(p);
        }
    }
    const double ring = std::sqrt(r * r - 0.0625);
    for (int i = 0; i < 2000; ++i) {
        const double phi = 2.0 * M_PI * i / 2000;
        boundary.push_back(Vec3(0, ring * std::cos(phi), ring * std::sin(phi)));
    }
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> coord(-0.8, 0.8);
    double worst = 0.0;
    for (int s = 0; s < 300; ++s) {
        const Vec3 x(coord(rng), 0.6 * coord(rng), 0.6 * coord(rng));
        double brute = std::numeric_limits<double>::infinity();
        for (const Vec3& p : boundary)
            brute = std::min(brute, (x - p).norm());
        const double exact = two_ball_union_signed_distance(x, c0, c1, r);
        const bool inside = (x - c0).norm() < r || (x - c1).norm() < r;
        EXPECT_EQ(exact < 0.0, inside);
        worst = std::max(worst, std::abs(std::abs(exact) - brute));
        EXPECT_LE(std::abs(exact), brute + 1e-12);  // sampled boundary: brute ≥ exact
    }
    EXPECT_LT(worst, 0.006);  // sample spacing ≈ r·sqrt(4π/n) ≈ 0.006
}

TEST(SurfaceErrorMeasure, ExactSphereSampleHasZeroVertexError) {
    const double r0 = 0.3, t = 0.01;
    const double radius = sphere_mean_curvature_radius(r0, t);
    EXPECT_NEAR(radius, std::sqrt(0.09 - 0.04), 1e-15);
    SurfaceMesh mesh = meshed_sphere(Vec3(0.1, 0.1, 0.1), radius, 0.02);
    project_to_sphere(mesh, Vec3(0.1, 0.1, 0.1), radius);
    const SurfaceError e = sphere_error(mesh, Vec3(0.1, 0.1, 0.1), radius);
    EXPECT_LT(e.vertex_linf, 1e-15);
    EXPECT_LT(e.vertex_l1, 1e-15);
    // Chords cut inside the sphere by at most ℓ²/(8R); L1 is a fraction of that.
    const double longest = edge_length_stats(mesh).max;
    EXPECT_GT(e.linf, 0.0);
    EXPECT_LE(e.linf, longest * longest / (4.0 * radius));
    EXPECT_LT(e.l1, e.linf);
    EXPECT_NEAR(e.area, surface_area(mesh), 1e-12);
    EXPECT_THROW(sphere_mean_curvature_radius(r0, 0.03), std::invalid_argument);
}

TEST(SurfaceErrorMeasure, L1IsTheAreaWeightedMeanDistance) {
    // A flat unit square 0.1 above the plane z = 0: every sample is at distance 0.1.
    const SurfaceMesh square({{0, 0, 0.1}, {1, 0, 0.1}, {1, 1, 0.1}, {0, 1, 0.1}},
                             {{0, 1, 2}, {0, 2, 3}});
    auto plane = [](const Vec3& x) { return x.z(); };
    SurfaceError e = surface_error(square, plane);
    EXPECT_NEAR(e.l1, 0.1, 1e-15);
    EXPECT_NEAR(e.linf, 0.1, 1e-15);
    EXPECT_EQ(e.samples, 4 + 2 * (16 + 12));  // vertices + m² centroids + non-corner lattice
    // A tilted square z = x: mean of |x| over the unit square is 1/2 (midpoint rule exact).
    const SurfaceMesh tilted({{0, 0, 0}, {1, 0, 1}, {1, 1, 1}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 3}});
    e = surface_error(tilted, plane);
    EXPECT_NEAR(e.l1, 0.5, 1e-14);
    EXPECT_NEAR(e.linf, 1.0, 1e-15);
    // Vertex L1: areas/3 per corner; triangle (0,1,2) has |φ| = 0, 1, 1 and (0,2,3) 0, 1, 0.
    EXPECT_NEAR(e.vertex_l1, (0.5 / 3.0) * (0 + 1 + 1) + (0.5 / 3.0) * (0 + 1 + 0), 1e-15);
    EXPECT_NEAR(relative_volume_change(2.0, 2.1), 0.05, 1e-15);
    EXPECT_THROW(relative_volume_change(0.0, 1.0), std::invalid_argument);
    // Signed vertex measures (the paper's): φ = 0, 1, 1, 1 at the corners (vertex 1 and 3 are
    // shared: 1 at (1,0,1), 0 at (0,1,0)); vertex 2 at (1,1,1) is where max |φ| is first met.
    EXPECT_NEAR(e.vertex_max_signed, 1.0, 1e-15);
    EXPECT_NEAR(e.vertex_min_signed, 0.0, 1e-15);
    EXPECT_NEAR(e.vertex_mean_signed, e.vertex_l1, 1e-15);
    EXPECT_EQ(e.vertex_linf_position, Vec3(1, 0, 1));
    // Below the plane the signed measures change sign, the norms do not.
    auto above = [](const Vec3& x) { return x.z() - 2.0; };
    const SurfaceError below = surface_error(tilted, above);
    EXPECT_NEAR(below.vertex_max_signed, -1.0, 1e-15);
    EXPECT_NEAR(below.vertex_min_signed, -2.0, 1e-15);
    EXPECT_NEAR(below.vertex_mean_signed, -below.vertex_l1, 1e-15);
    EXPECT_NEAR(below.vertex_linf, 2.0, 1e-15);
    SurfaceErrorOptions bad;
    bad.triangle_subdivisions = 0;
    EXPECT_THROW(surface_error(square, plane, bad), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::tracker
