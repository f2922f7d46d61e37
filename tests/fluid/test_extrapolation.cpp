// Velocity extrapolation into the void (free-surface mode).
#include <gtest/gtest.h>

#include <cmath>

#include "fluid/extrapolation.h"
#include "fluid/fluid_solver.h"

namespace meniscus::fluid {
namespace {

TEST(FluidExtrapolation, ConstantVelocityIsExtendedExactlyAndFarFacesAreZeroed) {
    const int n = 12;
    MacGrid grid(n, n, n, 0.1);
    InterfaceInput interface(grid);
    for (int k = 0; k < n; ++k) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                interface.phi(i, j, k) = grid.cell_centre(i, j, k).z() - 0.35;  // liquid below
            }
        }
    }
    // Liquid faces carry a constant velocity, void faces garbage.
    for (int axis = 0; axis < 3; ++axis) {
        grid.velocity(axis).fill(99.0);
    }
    for (int k = 0; k < n; ++k) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i <= n; ++i) {
                const bool wet = interface.phi(std::min(i, n - 1), j, k) < 0.0 ||
                                 interface.phi(std::max(i - 1, 0), j, k) < 0.0;
                if (wet) {
                    grid.u()(i, j, k) = 0.25;
                }
            }
        }
    }
    grid.zero_wall_normal_velocity();
    const int layers = 3;
    extrapolate_velocity(grid, interface, layers);
    // Liquid cells are k = 0..2 (φ = 0 at k = 3 counts as gas); u faces at rows k ≤ 2 + layers get
    // the constant; the rows above are zeroed.
    for (int k = 0; k < n; ++k) {
        for (int j = 0; j < n; ++j) {
            for (int i = 1; i < n; ++i) {
                const double expected = k <= 2 + layers ? 0.25 : 0.0;
                ASSERT_DOUBLE_EQ(grid.u()(i, j, k), expected) << i << " " << j << " " << k;
            }
            EXPECT_EQ(grid.u()(0, j, k), 0.0);  // wall faces untouched
        }
    }
}

TEST(FluidExtrapolation, FreeSurfaceStepOfATiltedPoolIsDivergenceFreeInTheLiquid) {
    // A tilted pool starts to slosh: the liquid velocity after each step is divergence-free and
    // the void next to the surface carries extrapolated (non-zero) velocity.
    FluidOptions options;
    options.mode = FluidMode::free_surface;
    options.pressure.iteration.tolerance = 1e-10;
    const int n = 16;
    FluidSolver solver(n, n, n, 1.0 / n, Eigen::Vector3d::Zero(), options);
    InterfaceInput interface(solver.grid());
    for (int k = 0; k < n; ++k) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                const Eigen::Vector3d x = solver.grid().cell_centre(i, j, k);
                interface.phi(i, j, k) = (x.z() - 0.3 - 0.3 * x.x()) / std::sqrt(1.09);
            }
        }
    }
    for (int step = 0; step < 3; ++step) {
        const StepResult result = solver.step(0.01, interface);
        ASSERT_TRUE(result.pressure.converged);
        EXPECT_LT(result.max_divergence, 1e-6);
    }
    EXPECT_GT(solver.grid().max_abs_velocity().x(), 1e-3);  // it does slosh
    // Just above the surface in the middle of the pool, w is extrapolated from the liquid.
    const int i = n / 2, j = n / 2;
    int k_surface = 0;
    while (interface.phi(i, j, k_surface) < 0.0) {
        ++k_surface;
    }
    EXPECT_NE(solver.grid().w()(i, j, k_surface + 1), 0.0);
}

}  // namespace
}  // namespace meniscus::fluid
