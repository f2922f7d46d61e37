#include "app/fluid_references.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace meniscus::app {

namespace {

constexpr double PI = 3.14159265358979323846;
using Complex = std::complex<double>;

/// Newton's method on the drop's characteristic equation: steps, and the relative step size
/// at which it stops.
constexpr int MAX_NEWTON_STEPS = 100;
constexpr double NEWTON_TOLERANCE = 1e-13;
/// A root whose imaginary part is below this fraction of its modulus lies on the real axis.
constexpr double APERIODIC_FRACTION = 1e-9;
/// Relative step of the central difference that gives the Newton derivative.
constexpr double DERIVATIVE_STEP = 1e-7;
/// Gaussian-smoothed lattice sums keep wavevectors with k·s up to this (e^{−k²s²/2} < 2e-16).
constexpr double SMOOTHING_CUTOFF = 8.5;

/// Spherical Bessel functions j_{l−1}(x) and j_l(x) of complex argument by upward recurrence
/// from j_0 = sin x / x, j_1 = sin x / x² − cos x / x (stable for |x| > l, the case here).
std::pair<Complex, Complex> spherical_bessel_pair(int l, Complex x) {
    Complex previous = std::sin(x) / x;
    Complex current = std::sin(x) / (x * x) - std::cos(x) / x;
    for (int n = 1; n < l; ++n) {
        const Complex next = (2.0 * n + 1.0) / x * current - previous;
        previous = current;
        current = next;
    }
    return {previous, current};
}

}  // namespace

double lamb_omega(int l, double sigma, double radius, double rho_inside, double rho_outside) {
    const double num = l * (l + 1.0) * (l - 1.0) * (l + 2.0) * sigma;
    const double den = radius * radius * radius * ((l + 1.0) * rho_inside + l * rho_outside);
    return std::sqrt(num / den);
}

double rayleigh_plateau_rate(double sigma, double rho, double radius, double k) {
    const double x = k * radius;
    if (x >= 1.0)
        return 0.0;
    const double w2 = sigma / (rho * radius * radius * radius) * x * (1.0 - x * x) *
                      std::cyl_bessel_i(1.0, x) / std::cyl_bessel_i(0.0, x);
    return std::sqrt(w2);
}

double capillary_wave_omega(double sigma, double k, double rho_below, double depth_below,
                            double rho_above, double depth_above) {
    if (!(sigma >= 0.0 && k > 0.0 && rho_below > 0.0 && rho_above > 0.0 && depth_below > 0.0 &&
          depth_above > 0.0))
        throw std::invalid_argument("capillary_wave_omega: arguments out of range");
    const auto coth = [](double x) { return 1.0 / std::tanh(x); };
    return std::sqrt(sigma * k * k * k /
                     (rho_below * coth(k * depth_below) + rho_above * coth(k * depth_above)));
}

std::complex<double> viscous_drop_characteristic(int l, double omega0_tilde,
                                                 std::complex<double> lambda_tilde) {
    // x² = −λ̃; either root gives the same G (G is even in x).
    const Complex x = std::sqrt(-lambda_tilde);
    const auto [j_lm1, j_l] = spherical_bessel_pair(l, x);
    const Complex g = x * j_lm1 / j_l;
    const double ll = l;
    const double w2 = omega0_tilde * omega0_tilde;
    const Complex lhs = 2.0 * (ll * ll - 1.0) * (2.0 * ll * lambda_tilde * (g - ll - 2.0) + w2);
    const Complex rhs = (lambda_tilde * lambda_tilde + 2.0 * ll * (ll - 1.0) * lambda_tilde + w2) *
                        (2.0 * ll * (ll + 2.0) + lambda_tilde - 2.0 * g);
    return lhs - rhs;
}

DropMode viscous_drop_mode(int l, double sigma, double radius, double rho, double nu) {
    if (l < 2 || !(sigma > 0.0) || !(radius > 0.0) || !(rho > 0.0) || !(nu > 0.0))
        throw std::invalid_argument(
            "viscous_drop_mode: need l >= 2 and sigma, radius, rho, nu > 0");
    const double omega0 = lamb_omega(l, sigma, radius, rho, 0.0);
    const double time_scale = radius * radius / nu;  // λ = λ̃ / time_scale
    const double w0 = omega0 * time_scale;
    Complex lambda(-(l - 1.0) * (2.0 * l + 1.0), w0);
    DropMode mode;
    for (; mode.iterations < MAX_NEWTON_STEPS; ++mode.iterations) {
        const Complex f = viscous_drop_characteristic(l, w0, lambda);
        const Complex h = DERIVATIVE_STEP * std::max(1.0, std::abs(lambda));
        const Complex df = (viscous_drop_characteristic(l, w0, lambda + h) -
                            viscous_drop_characteristic(l, w0, lambda - h)) /
                           (2.0 * h);
        const Complex step = f / df;
        lambda -= step;
        if (std::abs(step) <= NEWTON_TOLERANCE * std::abs(lambda))
            break;
    }
    // A root on the real axis (to round-off) is an aperiodic mode: the drop is overdamped.
    if (mode.iterations == MAX_NEWTON_STEPS ||
        !(lambda.imag() > APERIODIC_FRACTION * std::abs(lambda)) || !(lambda.real() < 0.0))
        throw std::runtime_error("viscous_drop_mode: no oscillatory root near Lamb's for l = " +
                                 std::to_string(l) + " (omega0 R^2/nu = " + std::to_string(w0) +
                                 ")");
    mode.omega = lambda.imag() / time_scale;
    mode.decay_rate = -lambda.real() / time_scale;
    return mode;
}

