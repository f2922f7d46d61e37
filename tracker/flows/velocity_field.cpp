#include "tracker/flows/velocity_field.h"

#include <cmath>
#include <stdexcept>

namespace meniscus::tracker {

EnrightField::EnrightField(double period) : m_period(period) {
    if (!(period > 0.0) || !std::isfinite(period))
        throw std::invalid_argument("period: expected a number > 0");
}

Vec3 EnrightField::velocity(const Vec3& p, double t) const {
    const double pi = M_PI;
    const double sx = std::sin(pi * p.x()), sy = std::sin(pi * p.y()), sz = std::sin(pi * p.z());
    const double s2x = std::sin(2 * pi * p.x()), s2y = std::sin(2 * pi * p.y()),
                 s2z = std::sin(2 * pi * p.z());
    const double modulation = std::sin(2 * pi * t / m_period);
    return modulation * Vec3(2 * sx * sx * s2y * s2z, -s2x * sy * sy * s2z, -s2x * s2y * sz * sz);
}

std::vector<Vec3> rk4_displacements(const SurfaceMesh& mesh, const VelocityField& field, double t,
                                    double dt, const CancellationToken& cancel) {
    std::vector<Vec3> d(static_cast<size_t>(mesh.num_vertices()), Vec3::Zero());
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        cancel.throw_if_requested("the velocity field");
        const Vec3 x = mesh.position(vi);
        const Vec3 k1 = field.velocity(x, t);
        const Vec3 k2 = field.velocity(x + 0.5 * dt * k1, t + 0.5 * dt);
        const Vec3 k3 = field.velocity(x + 0.5 * dt * k2, t + 0.5 * dt);
        const Vec3 k4 = field.velocity(x + dt * k3, t + dt);
        d[static_cast<size_t>(vi)] = dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    return d;
}

}  // namespace meniscus::tracker
