#pragma once
/// \file The field in which the kept A4 curl-noise states (tests/data/regression/
/// curl_noise_a4_t*.ply) were recorded, shared by the collision regression tests and
/// bench_tracker so that both step the states in the field they came from.

#include "tracker/flows/curl_noise.h"

namespace meniscus::tracker::testing {

/// The three-octave planar field of scenes/flows/a4_curl_noise_multiscale_xi0.04.json.
inline CurlNoiseOptions recorded_a4_field() {
    CurlNoiseOptions noise;
    noise.planar = true;
    noise.octaves = 3;
    noise.rms_speed = 0.05;
    noise.base_wavelength = 0.5;
    noise.time_frequency = 1.0;
    return noise;
}

/// The recorded run's RK4 step (s).
inline constexpr double RECORDED_A4_DT = 0.05;

}  // namespace meniscus::tracker::testing
