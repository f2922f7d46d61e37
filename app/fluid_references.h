#pragma once
/// \file Analytic references of `meniscus validate` part B (docs/validation.md): inviscid Lamb
/// and Rayleigh rates, the capillary wave between walls, the exact normal modes of a viscous
/// drop, and the creeping rise of a bubble in a box with free-slip walls.

#include <Eigen/Core>

#include <complex>
#include <vector>

namespace meniscus::app {

/// Lamb's inviscid frequency (rad/s) of mode l of a drop of radius R (m), density ρ_i inside and
/// ρ_o outside: ω² = l(l+1)(l−1)(l+2) σ / (R³ [(l+1) ρ_i + l ρ_o]).
double lamb_omega(int l, double sigma, double radius, double rho_inside, double rho_outside);

/// Rayleigh's inviscid growth rate (1/s) of a column of radius R at wavenumber k:
/// ω² = σ/(ρR³) · x(1−x²) I₁(x)/I₀(x), x = kR (0 for x ≥ 1).
double rayleigh_plateau_rate(double sigma, double rho, double radius, double k);

/// Inviscid capillary-wave frequency (rad/s) of wavenumber k on a flat interface between a
/// layer of depth h₁ (density ρ₁) below and h₂ (ρ₂) above, both bounded by flat walls:
/// ω² = σk³ / (ρ₁ coth(k h₁) + ρ₂ coth(k h₂)). Infinite depths give Prosperetti's
/// ω₀² = σk³/(ρ₁+ρ₂).
double capillary_wave_omega(double sigma, double k, double rho_below, double depth_below,
                            double rho_above, double depth_above);

/// A normal mode of a drop: amplitude ∝ e^{λt}, λ = −decay_rate + i·omega.
struct DropMode {
    double omega = 0.0;       ///< angular frequency, rad/s
    double decay_rate = 0.0;  ///< 1/s
    int iterations = 0;       ///< root-finder iterations
};

/// The least damped oscillatory mode l (≥ 2) of a free viscous drop (void outside): radius R (m),
/// density ρ, kinematic viscosity ν (m²/s, > 0), surface tension σ. The root of the exact
/// characteristic equation of the linearised Navier–Stokes equations with a traction-free,
/// capillary surface (Reid 1960; Chandrasekhar 1961, §98), derived in docs/validation.md:
/// with λ̃ = λR²/ν, ω̃₀ = ω₀R²/ν (ω₀ Lamb's inviscid frequency of the free drop), x² = −λ̃ and
/// G = x j_{l−1}(x)/j_l(x) (spherical Bessel functions),
///   2(l²−1)[2lλ̃(G − l − 2) + ω̃₀²] = [λ̃² + 2l(l−1)λ̃ + ω̃₀²][2l(l+2) + λ̃ − 2G],
/// found by Newton's method from Lamb's weak-damping estimate λ̃ = −(l−1)(2l+1) + iω̃₀.
/// Throws std::invalid_argument for bad arguments and std::runtime_error when the mode is
/// overdamped (no oscillatory root near Lamb's).
DropMode viscous_drop_mode(int l, double sigma, double radius, double rho, double nu);

/// The residual of the characteristic equation above at λ̃ (dimensionless), for tests.
std::complex<double> viscous_drop_characteristic(int l, double omega0_tilde,
                                                 std::complex<double> lambda_tilde);

/// Creeping (Stokes) rise of a bubble or drop of radius a in a liquid filling a box whose six
/// walls are all free-slip.
struct CreepingRiseSetup {
    double radius = 0.0;           ///< a, m
    double rho_liquid = 0.0;       ///< kg/m³
    double rho_inside = 0.0;       ///< kg/m³ (the bubble's gas or the drop's liquid)
    double mu_liquid = 0.0;        ///< Pa·s (> 0)
    double mu_inside = 0.0;        ///< Pa·s (≥ 0)
    double gravity = 9.81;         ///< m/s², acting along −z
    Eigen::Vector3d box_size = Eigen::Vector3d::Zero();  ///< m, the box [0, size]
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();    ///< m, the sphere's centre in the box
};

/// The reference rise speed and its parts.
struct CreepingRise {
    /// Hadamard–Rybczynski speed in an unbounded liquid (m/s, positive up when the inside is
    /// lighter): U∞ = (2/3)(Δρ g a²/μ)(1+κ)/(2+3κ), κ = μ_inside/μ_liquid.
    double unbounded = 0.0;
    /// The walls' correction (m/s, usually negative): the z-velocity at the centre of the flow
    /// reflected by the walls — the images of the sphere's point force F = Δρ g (4/3)πa³
    /// across the free-slip walls, which are mirror planes, so the images form a periodic array
    /// (period Lx, Ly laterally and 2Lz vertically, with −F images at −z₀) whose Stokes flow is
    /// a Fourier series. Its regular part at the centre comes from Gaussian-smoothed sums with
    /// the smoothed self-flow removed, extrapolated to zero width (Richardson, two widths), plus
    /// Faxén's Laplacian term κa²/(2(3κ+2)) ∇²u for a drop. Neglected: the reflection of the
    /// sphere's own dipole, O((a/ℓ)³ κ/(1+κ)), and of its stresslet, O((a/ℓ)⁴).
    double wall_correction = 0.0;
    double speed = 0.0;  ///< unbounded + wall_correction, m/s
    /// −wall_correction / (F/(6πμa)), F = Δρ g (4/3)πa³: the k·a/ℓ of the expansion
    /// U = F/(6πμa φ(κ)) − k (a/ℓ) F/(6πμa) + … (k = 2.104 for a cylinder of radius ℓ).
    double wall_coefficient = 0.0;
};

/// See CreepingRise. Throws std::invalid_argument when the sphere does not fit the box or a
/// parameter is out of range.
CreepingRise creeping_rise(const CreepingRiseSetup& setup);

/// A point force along z in a periodic Stokes flow: position (m) and sign (+1 or −1).
struct PeriodicForce {
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    double sign = 1.0;
};

/// The regular part of the z-velocity at forces[0] (m/s): the Stokes flow of the periodic array
/// (cell `period`, m) of point forces ±`force` (N, along z) at `forces`, in a liquid of viscosity
/// `mu`, with zero mean flow (Hasimoto's convention: the k = 0 mode dropped), minus forces[0]'s
/// own unbounded Stokeslet. Computed from Gaussian-smoothed forces of widths s and s/2
/// (s = min(period)/`width_divisor`), each sum over wavevectors with k s ≤ 8.5 and the smoothed
/// self-flow F sqrt(π/2)/(3π² μ s) removed, Richardson-extrapolated to s → 0.
double periodic_stokeslet_regular_w(const Eigen::Vector3d& period,
                                    const std::vector<PeriodicForce>& forces, double force,
                                    double mu, double width_divisor = 12.0);

}  // namespace meniscus::app
