// Prescribed velocity fields (tracker/flows/velocity_field.h): rigid motion and a user's field
// given as expressions, and a tracked sphere that a rigid motion carries back onto itself.
#include "tests/tracker/flow_test_meshes.h"

#include "tracker/flows/flow_errors.h"
#include "tracker/flows/flow_runner.h"
#include "tracker/flows/velocity_field.h"
#include "tracker/mesh_measures.h"
#include "tracker/surface_tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <string>

namespace meniscus::tracker {
namespace {

using namespace testing;

RigidMotionOptions spin_and_drift() {
    RigidMotionOptions o;
    o.angular_velocity = Vec3(1.0, 2.0, -2.0).normalized() * 2.0 * M_PI;  // one turn per second
    o.center = Vec3(0.1, -0.2, 0.3);
    o.velocity = Vec3(0.3, 0.0, -0.1);
    return o;
}

TEST(RigidMotionField, VelocityIsTranslationPlusRotationAboutTheMovingCentre) {
    const RigidMotionOptions o = spin_and_drift();
    const RigidMotionField field(o);
    const Vec3 x(0.4, 0.5, -0.6);
    for (double t : {0.0, 0.25, 1.5}) {
        const Vec3 c = o.center + t * o.velocity;
        EXPECT_LT((field.velocity(x, t) - (o.velocity + o.angular_velocity.cross(x - c))).norm(),
                  1e-15);
        EXPECT_LT((field.velocity(c, t) - o.velocity).norm(), 1e-15);  // the centre only drifts
    }
}

TEST(RigidMotionField, PositionIsTheExactFlowMap) {
    const RigidMotionField field(spin_and_drift());
    const Vec3 x0(0.4, 0.5, -0.6);
    // d/dt position = velocity(position) (central differences), |x − c| kept, back after a turn.
    constexpr double H = 1e-6;
    for (double t : {0.1, 0.37, 0.8}) {
        const Vec3 rate = (field.position(x0, t + H) - field.position(x0, t - H)) / (2 * H);
        EXPECT_LT((rate - field.velocity(field.position(x0, t), t)).norm(), 1e-7);
        const Vec3 c = field.options().center + t * field.options().velocity;
        EXPECT_NEAR((field.position(x0, t) - c).norm(), (x0 - field.options().center).norm(),
                    1e-14);
    }
    EXPECT_LT((field.position(x0, 1.0) - (x0 + field.options().velocity)).norm(), 1e-14);
    // Translation alone.
    RigidMotionOptions drift;
    drift.velocity = Vec3(1.0, 2.0, 3.0);
    EXPECT_LT((RigidMotionField(drift).position(x0, 0.5) - (x0 + 0.5 * drift.velocity)).norm(),
              1e-15);
}

TEST(RigidMotionField, Rk4ReturnsAPointAfterOneTurn) {
    // Rotation about z through (0.5, 0.5): Zalesak's field. RK4 turns a point by θ = ωΔt with
    // a phase error of θ⁵/120 of the radius per step (its amplitude error, θ⁶/144, is smaller):
    // 100 steps of θ = 2π/100 lag by 8.2e-7 of the radius after the turn.
    RigidMotionOptions o;
    o.angular_velocity = Vec3(0.0, 0.0, 2.0 * M_PI);
    o.center = Vec3(0.5, 0.5, 0.5);
    const RigidMotionField field(o);
    SurfaceMesh mesh;
    const Vec3 x0(0.5, 0.9, 0.2);
    const double radius = 0.4;
    mesh.add_vertex(x0);
    const int steps = 100;
    const double theta = 2.0 * M_PI / steps;
    const double step_error = std::pow(theta, 5) / 120.0 * radius;
    for (int i = 0; i < steps; ++i) {
        const std::vector<Vec3> d = rk4_displacements(mesh, field, i / double(steps), 1.0 / steps);
        displace(mesh, d);
        const double error = (mesh.position(0) - field.position(x0, (i + 1.0) / steps)).norm();
        EXPECT_NEAR(error, (i + 1) * step_error, 0.02 * (i + 1) * step_error);
    }
    EXPECT_LT((mesh.position(0) - x0).norm(), 1e-6 * radius);
}

TEST(RigidMotionField, RejectsNonFiniteOptions) {
    RigidMotionOptions o;
    o.center.x() = NAN;
    try {
        RigidMotionField f(o);
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()).rfind("center:", 0), 0u) << e.what();
    }
}

TEST(ExpressionField, EnrightWrittenAsExpressionsIsTheEnrightField) {
    ExpressionFieldOptions o;
    o.constants = {{"T", 3.0}};
    o.velocity = {"2 * sin(pi*x)^2 * sin(2*pi*y) * sin(2*pi*z) * sin(2*pi*t/T)",
                  "-sin(2*pi*x) * sin(pi*y)^2 * sin(2*pi*z) * sin(2*pi*t/T)",
                  "-sin(2*pi*x) * sin(2*pi*y) * sin(pi*z)^2 * sin(2*pi*t/T)"};
    const ExpressionField field(o);
    const EnrightField enright(3.0);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < 200; ++i) {
        const Vec3 x(u(rng), u(rng), u(rng));
        const double t = 3.0 * u(rng);
        EXPECT_LT((field.velocity(x, t) - enright.velocity(x, t)).norm(), 1e-14);
    }
}

