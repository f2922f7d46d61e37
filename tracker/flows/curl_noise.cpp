#include "tracker/flows/curl_noise.h"

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

namespace {

constexpr double TWO_PI = 2.0 * M_PI;
/// 2⁻⁵³: maps the top 53 bits of a 64-bit draw to [0, 1).
constexpr double UNIT_53 = 1.0 / 9007199254740992.0;

/// Uniform and Gaussian draws with transforms fixed here (std:: distributions are not
/// specified bit-for-bit across standard libraries).
class Draws {
public:
    explicit Draws(std::uint64_t seed) : m_engine(seed) {}
    /// Uniform in [0, 1).
    double uniform() { return static_cast<double>(m_engine() >> 11) * UNIT_53; }
    /// Standard normal by Box–Muller (one value per call).
    double gaussian() {
        const double u1 = 1.0 - uniform();  // (0, 1]
        const double u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(TWO_PI * u2);
    }
    /// Uniform direction on the unit sphere.
    Vec3 direction() {
        while (true) {
            const Vec3 g(gaussian(), gaussian(), gaussian());
            const double n = g.norm();
            if (n > 0.0)
                return g / n;
        }
    }

private:
    std::mt19937_64 m_engine;
};

}  // namespace

void CurlNoiseOptions::validate() const {
    auto fail = [](const std::string& field, const std::string& expected) {
        throw std::invalid_argument(field + ": expected " + expected);
    };
    if (octaves < 1)
        fail("octaves", "an integer >= 1");
    if (modes_per_octave < 1)
        fail("modes_per_octave", "an integer >= 1");
    if (!(base_wavelength > 0.0) || !std::isfinite(base_wavelength))
        fail("base_wavelength", "a finite number > 0 (metres)");
    if (!(lacunarity >= 1.0) || !std::isfinite(lacunarity))
        fail("lacunarity", "a finite number >= 1");
    if (!(persistence > 0.0) || !std::isfinite(persistence))
        fail("persistence", "a finite number > 0");
    if (!(rms_speed > 0.0) || !std::isfinite(rms_speed))
        fail("rms_speed", "a finite number > 0 (m/s)");
    if (!(time_frequency >= 0.0) || !std::isfinite(time_frequency))
        fail("time_frequency", "a finite number >= 0 (rad/s)");
}

CurlNoiseField::CurlNoiseField(const CurlNoiseOptions& options) : m_options(options) {
    options.validate();
    Draws draws(options.seed);
    double wavelength = options.base_wavelength;
    double octave_amplitude = 1.0;
    double mean_square_speed = 0.0;
    for (int o = 0; o < options.octaves; ++o) {
        for (int m = 0; m < options.modes_per_octave; ++m) {
            Mode mode{};
            const double jitter = 1.0 + WAVELENGTH_JITTER * (2.0 * draws.uniform() - 1.0);
            const double wave_number = TWO_PI / wavelength * jitter;
            mode.wave_vector = wave_number * draws.direction();
            // |ω × a| ~ octave_amplitude: the potential scales with 1 / |ω|.
            const Vec3 a_direction =
                options.planar ? Vec3(0.0, 0.0, draws.gaussian()) : draws.direction();
            mode.amplitude = octave_amplitude / wave_number * a_direction;
            mode.phase = TWO_PI * draws.uniform();
            mode.angular_velocity = options.time_frequency * (2.0 * draws.uniform() - 1.0);
            mode.curl_amplitude = mode.wave_vector.cross(mode.amplitude);
            mean_square_speed += 0.5 * mode.curl_amplitude.squaredNorm();
            m_modes.push_back(mode);
        }
        wavelength /= options.lacunarity;
        octave_amplitude *= options.persistence;
    }
    const double scale =
        mean_square_speed > 0.0 ? options.rms_speed / std::sqrt(mean_square_speed) : 0.0;
    for (Mode& mode : m_modes) {
        mode.amplitude *= scale;
        mode.curl_amplitude *= scale;
    }
}

Vec3 CurlNoiseField::velocity(const Vec3& x, double t) const {
    Vec3 u = Vec3::Zero();
    for (const Mode& mode : m_modes)
        u += std::cos(mode.wave_vector.dot(x) + mode.phase + mode.angular_velocity * t) *
             mode.curl_amplitude;
    return u;
}

Vec3 CurlNoiseField::potential(const Vec3& x, double t) const {
    Vec3 psi = Vec3::Zero();
    for (const Mode& mode : m_modes)
        psi += std::sin(mode.wave_vector.dot(x) + mode.phase + mode.angular_velocity * t) *
               mode.amplitude;
    return psi;
}

Eigen::Matrix3d CurlNoiseField::velocity_gradient(const Vec3& x, double t) const {
    Eigen::Matrix3d g = Eigen::Matrix3d::Zero();
    for (const Mode& mode : m_modes)
        g -= std::sin(mode.wave_vector.dot(x) + mode.phase + mode.angular_velocity * t) *
             (mode.curl_amplitude * mode.wave_vector.transpose());
    return g;
}

}  // namespace meniscus::tracker
