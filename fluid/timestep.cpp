#include "fluid/timestep.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace meniscus::fluid {

namespace {

constexpr double PI = 3.14159265358979323846;
constexpr double HALF = 0.5;

}  // namespace

void TimeStepOptions::validate() const {
    if (!(cfl_number > 0.0) || !std::isfinite(cfl_number)) {
        throw std::invalid_argument("TimeStepOptions.cfl_number must be positive");
    }
    if (!(max_dt > 0.0) || !std::isfinite(max_dt)) {
        throw std::invalid_argument("TimeStepOptions.max_dt must be positive (s)");
    }
}

TimeStepLimits compute_time_step(const MacGrid& grid, const PhaseOptions& phases, FluidMode mode,
                                 const TimeStepOptions& options) {
    options.validate();
    phases.validate();
    constexpr double INF = std::numeric_limits<double>::infinity();
    TimeStepLimits limits;
    const double speed = grid.max_abs_velocity().norm();
    const double dx = grid.dx();
    limits.cfl = speed > 0.0 ? options.cfl_number * dx / speed : INF;
    limits.viscous = INF;
    const double rho_mean =
        HALF * (phases.rho_liquid + (mode == FluidMode::two_phase ? phases.rho_gas : 0.0));
    limits.capillary =
        phases.sigma > 0.0 ? std::sqrt(rho_mean * dx * dx * dx / (2.0 * PI * phases.sigma)) : INF;
    limits.dt = options.max_dt;
    limits.binding = BindingLimit::max_dt;
    if (limits.cfl < limits.dt) {
        limits.dt = limits.cfl;
        limits.binding = BindingLimit::cfl;
    }
    if (limits.viscous < limits.dt) {
        limits.dt = limits.viscous;
        limits.binding = BindingLimit::viscous;
    }
    if (limits.capillary < limits.dt) {
        limits.dt = limits.capillary;
        limits.binding = BindingLimit::capillary;
    }
    return limits;
}

}  // namespace meniscus::fluid
