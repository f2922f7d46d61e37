// Face offsetting (Jiao 2007; paper §4.1): entropy-satisfying motion in the normal direction.
#include "tests/tracker/flow_test_meshes.h"

#include "tracker/flows/face_offsetting.h"
#include "tracker/flows/flow_errors.h"
#include "tracker/flows/vertex_normal_motion.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

namespace meniscus::tracker {
namespace {

using namespace testing;

TEST(FaceOffsetting, SphereRadiusChangesBySpeedTimesDt) {
    const double radius = 0.2;
    const Vec3 center(0.25, 0.0, 0.0);
    const double h = 0.001;  // 0.2 m/s × 0.005 s, the A1 step
    std::vector<double> errors, mean_edges;
    for (double edge : {0.04, 0.02, 0.01}) {
        SurfaceMesh mesh = meshed_sphere(center, radius, edge);
        project_to_sphere(mesh, center, radius);
        mean_edges.push_back(edge_length_stats(mesh).mean);
        for (double sign : {1.0, -1.0}) {
            const FaceOffset offset = face_offset_displacements(mesh, sign * 0.2, 0.005);
            double max_error = 0.0;
            int rank_one = 0, live = 0;
            for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
                if (!mesh.vertex_alive(vi))
                    continue;
                const Vec3 p = mesh.position(vi) + offset.displacements[static_cast<size_t>(vi)];
                max_error =
                    std::max(max_error, std::abs((p - center).norm() - (radius + sign * h)));
                rank_one += offset.primary_rank[static_cast<size_t>(vi)] == 1;
                ++live;
            }
            if (sign > 0.0) {
                errors.push_back(max_error / h);
                std::cout << "[ measured ] face offsetting sphere R=0.2 h=" << mean_edges.back()
                          << ": max |Δr − sΔt| / sΔt = " << max_error / h << ", rank-1 vertices "
                          << rank_one << "/" << live << "\n";
            }
            EXPECT_LT(max_error, 0.05 * h);
        }
    }
    EXPECT_LT(errors[1], errors[0]);
    EXPECT_LT(errors[2], errors[1]);
    EXPECT_GT(observed_order(errors[0], errors[2], mean_edges[0], mean_edges[2]), 1.5);
}

TEST(FaceOffsetting, AngleWeightsAlsoOffsetTheSphere) {
    const double radius = 0.2, h = 0.001;
    SurfaceMesh mesh = meshed_sphere(Vec3::Zero(), radius, 0.02);
    project_to_sphere(mesh, Vec3::Zero(), radius);
    FaceOffsettingOptions options;
    options.weighting = OffsetWeighting::angle;
    const FaceOffset offset = face_offset_displacements(mesh, 0.2, 0.005, options);
    const SurfaceError before = sphere_error(mesh, Vec3::Zero(), radius);
    displace(mesh, offset.displacements);
    const SurfaceError after = sphere_error(mesh, Vec3::Zero(), radius + h);
    EXPECT_LT(after.vertex_linf, 0.05 * h);
    EXPECT_LT(before.vertex_linf, 1e-15);
}

TEST(FaceOffsetting, FirstStepOfTwoSphereTestAgreesWithExactSolution) {
    const TwoSphereNormalFlow flow;  // docs/validation.md A1
    const double dt = 0.005;
    for (double edge : {0.04, 0.02}) {
        ImplicitMeshOptions mesh_options;
        mesh_options.edge_length = edge;
        SurfaceMesh mesh =
            mesh_implicit_shape(*make_union({make_sphere(flow.center0, flow.initial_radius),
                                             make_sphere(flow.center1, flow.initial_radius)}),
                                mesh_options);
        for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
            const Vec3& p = mesh.position(vi);
            const Vec3& c = p.x() < 0.0 ? flow.center0 : flow.center1;
            mesh.set_position(vi, c + flow.initial_radius * (p - c).normalized());
        }
        const SurfaceError before = two_sphere_normal_flow_error(mesh, flow, 0.0);
        const FaceOffsetStep step = face_offset_step(
            mesh,
            std::vector<double>(static_cast<size_t>(mesh.num_triangles()), flow.normal_speed(0.0)),
            dt);
        EXPECT_FALSE(step.shortened);
        EXPECT_EQ(step.dt, dt);
        displace(mesh, step.displacements);
        const SurfaceError after = two_sphere_normal_flow_error(mesh, flow, dt);
        std::cout << "[ measured ] A1 first step ξ=" << edge << ": vertex L∞ " << after.vertex_linf
                  << " (sΔt = " << flow.speed * dt << "), L∞ " << after.linf << " (before "
                  << before.linf << "), L1 " << after.l1 << " (before " << before.l1 << ")\n";
        EXPECT_LT(after.vertex_linf, 0.05 * flow.speed * dt);
        // The chord error of the sphere mesh is the floor: one step must not add to it.
        EXPECT_LT(after.linf, before.linf * 1.05 + 0.05 * flow.speed * dt);
        EXPECT_LT(after.l1, before.l1 * 1.05 + 0.05 * flow.speed * dt);
    }
}

