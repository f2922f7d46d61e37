#pragma once
/// \file Time-step limits, reported separately so callers see which one binds.

#include "fluid/mac_grid.h"
#include "fluid/phases.h"

namespace meniscus::fluid {

/// Which limit produced TimeStepLimits::dt.
enum class BindingLimit { cfl, viscous, capillary, max_dt };

/// Options of the time-step choice.
struct TimeStepOptions {
    double cfl_number = 1.0;  ///< cells a fluid particle may cross per step (> 0)
    double max_dt = 1.0;      ///< upper bound on Δt in seconds, used when nothing else binds (> 0)

    /// Throws std::invalid_argument naming the field when out of range.
    void validate() const;
};

/// Each limit in seconds (+∞ when it does not apply) and the resulting Δt.
struct TimeStepLimits {
    /// cfl_number · dx / |u|_max with |u|_max = ‖(max|u|, max|v|, max|w|)‖₂ over all faces.
    double cfl = 0.0;
    /// Explicit viscous limit. Viscosity in fluid/ is fully implicit (backward Euler), so no
    /// explicit viscous part remains and this is +∞; kept so callers see every limit.
    double viscous = 0.0;
    /// Capillary (Brackbill) limit sqrt(ρ̄ dx³ / (2π σ)), ρ̄ = (ρ_l + ρ_g)/2 in two_phase and
    /// ρ_l/2 in free_surface (the void has no density); +∞ when σ = 0.
    double capillary = 0.0;
    double dt = 0.0;                              ///< min of the limits and max_dt, s
    BindingLimit binding = BindingLimit::max_dt;  ///< which one is the minimum
};

/// Computes the limits for the current face velocities of `grid`. Throws std::invalid_argument
/// when `options` or `phases` are invalid.
TimeStepLimits compute_time_step(const MacGrid& grid, const PhaseOptions& phases, FluidMode mode,
                                 const TimeStepOptions& options);

}  // namespace meniscus::fluid
