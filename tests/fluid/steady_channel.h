#pragma once
/// \file A viscous liquid in a channel of `length` × H × one cell run to its steady state (tests
/// of moving walls and of inflow and outflow faces): Stokes flow, ν = 1 m²/s, the solves
/// converged to 1e-12, the coupled viscous-pressure scheme at Δt = ½ H²/ν.

#include "fluid/fluid_solver.h"

namespace meniscus::fluid::testing {

constexpr double CHANNEL_HEIGHT = 1.0;  ///< H, m
constexpr double CHANNEL_RHO = 1000.0;
constexpr double CHANNEL_MU = 1000.0;  ///< ν = 1 m²/s

/// Runs a one-phase liquid (every key of `options` but the phases, gravity, solver tolerances
/// and passes kept) in a box of `length`·n × n × 1 cells of H / n (n = `cells_across`) from rest
/// until no face velocity changes by more than 1e-10 `speed` in a step, at most 400 steps;
/// every solve and the steady state are checked with gtest expectations.
FluidSolver steady_channel(FluidOptions options, int cells_across, int length, double speed);

}  // namespace meniscus::fluid::testing
