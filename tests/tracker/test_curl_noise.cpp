// Curl noise (paper §4.3–4.4): divergence-free, seeded, reproducible.
#include "tests/tracker/flow_test_meshes.h"

#include "tracker/flows/curl_noise.h"
#include "tracker/flows/flow_errors.h"
#include "tracker/flows/flow_runner.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>

namespace meniscus::tracker {
namespace {

using namespace testing;

TEST(CurlNoise, DivergenceFreeAndGradientMatchesFiniteDifferences) {
    for (bool planar : {false, true}) {
        CurlNoiseOptions options;
        options.seed = 42;
        options.planar = planar;
        options.time_frequency = 1.5;
        const CurlNoiseField field(options);
        std::mt19937_64 rng(7);
        std::uniform_real_distribution<double> coord(-1.0, 1.0);
        const double step = 1e-5;  // central differences, error ~ step² |∇³u|
        double worst_divergence = 0.0, worst_gradient = 0.0;
        for (int sample = 0; sample < 50; ++sample) {
            const Vec3 x(coord(rng), coord(rng), coord(rng));
            const double t = coord(rng);
            Eigen::Matrix3d fd;
            for (int j = 0; j < 3; ++j) {
                const Vec3 dx = step * Vec3::Unit(j);
                fd.col(j) = (field.velocity(x + dx, t) - field.velocity(x - dx, t)) / (2 * step);
            }
            const Eigen::Matrix3d g = field.velocity_gradient(x, t);
            const double scale = fd.norm();
            ASSERT_GT(scale, 0.0);
            worst_divergence = std::max(worst_divergence, std::abs(fd.trace()) / scale);
            worst_gradient = std::max(worst_gradient, (g - fd).norm() / scale);
            EXPECT_LT(std::abs(g.trace()), 1e-12 * g.norm());
            if (planar) {
                EXPECT_EQ(field.velocity(x, t).z(), 0.0);
            }
        }
        std::cout << "[ measured ] curl noise" << (planar ? " (planar)" : "")
                  << ": max |div u|_FD / |∇u| = " << worst_divergence
                  << ", max |∇u − FD| / |∇u| = " << worst_gradient << "\n";
        EXPECT_LT(worst_divergence, 1e-7);
        EXPECT_LT(worst_gradient, 1e-7);
    }
}

TEST(CurlNoise, VelocityIsTheCurlOfThePotential) {
    const CurlNoiseField field;
    const Vec3 x(0.3, -0.1, 0.7);
    const double step = 1e-5;
    Eigen::Matrix3d dpsi;  // dpsi(i, j) = ∂ψᵢ/∂xⱼ
    for (int j = 0; j < 3; ++j) {
        const Vec3 dx = step * Vec3::Unit(j);
        dpsi.col(j) = (field.potential(x + dx, 0.0) - field.potential(x - dx, 0.0)) / (2 * step);
    }
    const Vec3 curl(dpsi(2, 1) - dpsi(1, 2), dpsi(0, 2) - dpsi(2, 0), dpsi(1, 0) - dpsi(0, 1));
    EXPECT_LT((curl - field.velocity(x, 0.0)).norm(), 1e-7 * field.velocity(x, 0.0).norm());
}

TEST(CurlNoise, SeedReproducibleAndRmsSpeedAsRequested) {
    CurlNoiseOptions options;
    options.seed = 123;
    options.rms_speed = 2.0;
    const CurlNoiseField a(options), b(options);
    options.seed = 124;
    const CurlNoiseField c(options);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> coord(-5.0, 5.0);
    double sum_sq = 0.0;
    const int samples = 4000;
    for (int i = 0; i < samples; ++i) {
        const Vec3 x(coord(rng), coord(rng), coord(rng));
        EXPECT_EQ(a.velocity(x, 0.0), b.velocity(x, 0.0));
        if (i < 10) {
            EXPECT_NE(a.velocity(x, 0.0), c.velocity(x, 0.0));
        }
        sum_sq += a.velocity(x, 0.0).squaredNorm();
    }
    const double rms = std::sqrt(sum_sq / samples);
    std::cout << "[ measured ] curl noise sampled RMS speed " << rms << " (requested 2)\n";
    EXPECT_NEAR(rms, 2.0, 0.2);
    // Seed 1 at one point, pinned so that a change of the mode generator is noticed (the
    // engine's sequence and our transforms are fixed; only libm's sin/cos/log may round
    // differently).
    const Vec3 u = CurlNoiseField().velocity(Vec3(0.1, 0.2, 0.3), 0.0);
    EXPECT_LT((u - Vec3(-0.75997098276854835, 0.7760196192985982, -0.14080315452288916)).norm(),
              1e-12);
}

TEST(CurlNoise, Rk4AdvectionNearlyPreservesVolume) {
    CurlNoiseOptions options;
    options.rms_speed = 0.5;
    const CurlNoiseField field(options);
    SurfaceMesh mesh = meshed_sphere(Vec3(0.1, 0.0, -0.1), 0.2, 0.02);
    const double v0 = enclosed_volume(mesh);
    const double dt = 0.01;
    for (int s = 0; s < 20; ++s)
        displace(mesh, rk4_displacements(mesh, field, s * dt, dt));
    const double change = relative_volume_change(mesh, v0);
    std::cout << "[ measured ] curl noise RK4 20 steps of 0.01 s, ξ=0.02: relative volume change "
              << change << "\n";
    EXPECT_LT(std::abs(change), 5e-3);
}

TEST(CurlNoise, OptionsValidated) {
    CurlNoiseOptions options;
    options.octaves = 0;
    EXPECT_THROW(CurlNoiseField{options}, std::invalid_argument);
    options = {};
    options.base_wavelength = -1.0;
    EXPECT_THROW(CurlNoiseField{options}, std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::tracker
