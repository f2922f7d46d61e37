#pragma once
/// \file Curl noise (Bridson, Hourihan and Nordenstam 2007; paper §4.3–4.4): a smooth,
/// pseudorandom, exactly divergence-free velocity field u = ∇ × ψ.
///
/// The potential is a seeded sum of random Fourier modes in octaves,
///
///     ψ(x, t) = Σₖ aₖ sin(ωₖ · x + φₖ + νₖ t),
///
/// so u = Σₖ cos(ωₖ · x + φₖ + νₖ t) (ωₖ × aₖ) and ∇u are evaluated analytically (no finite
/// differences): u is C^∞ and ∇ · u = 0 exactly (up to round-off). Octave o has wavelength
/// base_wavelength / lacunarityᵒ; wave-vector directions are uniform on the sphere, lengths
/// jittered by ±`WAVELENGTH_JITTER` around 2π/wavelength, phases uniform, and the velocity
/// amplitude of octave o scales with persistenceᵒ. All amplitudes are finally scaled so that the
/// spatial RMS of |u| is `rms_speed` (for distinct wave vectors the spatial mean of |u|² is
/// ½ Σₖ |ωₖ × aₖ|²).
///
/// Planar option (paper §4.3: "a random spline potential with zero x- and y-components"):
/// ψ = (0, 0, φ), hence u = (∂φ/∂y, −∂φ/∂x, 0): u_z ≡ 0, while φ still varies with z.
///
/// Reproducibility: modes are drawn from std::mt19937_64 (whose output sequence the C++ standard
/// fixes) with our own uniform and Gaussian transforms, so a seed gives the same field with any
/// standard library.

#include "tracker/flows/velocity_field.h"

#include <cstdint>
#include <vector>

namespace meniscus::tracker {

/// Options of CurlNoiseField.
struct CurlNoiseOptions {
    std::uint64_t seed = 1;
    int octaves = 3;               ///< ≥ 1
    int modes_per_octave = 24;     ///< ≥ 1
    double base_wavelength = 0.5;  ///< wavelength of the first octave (m, > 0)
    double lacunarity = 2.0;       ///< wavelength divisor per octave (≥ 1)
    double persistence = 0.5;      ///< velocity amplitude factor per octave (> 0)
    double rms_speed = 1.0;        ///< spatial RMS of |u| (m/s, > 0)
    bool planar = false;           ///< ψ = (0, 0, φ): motion in planes z = const
    double time_frequency = 0.0;   ///< νₖ uniform in [−f, f] (rad/s, ≥ 0; 0 = steady field)
    void validate() const;         ///< throws std::invalid_argument naming the field
};

/// Relative jitter of each mode's wave number around 2π / (octave wavelength).
constexpr double WAVELENGTH_JITTER = 0.25;

/// Divergence-free pseudorandom velocity field (m/s); see the file comment.
class CurlNoiseField final : public VelocityField {
public:
    /// Throws std::invalid_argument on invalid options.
    explicit CurlNoiseField(const CurlNoiseOptions& options = {});
    Vec3 velocity(const Vec3& x, double t) const override;
    /// The vector potential ψ(x, t) (m²/s).
    Vec3 potential(const Vec3& x, double t) const;
    /// Velocity gradient G with G(i, j) = ∂uᵢ/∂xⱼ (1/s); its trace is zero.
    Eigen::Matrix3d velocity_gradient(const Vec3& x, double t) const;
    const CurlNoiseOptions& options() const { return m_options; }

private:
    struct Mode {
        Vec3 wave_vector;         ///< ωₖ (rad/m)
        Vec3 amplitude;           ///< aₖ (m²/s)
        Vec3 curl_amplitude;      ///< ωₖ × aₖ (m/s)
        double phase;             ///< φₖ (rad)
        double angular_velocity;  ///< νₖ (rad/s)
    };
    CurlNoiseOptions m_options;
    std::vector<Mode> m_modes;
};

}  // namespace meniscus::tracker
