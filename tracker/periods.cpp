#include "tracker/periods.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

Eigen::Vector3d MeshPeriods::shift_towards(const Eigen::Vector3d& p,
                                           const Eigen::Vector3d& reference) const {
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    for (int a = 0; a < 3; ++a)
        if (wraps(a))
            s[a] = -length[a] * std::round((p[a] - reference[a]) / length[a]);
    return s;
}

Eigen::Vector3d MeshPeriods::wrap(const Eigen::Vector3d& p) const {
    Eigen::Vector3d q = p;
    for (int a = 0; a < 3; ++a)
        if (wraps(a)) {
            q[a] = origin[a] + (p[a] - origin[a]) -
                   length[a] * std::floor((p[a] - origin[a]) / length[a]);
            // Rounding can land exactly on origin + length; that point is the origin's image.
            if (q[a] >= origin[a] + length[a])
                q[a] = origin[a];
        }
    return q;
}

void MeshPeriods::validate() const {
    static const char* names[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(origin[a]))
            throw std::invalid_argument(std::string("periods/origin/") + names[a] +
                                        ": expected a finite number");
        if (!std::isfinite(length[a]) || length[a] < 0.0)
            throw std::invalid_argument(std::string("periods/length/") + names[a] +
                                        ": expected a finite number >= 0 (0: does not wrap)");
    }
}

}  // namespace meniscus::tracker
