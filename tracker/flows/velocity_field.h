#pragma once
/// \file Analytic velocity fields for the paper's external-flow tests (§4.3) and other
/// interface-tracking benchmarks (rigid motion: Zalesak's notched sphere; a user's field given
/// as expressions), and vertex advection by classical RK4 through them.

#include "tracker/flows/expression.h"
#include "common/cancellation.h"
#include "tracker/mesh.h"

#include <array>
#include <map>
#include <string>
#include <vector>

namespace meniscus::tracker {

/// A velocity field u(x, t) in m/s.
class VelocityField {
public:
    virtual ~VelocityField() = default;
    virtual Vec3 velocity(const Vec3& x, double t) const = 0;
};

/// Enright's deformation test on the unit cube (Enright et al. 2002; paper §4.3):
/// u = 2 sin²(πx) sin(2πy) sin(2πz), v = −sin(2πx) sin²(πy) sin(2πz),
/// w = −sin(2πx) sin(2πy) sin²(πz), all multiplied by sin(2πt / period) (paper: period 3 —
/// the sin(2π t/3) modulation — so the flow reverses at t = period/2 and the surface returns
/// to its start at t = period).
class EnrightField final : public VelocityField {
public:
    /// Throws std::invalid_argument unless period > 0.
    explicit EnrightField(double period = 3.0);
    Vec3 velocity(const Vec3& x, double t) const override;

private:
    double m_period;
};

/// Options of RigidMotionField.
struct RigidMotionOptions {
    /// ω (rad/s): the rotation axis times the rate, right-handed (ω = (0, 0, 2π) turns once a
    /// second counter-clockwise seen from +z).
    Vec3 angular_velocity = Vec3::Zero();
    Vec3 center = Vec3::Zero();    ///< centre of rotation at t = 0 (m)
    Vec3 velocity = Vec3::Zero();  ///< translation (m/s); the centre of rotation moves with it
    void validate() const;         ///< throws std::invalid_argument naming the field
};

/// Rigid motion: translation at `velocity` and rotation at `angular_velocity` about a centre
/// that moves with the translation, c(t) = c₀ + v t:
///
///     u(x, t) = v + ω × (x − c(t)),
///
/// whose exact flow map is x(t) = c(t) + R(ω t)(x₀ − c₀) (R: rotation by |ω| t about ω/|ω|).
/// A body turns about its own centre while it translates; v = 0 is a rotation about a fixed
/// axis through c₀, ω = 0 a translation. Divergence-free: volumes are kept exactly.
class RigidMotionField final : public VelocityField {
public:
    /// Throws std::invalid_argument on invalid options.
    explicit RigidMotionField(const RigidMotionOptions& options);
    Vec3 velocity(const Vec3& x, double t) const override;
    /// Exact position at time t of the point that was at x0 at t = 0 (m).
    Vec3 position(const Vec3& x0, double t) const;
    const RigidMotionOptions& options() const { return m_options; }

private:
    RigidMotionOptions m_options;
};

/// Options of ExpressionField.
struct ExpressionFieldOptions {
    /// u, v, w (m/s) as expressions (tracker/flows/expression.h) in the variables x, y, z (m)
    /// and t (s), `pi` and the `constants`.
    std::array<std::string, 3> velocity = {"0", "0", "0"};
    /// Named numbers the expressions may use (names as for variables; not x, y, z, t, pi or a
    /// function name).
    std::map<std::string, double> constants;
    /// Compiles every expression: throws std::invalid_argument naming the field, e.g.
    /// "velocity/1: column 7: unknown name 'q' (...)" or "constants/x: ...".
    void validate() const;
};

/// A user's analytic velocity field u(x, t) given as one expression per component. Evaluation
/// throws std::domain_error naming the component, point and time where a component is not
/// finite (e.g. log of a negative number): advecting a surface by NaN is never meant.
class ExpressionField final : public VelocityField {
public:
    /// Throws std::invalid_argument as ExpressionFieldOptions::validate().
    explicit ExpressionField(const ExpressionFieldOptions& options);
    Vec3 velocity(const Vec3& x, double t) const override;

private:
    std::vector<Expression> m_components;
};

/// Displacements over [t, t + dt] of each live vertex of `mesh` by classical fourth-order
/// Runge–Kutta through `field` (dead slots get zero). The mesh is not modified. Throws
/// meniscus::Cancelled when `cancel` is requested (checked per vertex: a field of many modes
/// makes each evaluation long).
std::vector<Vec3> rk4_displacements(const SurfaceMesh& mesh, const VelocityField& field, double t,
                                    double dt, const CancellationToken& cancel = {});

}  // namespace meniscus::tracker