TEST(FaceOffsetting, ShrinkingCubeStaysSharpWhereVertexNormalsRoundIt) {
    const double a = 0.5, h = 0.05;
    const SurfaceMesh mesh = cube_mesh(a, 6);
    const ShapePtr exact = make_box(Vec3::Constant(-(a - h)), Vec3::Constant(a - h));
    const FaceOffset offset = face_offset_displacements(mesh, -1.0, h);
    const std::vector<Vec3> vn = vertex_normal_displacements(mesh, -1.0, h);
    double fo_error = 0.0, vn_error = 0.0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        const Vec3& p = mesh.position(vi);
        const int on_faces = (std::abs(std::abs(p.x()) - a) < 1e-12) +
                             (std::abs(std::abs(p.y()) - a) < 1e-12) +
                             (std::abs(std::abs(p.z()) - a) < 1e-12);
        EXPECT_EQ(offset.primary_rank[static_cast<size_t>(vi)], on_faces);
        fo_error = std::max(
            fo_error, std::abs(exact->value(p + offset.displacements[static_cast<size_t>(vi)])));
        vn_error = std::max(vn_error, std::abs(exact->value(p + vn[static_cast<size_t>(vi)])));
    }
    std::cout << "[ measured ] shrinking cube by h: face offsetting max |φ| / h = " << fo_error / h
              << ", vertex normals " << vn_error / h << "\n";
    EXPECT_LT(fo_error, 1e-12);
    EXPECT_GT(vn_error, 0.2 * h);  // edges: (1 − 1/√2) h for symmetric fans

    // Expanding: the exact solution is the rounded dilation {dist(x, cube) = h}. The Huygens
    // rule puts every vertex exactly on it (edge and corner vertices move by h inside their
    // normal cones), as vertex normals also do here; the plane rule keeps a sharp box of
    // half-width a + h instead.
    const ShapePtr cube = make_box(Vec3::Constant(-a), Vec3::Constant(a));
    const ShapePtr sharp = make_box(Vec3::Constant(-(a + h)), Vec3::Constant(a + h));
    const FaceOffset grow = face_offset_displacements(mesh, 1.0, h);
    FaceOffsettingOptions planes;
    planes.expansion = ExpansionRule::planes;
    const FaceOffset grow_sharp = face_offset_displacements(mesh, 1.0, h, planes);
    const std::vector<Vec3> vn_grow = vertex_normal_displacements(mesh, 1.0, h);
    double fo_rounded = 0.0, vn_rounded = 0.0, planes_sharp = 0.0;
    int expanding = 0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        const size_t i = static_cast<size_t>(vi);
        const Vec3& p = mesh.position(vi);
        fo_rounded = std::max(fo_rounded, std::abs(cube->value(p + grow.displacements[i]) - h));
        vn_rounded = std::max(vn_rounded, std::abs(cube->value(p + vn_grow[i]) - h));
        planes_sharp =
            std::max(planes_sharp, std::abs(sharp->value(p + grow_sharp.displacements[i])));
        expanding += grow.expanding[i];
        EXPECT_EQ(offset.expanding[i], 0);  // shrinking a convex body: shocks only
    }
    EXPECT_LT(fo_rounded, 1e-12);
    EXPECT_LT(vn_rounded, 1e-12);
    EXPECT_LT(planes_sharp, 1e-12);
    EXPECT_GT(expanding, 0);
}