double periodic_stokeslet_regular_w(const Eigen::Vector3d& period,
                                    const std::vector<PeriodicForce>& forces, double force,
                                    double mu, double width_divisor) {
    if (forces.empty() || !(period.minCoeff() > 0.0) || !(mu > 0.0) || !(width_divisor > 1.0))
        throw std::invalid_argument("periodic_stokeslet_regular_w: arguments out of range");
    const double volume = period.prod();
    const auto smoothed = [&](double s) {
        const double k_max = SMOOTHING_CUTOFF / s;
        Eigen::Vector3i n_max;
        for (int d = 0; d < 3; ++d)
            n_max[d] = static_cast<int>(std::ceil(k_max * period[d] / (2.0 * PI)));
        double sum = 0.0;
        for (int a = -n_max[0]; a <= n_max[0]; ++a)
            for (int b = -n_max[1]; b <= n_max[1]; ++b)
                for (int c = -n_max[2]; c <= n_max[2]; ++c) {
                    if (a == 0 && b == 0 && c == 0)
                        continue;
                    const Eigen::Vector3d k(2.0 * PI * a / period.x(), 2.0 * PI * b / period.y(),
                                            2.0 * PI * c / period.z());
                    const double k2 = k.squaredNorm();
                    if (k2 > k_max * k_max)
                        continue;
                    double phase = 0.0;  // Re Σ_s sign_s e^{i k·(x₀ − x_s)}
                    for (const PeriodicForce& f : forces)
                        phase += f.sign * std::cos(k.dot(forces[0].position - f.position));
                    sum += (1.0 - k.z() * k.z() / k2) / k2 * std::exp(-0.5 * k2 * s * s) * phase;
                }
        const double self = std::sqrt(0.5 * PI) / (3.0 * PI * PI * s);
        return force / mu * (sum / volume - forces[0].sign * self);
    };
    const double s = period.minCoeff() / width_divisor;
    return (4.0 * smoothed(0.5 * s) - smoothed(s)) / 3.0;
}

CreepingRise creeping_rise(const CreepingRiseSetup& setup) {
    const double a = setup.radius;
    const Eigen::Vector3d& box = setup.box_size;
    const Eigen::Vector3d& c = setup.centre;
    if (!(a > 0.0) || !(setup.mu_liquid > 0.0) || !(setup.mu_inside >= 0.0) ||
        !(setup.rho_liquid > 0.0) || !(setup.rho_inside >= 0.0))
        throw std::invalid_argument("creeping_rise: radius, densities or viscosities out of range");
    for (int d = 0; d < 3; ++d)
        if (!(c[d] - a > 0.0 && c[d] + a < box[d]))
            throw std::invalid_argument("creeping_rise: the sphere does not fit inside the box");
    const double kappa = setup.mu_inside / setup.mu_liquid;
    const double delta_rho = setup.rho_liquid - setup.rho_inside;
    CreepingRise rise;
    rise.unbounded = 2.0 / 3.0 * delta_rho * setup.gravity * a * a / setup.mu_liquid *
                     (1.0 + kappa) / (2.0 + 3.0 * kappa);
    // The force the sphere exerts on the liquid: its buoyancy minus its weight, along +z.
    const double force = delta_rho * setup.gravity * 4.0 / 3.0 * PI * a * a * a;
    // Mirror images across the six free-slip walls: a periodic cell of twice the box with the
    // sphere at (x, y, z) and its images at (±x, ±y, ±z); a z-mirror reverses the force.
    std::vector<PeriodicForce> forces;
    for (int sx : {1, -1})
        for (int sy : {1, -1})
            for (int sz : {1, -1})
                forces.push_back({Eigen::Vector3d(sx * c.x(), sy * c.y(), sz * c.z()),
                                  static_cast<double>(sz)});
    rise.wall_correction = periodic_stokeslet_regular_w(2.0 * box, forces, force,
                                                        setup.mu_liquid);
    rise.speed = rise.unbounded + rise.wall_correction;
    rise.wall_coefficient = -rise.wall_correction * 6.0 * PI * setup.mu_liquid * a / force;
    return rise;
}

}  // namespace meniscus::app
