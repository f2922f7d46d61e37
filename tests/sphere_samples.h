#pragma once
/// \file Test helper shared by the level-set reference tests: points spread evenly over a sphere.

#include <Eigen/Core>

#include <cmath>
#include <vector>

namespace meniscus::testing {

/// `count` points on the sphere of `radius` around `center` (Fibonacci lattice: equal-area
/// bands in z, successive points turned by the golden angle).
inline std::vector<Eigen::Vector3d> fibonacci_sphere_points(const Eigen::Vector3d& center,
                                                           double radius, int count) {
    const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
    std::vector<Eigen::Vector3d> out;
    out.reserve(static_cast<size_t>(count));
    for (int i = 0; i < count; ++i) {
        const double z = 1.0 - 2.0 * (i + 0.5) / count;
        const double r = std::sqrt(1.0 - z * z);
        const double a = golden_angle * i;
        out.push_back(center + radius * Eigen::Vector3d(r * std::cos(a), r * std::sin(a), z));
    }
    return out;
}

}  // namespace meniscus::testing
