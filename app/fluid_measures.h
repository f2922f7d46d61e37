#pragma once
/// \file Measuring two-phase runs (docs/validation.md part B; used by `meniscus validate` and the
/// scene physics tests): coupled runs sampled every step, exact volume moments and Fourier modes
/// of the mesh, least-squares fits of damped oscillations and of growth from rest. The analytic
/// references are in fluid_references.h.

#include "app/scene.h"
#include "coupling/simulation.h"
#include "tracker/mesh.h"

#include <Eigen/Core>

#include <functional>
#include <vector>

namespace meniscus::app {

// ---- Running a fluid scene step by step ------------------------------------------------------

/// What a sampled run recorded after every step (index 0: the initial state).
struct FluidRunRecord {
    std::vector<double> t;                ///< s
    std::vector<int> components;          ///< connected components of the surface
    std::vector<double> enclosed_volume;  ///< m³, volume enclosed by the surface
    std::vector<int> intersecting_pairs;  ///< exact check after each step (−1 = not checked)
    std::vector<double> max_speed;        ///< max |u| over the grid's faces, m/s
    long long steps = 0;
    bool completed = false;      ///< reached the end time
    bool pressure_converged = true;  ///< every pressure solve converged
    bool viscosity_converged = true;  ///< every viscosity solve converged
    int max_passes = 0;               ///< most viscous + pressure passes of a step
    double first_dt = 0.0;            ///< the first step's Δt, s
    int max_intersecting_pairs = 0;
    int merges = 0;
    int splits = 0;
    double wall_seconds = 0.0;
};

/// Steps `sim` until `end_time` (s), calling `sample` after every step (and once before the
/// first), recording the series above. Stops early (completed = false) after `max_steps` steps
/// when max_steps > 0.
FluidRunRecord run_sampled(coupling::Simulation& sim, double end_time,
                           const std::function<void(const coupling::Simulation&)>& sample,
                           long long max_steps = 0);

// ---- Measurements on the mesh ----------------------------------------------------------------

/// Volume enclosed by a closed mesh and its second moments about the centroid.
struct VolumeMoments {
    double volume = 0.0;                                 ///< m³
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< m
    /// Semi-axes (m) of the axis-aligned ellipsoid with the same volume moments:
    /// sqrt(5 ∫(x_d − c_d)² dV / V) along each axis d (exact for such an ellipsoid).
    Eigen::Vector3d semi_axes = Eigen::Vector3d::Zero();
};
/// Exact volume integrals over the closed mesh (signed tetrahedra from the origin).
VolumeMoments volume_moments(const tracker::SurfaceMesh& mesh);

/// Velocity (m/s) of the centroid of the volume a closed mesh encloses when its vertices move
/// with `velocities` (one per vertex slot, linear over each triangle):
/// (1/V) ∮ (x − c)(u·n) dA, exact for that piecewise-linear motion. For a drop or bubble this is
/// its translation speed (the centroid's motion, free of the remeshing noise of differencing
/// centroids). Throws std::invalid_argument when the sizes differ or the volume is not positive.
Eigen::Vector3d centroid_velocity(const tracker::SurfaceMesh& mesh,
                                  const std::vector<tracker::Vec3>& velocities);

/// Fourier mode of a surface: least-squares fit h = mean + a·cos(k(s − s0)) + b·sin(k(s − s0)).
struct ModeFit {
    double mean = 0.0;
    double cos_amplitude = 0.0;  ///< a
    double sin_amplitude = 0.0;  ///< b
};
/// Radius of a column along x about the axis (y, z) = axis_yz: fit over the live vertices with
/// x in [x_lo, x_hi] of r = mean + a cos(2π(x − x0)/λ) + b sin(…).
ModeFit column_radius_mode(const tracker::SurfaceMesh& mesh, const Eigen::Vector2d& axis_yz,
                           double x0, double wavelength, double x_lo, double x_hi);
/// Height of a wavy surface z(x): fit over the live vertices inside the box [lo, hi] with z above
/// z_min of z = mean + a cos(2π(x − x0)/λ) + b sin(…).
ModeFit surface_height_mode(const tracker::SurfaceMesh& mesh, const Eigen::Vector3d& lo,
                            const Eigen::Vector3d& hi, double z_min, double x0, double wavelength);

// ---- Fits --------------------------------------------------------------------------------------

/// y(t) ≈ offset + e^{−γt} (A cos ωt + B sin ωt), least squares: A, B and the offset are linear,
/// ω and γ are found by nested golden-section searches.
struct OscillationFit {
    double omega = 0.0;       ///< rad/s
    double decay_rate = 0.0;  ///< γ, 1/s (the amplitude decays as e^{−γt})
    double offset = 0.0;
    double cos_coefficient = 0.0;  ///< A
    double sin_coefficient = 0.0;  ///< B
    double amplitude = 0.0;        ///< sqrt(A² + B²)
    double rms_residual = 0.0;
};
/// Fits over all samples; ω is searched in [omega_min, omega_max], γ in [−omega_min, omega_min].
/// Throws std::invalid_argument with fewer than 6 samples or a bad range.
OscillationFit fit_damped_oscillation(const std::vector<double>& t, const std::vector<double>& y,
                                      double omega_min, double omega_max);

/// y(t) ≈ A e^{st} + B e^{−st} (the linear Rayleigh–Plateau amplitude from rest), least squares
/// relative to y; s searched in [rate_min, rate_max] by golden section.
struct GrowthFit {
    double rate = 0.0;  ///< s, 1/s
    double a_plus = 0.0;
    double a_minus = 0.0;
    double rms_relative_residual = 0.0;
};
GrowthFit fit_growth_from_rest(const std::vector<double>& t, const std::vector<double>& y,
                               double rate_min, double rate_max);

}  // namespace meniscus::app