TEST(ExpressionField, NumbersAndRigidRotationAsText) {
    ExpressionFieldOptions o;
    o.velocity = {"-2*pi*(y - 0.5)", "2*pi*(x - 0.5)", "0.25"};
    const ExpressionField field(o);
    RigidMotionOptions r;
    r.angular_velocity = Vec3(0.0, 0.0, 2.0 * M_PI);
    r.center = Vec3(0.5, 0.5, 0.0);
    r.velocity = Vec3(0.0, 0.0, 0.25);
    const RigidMotionField rigid(r);
    for (const Vec3& x : {Vec3(0.1, 0.2, 0.3), Vec3(0.9, -0.4, 2.0)})
        EXPECT_LT((field.velocity(x, 0.0) - rigid.velocity(x, 0.0)).norm(), 1e-14);
}

TEST(ExpressionField, ErrorsNameTheComponentAndColumn) {
    ExpressionFieldOptions o;
    o.velocity = {"x", "1 + q", "0"};
    try {
        o.validate();
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()).rfind("velocity/1: column 5: unknown name 'q'", 0), 0u)
            << e.what();
    }
    o.velocity = {"0", "0", "0"};
    o.constants = {{"x", 1.0}};
    try {
        ExpressionField f(o);
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()).rfind("constants/x: ", 0), 0u) << e.what();
    }
}

TEST(ExpressionField, NonFiniteVelocityThrowsNamingComponentPointAndTime) {
    ExpressionFieldOptions o;
    o.velocity = {"0", "log(x)", "0"};
    const ExpressionField field(o);
    EXPECT_NO_THROW(field.velocity(Vec3(1.0, 0.0, 0.0), 0.0));
    try {
        field.velocity(Vec3(-1.0, 0.0, 0.0), 0.5);
        FAIL() << "expected std::domain_error";
    } catch (const std::domain_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("velocity/1"), std::string::npos) << what;
        EXPECT_NE(what.find("x = (-1, 0, 0)"), std::string::npos) << what;
        EXPECT_NE(what.find("t = 0.5"), std::string::npos) << what;
    }
}

/// A sphere turned once about a tilted axis while it drifts, through the collision-safe
/// tracker with mesh improvement on every step, ends where the drift alone takes it: the
/// remeshing moves vertices along the surface, not off it, and keeps the volume.
TEST(RigidMotionField, TrackedSphereReturnsToItselfAfterOneTurn) {
    const double radius = 0.2, xi = 0.04;
    const Vec3 center(0.1, -0.2, 0.3);
    SurfaceMesh start = meshed_sphere(center, radius, xi);
    const double volume0 = enclosed_volume(start);
    RigidMotionOptions o = spin_and_drift();
    o.center = center;
    const RigidMotionField field(o);
    const VelocityFieldStepper stepper(field);
    TrackerOptions options;
    options.verify_intersection_free = true;
    SurfaceTracker tracker(start, options);
    const double dt = 0.02;
    const int steps = 50;
    int pairs = 0;
    for (int i = 0; i < steps; ++i) {
        tracker.improve();
        tracker.change_topology();
        const FlowStep step = stepper.step(tracker.mesh(), i * dt, dt);
        std::vector<Vec3> velocities(step.displacements.size());
        for (size_t vi = 0; vi < velocities.size(); ++vi)
            velocities[vi] = step.displacements[vi] / step.dt;
        const IntegrateResult r = tracker.integrate(velocities, step.dt);
        EXPECT_EQ(r.time_advanced, step.dt);
        pairs = std::max(pairs, r.intersecting_pairs);
    }
    SurfaceMesh expected = start;  // the start, drifted by v·T
    for (int vi = 0; vi < expected.num_vertices(); ++vi)
        expected.set_position(vi, expected.position(vi) + o.velocity);
    const HausdorffDistance h = hausdorff_distance(tracker.mesh(), expected);
    const double volume_change = relative_volume_change(tracker.mesh(), volume0);
    const SurfaceError to_sphere = sphere_error(tracker.mesh(), center + o.velocity, radius);
    std::cout << "[ measured ] sphere r=0.2, ξ=0.04, one turn + drift in 50 RK4 steps: Hausdorff "
              << h.symmetric << " (" << h.symmetric / xi << " ξ), mean " << h.a_to_b.l1
              << ", vertex L∞ to the sphere " << to_sphere.vertex_linf << ", volume change "
              << volume_change << "\n";
    // Measured: Hausdorff 3.4e-4 (0.0085 ξ), vertex L∞ 1.7e-5, volume change −1.4e-6.
    EXPECT_EQ(pairs, 0);
    EXPECT_LT(h.symmetric, 0.02 * xi);
    EXPECT_LT(to_sphere.vertex_linf, 2e-3 * xi);
    EXPECT_LT(std::abs(volume_change), 1e-5);
}

}  // namespace
}  // namespace meniscus::tracker
