#include "fluid/fluid_solver.h"

#include <chrono>
#include <stdexcept>

#include "fluid/extrapolation.h"
#include "fluid/forces.h"

namespace meniscus::fluid {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

const FluidOptions& validated(const FluidOptions& options) {
    options.validate();
    return options;
}

}  // namespace

void FluidOptions::validate() const {
    phases.validate();
    if (mode != FluidMode::two_phase && mode != FluidMode::free_surface) {
        throw std::invalid_argument("FluidOptions.mode: unknown mode");
    }
    if (!gravity.allFinite()) {
        throw std::invalid_argument("FluidOptions.gravity must be finite (m/s^2)");
    }
    walls.validate();
    advection.validate();
    viscosity.validate();
    pressure.validate();
    time_step.validate();
    if (extrapolation_layers < 0) {
        throw std::invalid_argument("FluidOptions.extrapolation_layers must be non-negative");
    }
}

FluidSolver::FluidSolver(int nx, int ny, int nz, double dx, const Eigen::Vector3d& origin,
                         const FluidOptions& options)
    : m_options(validated(options)), m_grid(nx, ny, nz, dx, origin), m_pressure(nx, ny, nz, 0.0) {}

StepResult FluidSolver::step(double dt, const InterfaceInput& interface) {
    if (!(dt > 0.0)) {
        throw std::invalid_argument("FluidSolver::step: dt must be positive (s)");
    }
    interface.validate(m_grid);
    StepResult result;
    const Clock::time_point step_start = Clock::now();

    Clock::time_point start = Clock::now();
    advect_velocity(m_grid, dt, m_options.advection);
    m_grid.zero_wall_normal_velocity();
    result.timings.advection = seconds_since(start);

    // Viscosity before gravity: the body force is then balanced by the pressure of the same
    // projection, so a fluid at rest in hydrostatic equilibrium stays exactly at rest.
    start = Clock::now();
    result.viscosity = m_viscosity.solve(m_grid, interface, m_options.phases, m_options.mode,
                                         m_options.walls, dt, m_options.viscosity);
    result.timings.viscosity = seconds_since(start);

    start = Clock::now();
    apply_gravity(m_grid, m_options.gravity, dt);
    result.timings.forces = seconds_since(start);

    start = Clock::now();
    const ProjectionResult projection = project(m_grid, interface, m_options.phases, m_options.mode,
                                                dt, m_options.pressure, m_pressure);
    result.pressure = projection.solve;
    result.max_divergence = projection.max_divergence;
    result.timings.pressure = seconds_since(start);

    if (m_options.mode == FluidMode::free_surface) {
        start = Clock::now();
        extrapolate_velocity(m_grid, interface, m_options.extrapolation_layers);
        result.timings.extrapolation = seconds_since(start);
    }
    result.timings.total = seconds_since(step_start);
    return result;
}

TimeStepLimits FluidSolver::time_step_limits() const {
    return compute_time_step(m_grid, m_options.phases, m_options.mode, m_options.time_step);
}

}  // namespace meniscus::fluid
