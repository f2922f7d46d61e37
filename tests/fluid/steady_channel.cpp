#include "steady_channel.h"

#include <gtest/gtest.h>

namespace meniscus::fluid::testing {

FluidSolver steady_channel(FluidOptions options, int cells_across, int length, double speed) {
    options.phases = {CHANNEL_RHO, CHANNEL_RHO, CHANNEL_MU, CHANNEL_MU, 0.0};
    options.gravity = Eigen::Vector3d::Zero();
    options.pressure.iteration.tolerance = 1e-12;
    options.viscosity.iteration.tolerance = 1e-12;
    options.viscosity.iteration.max_iterations = 5000;
    options.viscous_pressure.max_passes = 30;
    options.viscous_pressure.pass_tolerance = 1e-10;
    const double dx = CHANNEL_HEIGHT / cells_across;
    FluidSolver solver(length * cells_across, cells_across, 1, dx, Eigen::Vector3d::Zero(),
                       options);
    const InterfaceInput interface(solver.grid());  // all liquid
    // The coupled scheme is steady at any Δt.
    const double dt = 0.5 * CHANNEL_HEIGHT * CHANNEL_HEIGHT * CHANNEL_RHO / CHANNEL_MU;
    bool steady = false;
    for (int step = 0; step < 400 && !steady; ++step) {
        const MacGrid before = solver.grid();
        const StepResult r = solver.step(dt, interface);
        EXPECT_TRUE(r.pressure.converged);
        EXPECT_TRUE(r.viscosity.converged);
        steady = step > 2 && max_velocity_difference(before, solver.grid()) <= 1e-10 * speed;
    }
    EXPECT_TRUE(steady) << "no steady state at " << cells_across << " cells across";
    return solver;
}

}  // namespace meniscus::fluid::testing