TEST(FaceOffsetting, ConcaveCreaseRisesToThePlanesIntersection) {
    const double slope = 0.5, h = 0.01;
    const SurfaceMesh mesh = valley_mesh(slope, 4);
    const int crease = 2 * 4 + 1 + 4;  // row j = 1, column i = n: the point (0, 0.25, 0)
    ASSERT_NEAR(mesh.position(crease).x(), 0.0, 1e-15);
    ASSERT_FALSE(mesh.is_boundary_vertex(crease));
    const FaceOffset offset = face_offset_displacements(mesh, 1.0, h);
    const std::vector<Vec3> vn = vertex_normal_displacements(mesh, 1.0, h);
    const double cos_theta = 1.0 / std::sqrt(1.0 + slope * slope);
    const Vec3 expected(0.0, 0.0, h / cos_theta);  // on both offset planes: the entropy solution
    EXPECT_EQ(offset.primary_rank[static_cast<size_t>(crease)], 2);
    EXPECT_LT((offset.displacements[static_cast<size_t>(crease)] - expected).norm(), 1e-14);
    // Vertex normals move the crease by h only: it lags behind both planes.
    EXPECT_NEAR(vn[static_cast<size_t>(crease)].z(), h, 1e-14);
    const double gap =
        (offset.displacements[static_cast<size_t>(crease)] - vn[static_cast<size_t>(crease)])
            .norm();
    std::cout << "[ measured ] valley crease, slope " << slope << ": face offsetting − vertex "
              << "normal = " << gap / h << " h (exact h(1/cosθ − 1) = " << (1.0 / cos_theta - 1.0)
              << " h)\n";
    EXPECT_NEAR(gap, h * (1.0 / cos_theta - 1.0), 1e-14);
    EXPECT_EQ(offset.expanding[static_cast<size_t>(crease)], 0);

    // Moving down the valley opens an expansion fan: the exact crease point is h below
    // (Huygens); the plane intersection would overshoot to h / cos θ.
    const FaceOffset down = face_offset_displacements(mesh, -1.0, h);
    EXPECT_EQ(down.expanding[static_cast<size_t>(crease)], 1);
    EXPECT_LT((down.displacements[static_cast<size_t>(crease)] - Vec3(0, 0, -h)).norm(), 1e-14);
    FaceOffsettingOptions planes;
    planes.expansion = ExpansionRule::planes;
    const FaceOffset down_sharp = face_offset_displacements(mesh, -1.0, h, planes);
    EXPECT_LT((down_sharp.displacements[static_cast<size_t>(crease)] + expected).norm(), 1e-14);
}

TEST(FaceOffsetting, NearFoldOffsetIsCapped) {
    // A valley with slope 10 (normals 2·84.3° apart): the planes meet 10.05 h above the crease;
    // the cap (default 4) holds the crease vertex to 4 h along the same direction.
    const double h = 0.01;
    const SurfaceMesh mesh = valley_mesh(10.0, 4);
    const size_t crease = 2 * 4 + 1 + 4;
    const FaceOffset capped = face_offset_displacements(mesh, 1.0, h);
    FaceOffsettingOptions loose;
    loose.max_offset_ratio = 20.0;
    const FaceOffset uncapped = face_offset_displacements(mesh, 1.0, h, loose);
    EXPECT_EQ(capped.capped[crease], 1);
    EXPECT_EQ(uncapped.capped[crease], 0);
    EXPECT_NEAR(uncapped.displacements[crease].z(), h * std::sqrt(101.0), 1e-12);
    EXPECT_LT((capped.displacements[crease] - Vec3(0, 0, 4.0 * h)).norm(), 1e-12);
    loose.max_offset_ratio = 0.5;
    EXPECT_THROW(face_offset_displacements(mesh, 1.0, h, loose), std::invalid_argument);
}

TEST(FaceOffsetting, InversionLimitIsExactForOneTriangle) {
    const SurfaceMesh mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
    // Vertex 2 moves straight down through the opposite edge: area ∝ (1 − 2τ).
    const std::vector<Vec3> d = {Vec3::Zero(), Vec3::Zero(), Vec3(0, -2, 0)};
    InversionLimitOptions options;
    options.min_area_fraction = 0.0;
    EXPECT_NEAR(max_non_inverting_step_fraction(mesh, d, options), 0.5, 1e-15);
    options.min_area_fraction = 0.1;
    EXPECT_NEAR(max_non_inverting_step_fraction(mesh, d, options), 0.45, 1e-15);
    // Moving in-plane without inverting, or rigidly, is unrestricted.
    EXPECT_EQ(max_non_inverting_step_fraction(mesh, {Vec3(1, 1, 5), Vec3(1, 1, 5), Vec3(1, 1, 5)},
                                              options),
              1.0);
    options.min_area_fraction = 1.0;
    EXPECT_THROW(max_non_inverting_step_fraction(mesh, d, options), std::invalid_argument);
}

