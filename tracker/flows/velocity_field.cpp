#include "tracker/flows/velocity_field.h"

#include <Eigen/Geometry>

#include <cmath>
#include <sstream>
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

namespace {

void check_finite(const Vec3& v, const char* field) {
    if (!v.allFinite())
        throw std::invalid_argument(std::string(field) + ": expected finite numbers");
}

/// The variables of ExpressionField's expressions, in the order evaluate() receives them.
const std::vector<std::string> FIELD_VARIABLES = {"x", "y", "z", "t"};

std::vector<std::pair<std::string, double>> constant_list(const ExpressionFieldOptions& o) {
    return {o.constants.begin(), o.constants.end()};
}

}  // namespace

void RigidMotionOptions::validate() const {
    check_finite(angular_velocity, "angular_velocity");
    check_finite(center, "center");
    check_finite(velocity, "velocity");
}

RigidMotionField::RigidMotionField(const RigidMotionOptions& options) : m_options(options) {
    m_options.validate();
}

Vec3 RigidMotionField::velocity(const Vec3& x, double t) const {
    const Vec3 center = m_options.center + t * m_options.velocity;
    return m_options.velocity + m_options.angular_velocity.cross(x - center);
}

Vec3 RigidMotionField::position(const Vec3& x0, double t) const {
    const Vec3 center = m_options.center + t * m_options.velocity;
    const double rate = m_options.angular_velocity.norm();
    if (rate == 0.0)
        return x0 + t * m_options.velocity;
    const Eigen::AngleAxisd rotation(rate * t, m_options.angular_velocity / rate);
    return center + rotation * (x0 - m_options.center);
}

void ExpressionFieldOptions::validate() const {
    const auto constants_list = constant_list(*this);
    // Constants first: a bad name is reported at its own key.
    for (const auto& [name, value] : constants) {
        try {
            Expression("0", FIELD_VARIABLES, {{name, value}});
        } catch (const std::invalid_argument& e) {
            std::string what = e.what();
            // "constant 'x': problem" → "constants/x: problem"
            const auto colon = what.find("': ");
            throw std::invalid_argument(
                "constants/" + name + ": " +
                (colon == std::string::npos ? what : what.substr(colon + 3)));
        }
    }
    for (size_t i = 0; i < velocity.size(); ++i) {
        try {
            Expression(velocity[i], FIELD_VARIABLES, constants_list);
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument("velocity/" + std::to_string(i) + ": " + e.what());
        }
    }
}

ExpressionField::ExpressionField(const ExpressionFieldOptions& options) {
    options.validate();
    const auto constants = constant_list(options);
    for (const std::string& text : options.velocity)
        m_components.emplace_back(text, FIELD_VARIABLES, constants);
}

Vec3 ExpressionField::velocity(const Vec3& x, double t) const {
    const double values[4] = {x.x(), x.y(), x.z(), t};
    Vec3 u;
    for (int i = 0; i < 3; ++i) {
        u[i] = m_components[static_cast<size_t>(i)].evaluate(values);
        if (!std::isfinite(u[i])) {
            std::ostringstream s;
            s.precision(9);
            s << "velocity/" << i << " (\"" << m_components[static_cast<size_t>(i)].text()
              << "\") is " << u[i] << " at x = (" << x.x() << ", " << x.y() << ", " << x.z()
              << "), t = " << t;
            throw std::domain_error(s.str());
        }
    }
    return u;
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
