// The analytic references of `meniscus validate` part B (app/fluid_references.h): each checked
// against an independent published number or a limit it must reach.
#include <gtest/gtest.h>

#include <cmath>

#include "app/fluid_references.h"

namespace meniscus::app {
namespace {

constexpr double PI = 3.14159265358979323846;

TEST(FluidReferences, PeriodicStokesletReproducesHasimotosCubicArray) {
    // Hasimoto (1959): a simple cubic array of spheres at small volume fraction c settles at
    // F/(6πμa) (1 − 1.7601 c^{1/3}), c^{1/3} = (4π/3)^{1/3} a/L, i.e. the regular flow at a
    // force is −1.7601 (4π/3)^{1/3} F/(6πμL).
    const double w = periodic_stokeslet_regular_w(Eigen::Vector3d::Ones(),
                                                  {{Eigen::Vector3d::Zero(), 1.0}}, 1.0, 1.0);
    EXPECT_NEAR(w * 6.0 * PI, -1.7601 * std::cbrt(4.0 * PI / 3.0), 1e-4);
    // Independent of the smoothing width once extrapolated.
    const double narrow = periodic_stokeslet_regular_w(
        Eigen::Vector3d::Ones(), {{Eigen::Vector3d::Zero(), 1.0}}, 1.0, 1.0, 24.0);
    EXPECT_NEAR(narrow, w, 1e-6 * std::abs(w));
}

CreepingRiseSetup bubble_in_box(double box_radii) {
    CreepingRiseSetup s;
    s.radius = 1e-3;
    s.rho_liquid = 1000.0;
    s.rho_inside = 1.0;
    s.mu_liquid = 2.0;
    s.mu_inside = 2e-3;
    s.box_size = Eigen::Vector3d::Constant(box_radii * s.radius);
    s.centre = 0.5 * s.box_size;
    return s;
}

TEST(FluidReferences, CreepingRiseTendsToHadamardRybczynskiAsTheBoxGrows) {
    const CreepingRise small = creeping_rise(bubble_in_box(10.0));
    const CreepingRise large = creeping_rise(bubble_in_box(40.0));
    const double kappa = 1e-3;
    const double unbounded = 2.0 / 3.0 * 999.0 * 9.81 * 1e-6 / 2.0 * (1 + kappa) / (2 + 3 * kappa);
    EXPECT_NEAR(small.unbounded, unbounded, 1e-12);
    // The walls slow the bubble, and their effect falls as a/ℓ (first reflection).
    EXPECT_LT(small.wall_correction, 0.0);
    EXPECT_NEAR(large.wall_correction / small.wall_correction, 0.25, 0.01);
    EXPECT_NEAR(small.speed / small.unbounded, 0.799, 0.002);
    EXPECT_NEAR(small.speed, small.unbounded + small.wall_correction, 1e-15);
}

TEST(FluidReferences, CreepingRiseIsSymmetricInTheBoxAndSlowerNearAWall) {
    CreepingRiseSetup s = bubble_in_box(10.0);
    const CreepingRise centre = creeping_rise(s);
    s.centre.z() = 0.3 * s.box_size.z();
    const CreepingRise low = creeping_rise(s);
    s.centre.z() = 0.7 * s.box_size.z();
    const CreepingRise high = creeping_rise(s);
    EXPECT_NEAR(low.speed, high.speed, 1e-9 * centre.speed);
    EXPECT_LT(low.speed, centre.speed);
    s.centre.z() = 0.5 * s.radius;
    EXPECT_THROW(creeping_rise(s), std::invalid_argument);
}

TEST(FluidReferences, ViscousDropModeTendsToLambAtWeakViscosity) {
    // ω̃₀ = ω₀R²/ν = 1e4: the root is within 1 % of Lamb's ω₀ and 5ν/R² (first correction
    // O(ω̃₀^{−1/2})).
    const double radius = 1.0, rho = 1.0, nu = 1.0, w0 = 1e4;
    const double sigma = w0 * w0 * rho / 8.0;  // ω₀² = 8σ/(ρR³) for l = 2
    const DropMode mode = viscous_drop_mode(2, sigma, radius, rho, nu);
    EXPECT_NEAR(mode.omega / w0, 1.0, 1e-3);
    EXPECT_NEAR(mode.decay_rate, 5.0, 0.05);
    const std::complex<double> root(-mode.decay_rate, mode.omega);
    EXPECT_LT(std::abs(viscous_drop_characteristic(2, w0, root)),
              1e-9 * std::abs(viscous_drop_characteristic(2, w0, root * 1.01)));
}

TEST(FluidReferences, ViscousDropStopsOscillatingAtTheCriticalOhnesorgeNumber) {
    // The l = 2 mode of a free drop is aperiodic above Oh = μ/sqrt(ρσR) ≈ 0.77 (Chandrasekhar),
    // i.e. below ω̃₀ = sqrt(8)/Oh ≈ 3.7.
    const auto mode_at = [](double w0) {
        return viscous_drop_mode(2, w0 * w0 / 8.0, 1.0, 1.0, 1.0);
    };
    EXPECT_GT(mode_at(3.8).omega, 0.0);
    EXPECT_THROW(mode_at(3.0), std::runtime_error);
    const DropMode b6 = mode_at(20.0);  // the B6 case: slower and less damped than Lamb
    EXPECT_NEAR(b6.omega / 20.0, 0.958, 0.001);
    EXPECT_NEAR(b6.decay_rate, 3.90, 0.01);
    EXPECT_LT(b6.decay_rate, 5.0);
}

TEST(FluidReferences, CapillaryWaveBetweenWallsTendsToTheDeepLimit) {
    const double k = 2.0 * PI;
    const double deep = std::sqrt(k * k * k / 2.0);
    EXPECT_NEAR(capillary_wave_omega(1.0, k, 1.0, 10.0, 1.0, 10.0), deep, 1e-12 * deep);
    // B4's layers of half a wavelength: coth(π) = 1.0037.
    EXPECT_NEAR(capillary_wave_omega(1.0, k, 1.0, 0.5, 1.0, 0.5) / deep,
                1.0 / std::sqrt(1.0 / std::tanh(PI)), 1e-12);
}

}  // namespace
}  // namespace meniscus::app