TEST(FaceOffsetting, StepIsShortenedSoNoTriangleInverts) {
    const double radius = 0.2;
    SurfaceMesh mesh = meshed_sphere(Vec3::Zero(), radius, 0.04);
    project_to_sphere(mesh, Vec3::Zero(), radius);
    const std::vector<double> speeds(static_cast<size_t>(mesh.num_triangles()), -1.0);
    const FaceOffsetStep step = face_offset_step(mesh, speeds, 1.0);  // would shrink through 0
    EXPECT_TRUE(step.shortened);
    EXPECT_EQ(step.attempts, 1);  // linear in Δt: the displacements are scaled, not recomputed
    // A shrinking sphere's triangles scale by (1 − s t / R)²: 10 % area left at
    // t ≈ (1 − √0.1) R / s; on a coarse irregular mesh the offsets of a step of 5R are not
    // exactly radial, so only roughly.
    EXPECT_NEAR(step.dt, (1.0 - std::sqrt(0.1)) * radius, 0.1 * radius);
    const std::vector<Vec3> p1 = moved(mesh, step.displacements);
    double min_fraction = 1.0;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        const Triangle& t = mesh.triangle(ti);
        const Vec3& a = mesh.position(t[0]);
        const Vec3 n0 = (mesh.position(t[1]) - a).cross(mesh.position(t[2]) - a);
        const Vec3 n1 = (p1[static_cast<size_t>(t[1])] - p1[static_cast<size_t>(t[0])])
                            .cross(p1[static_cast<size_t>(t[2])] - p1[static_cast<size_t>(t[0])]);
        min_fraction = std::min(min_fraction, n1.dot(n0.normalized()) / n0.norm());
    }
    EXPECT_GT(min_fraction, 0.1 - 1e-9);
    EXPECT_LT(min_fraction, 0.1 + 1e-6);

    FaceOffsettingOptions smoothing;
    smoothing.null_space_smoothing = 0.5;
    const FaceOffsetStep smoothed = face_offset_step(mesh, speeds, 1.0, smoothing);
    EXPECT_TRUE(smoothed.shortened);
    EXPECT_GE(max_non_inverting_step_fraction(mesh, smoothed.displacements), 1.0);
}

TEST(FaceOffsetting, NormalTurnCheckForRemeshing) {
    const Vec3 up(0, 0, 1);
    const Vec3 a(0, 0, 0), b(1, 0, 0);
    auto tilted = [](double degrees) {
        const double r = degrees * M_PI / 180.0;
        return Vec3(0, std::cos(r), std::sin(r));  // normal turned by `degrees` about x
    };
    EXPECT_FALSE(triangle_normal_turn_too_large(up, a, b, tilted(20.0)));
    EXPECT_TRUE(triangle_normal_turn_too_large(up, a, b, tilted(40.0)));
    EXPECT_TRUE(triangle_normal_turn_too_large(up, a, b, Vec3(0, -1, 0)));  // inverted
    EXPECT_TRUE(triangle_normal_turn_too_large(up, a, b, Vec3(2, 0, 0)));   // degenerate
    NormalTurnLimit wide;
    wide.max_angle_degrees = 45.0;
    EXPECT_FALSE(triangle_normal_turn_too_large(up, a, b, tilted(40.0), wide));
    EXPECT_THROW(triangle_normal_turn_too_large(Vec3::Zero(), a, b, tilted(0)),
                 std::invalid_argument);

    // Flip of a flat quad is fine; flipping a sharp roof ridge turns normals too far.
    const Vec3 p0(0, 0, 0), p1(1, 0, 0), p2(1, 1, 0), p3(0, 1, 0);
    EXPECT_FALSE(operation_turns_normals_too_far({{p0, p1, p2}, {p0, p2, p3}},
                                                 {{p0, p1, p3}, {p1, p2, p3}}));
    const Vec3 r2(1, 1, 2.0);  // roof folded along the diagonal p0–r2 (new normal turns 55°)
    EXPECT_TRUE(operation_turns_normals_too_far({{p0, p1, r2}, {p0, r2, p3}},
                                                {{p0, p1, p3}, {p1, r2, p3}}));
    NormalTurnLimit bad;
    bad.max_angle_degrees = 180.0;
    EXPECT_THROW(bad.validate(), std::invalid_argument);
}

TEST(FaceOffsetting, OptionsAndInputsAreValidated) {
    const SurfaceMesh mesh = cube_mesh(1.0, 1);
    FaceOffsettingOptions options;
    options.primary_eigenvalue_ratio = 0.0;
    EXPECT_THROW(face_offset_displacements(mesh, 1.0, 0.1, options), std::invalid_argument);
    options = {};
    options.null_space_smoothing = 2.0;
    EXPECT_THROW(face_offset_displacements(mesh, 1.0, 0.1, options), std::invalid_argument);
    EXPECT_THROW(face_offset_displacements(mesh, std::vector<double>(3, 1.0), 0.1),
                 std::invalid_argument);
    EXPECT_THROW(face_offset_step(mesh, std::vector<double>(12, 1.0), 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::tracker
