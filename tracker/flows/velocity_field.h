#pragma once
/// \file Analytic velocity fields for the paper's external-flow tests (§4.3) and vertex
/// advection by classical RK4 through them.

#include "common/cancellation.h"
#include "tracker/mesh.h"

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

/// Displacements over [t, t + dt] of each live vertex of `mesh` by classical fourth-order
/// Runge–Kutta through `field` (dead slots get zero). The mesh is not modified. Throws
/// meniscus::Cancelled when `cancel` is requested (checked per vertex: a field of many modes
/// makes each evaluation long).
std::vector<Vec3> rk4_displacements(const SurfaceMesh& mesh, const VelocityField& field, double t,
                                    double dt, const CancellationToken& cancel = {});

}  // namespace meniscus::tracker
