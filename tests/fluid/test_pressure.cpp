// Pressure projection: hydrostatics, the σκ jump and divergence-free output, for every backend;
// the options and the gradient and divergence helpers. The solvers themselves:
// test_pressure_solvers.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "fluid/pressure.h"
#include "pressure_test_support.h"

namespace meniscus::fluid {
namespace {

using pressure_test::add_gravity;
using pressure_test::GRAVITY;
using pressure_test::tight_options;

/// Flat interface at height h: liquid below (φ = z − h < 0).
InterfaceInput flat_interface(const MacGrid& grid, double h, double kappa) {
    InterfaceInput interface(grid);
    for (int k = 0; k < grid.nz(); ++k) {
        for (int j = 0; j < grid.ny(); ++j) {
            for (int i = 0; i < grid.nx(); ++i) {
                interface.phi(i, j, k) = grid.cell_centre(i, j, k).z() - h;
            }
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        interface.kappa(axis).fill(kappa);
    }
    return interface;
}

/// Exact hydrostatic pressure up to a constant: liquid below h, gas above.
double hydrostatic(double z, double h, double rho_liquid, double rho_gas) {
    return z < h ? -rho_liquid * GRAVITY * z
                 : -rho_liquid * GRAVITY * h - rho_gas * GRAVITY * (z - h);
}

double max_velocity(const MacGrid& grid) {
    return grid.max_abs_velocity().maxCoeff();
}

class FluidPressureSolverTest : public ::testing::TestWithParam<PressureSolver> {};

TEST_P(FluidPressureSolverTest, TwoPhaseStillWaterIsHydrostaticAtDensityRatio1000) {
    const int n = 16;
    MacGrid grid(n, n, n, 1.0 / n);
    PhaseOptions phases;
    phases.rho_liquid = 1000.0;
    phases.rho_gas = 1.0;
    phases.sigma = 0.0;
    const double h = 0.53;  // not on a cell centre or a face
    const InterfaceInput interface = flat_interface(grid, h, 0.0);
    const double dt = 1e-2;
    add_gravity(grid, dt);
    Array3<double> pressure;
    const ProjectionResult result = project(grid, interface, phases, FluidMode::two_phase, dt,
                                            tight_options(GetParam()), pressure);
    ASSERT_TRUE(result.solve.converged) << "residual " << result.solve.residual;
    // Still water stays still.
    EXPECT_LT(max_velocity(grid), 1e-7 * GRAVITY * dt);
    // Pressure is the exact hydrostatic profile up to a constant.
    double offset = pressure(0, 0, 0) - hydrostatic(grid.cell_centre(0, 0, 0).z(), h, 1000.0, 1.0);
    double max_error = 0.0;
    for (int k = 0; k < n; ++k) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                const double exact = hydrostatic(grid.cell_centre(i, j, k).z(), h, 1000.0, 1.0);
                max_error = std::max(max_error, std::abs(pressure(i, j, k) - offset - exact));
            }
        }
    }
    const double scale = phases.rho_liquid * GRAVITY * h;
    std::printf("two-phase hydrostatic: max |p - p_exact| = %.3e Pa of %.1f Pa, max |u| = %.3e\n",
                max_error, scale, max_velocity(grid));
    EXPECT_LT(max_error, 1e-7 * scale) << "max hydrostatic error " << max_error << " Pa";
}

TEST_P(FluidPressureSolverTest, FreeSurfaceStillWaterIsHydrostatic) {
    const int n = 16;
    MacGrid grid(n, n, n, 1.0 / n);
    PhaseOptions phases;
    phases.sigma = 0.0;
    const double h = 0.61;
    const InterfaceInput interface = flat_interface(grid, h, 0.0);
    const double dt = 1e-2;
    add_gravity(grid, dt);
    Array3<double> pressure;
    const ProjectionResult result = project(grid, interface, phases, FluidMode::free_surface, dt,
                                            tight_options(GetParam()), pressure);
    ASSERT_TRUE(result.solve.converged);
    // Liquid faces are still; gas faces (not solved) keep u*.
    double max_liquid_w = 0.0;
    double max_error = 0.0;
    for (int k = 0; k < n; ++k) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                const double z = grid.cell_centre(i, j, k).z();
                if (z < h) {
                    max_liquid_w = std::max({max_liquid_w, std::abs(grid.w()(i, j, k)),
                                             std::abs(grid.w()(i, j, k + 1))});
                    const double exact = phases.rho_liquid * GRAVITY * (h - z);
                    max_error = std::max(max_error, std::abs(pressure(i, j, k) - exact));
                }
            }
        }
    }
    std::printf("free-surface hydrostatic: max |p - p_exact| = %.3e Pa, max liquid |w| = %.3e\n",
                max_error, max_liquid_w);
    EXPECT_LT(max_liquid_w, 1e-7 * GRAVITY * dt);
    EXPECT_LT(max_error, 1e-7 * phases.rho_liquid * GRAVITY * h) << max_error << " Pa";
}

TEST_P(FluidPressureSolverTest, FlatInterfaceWithConstantCurvatureJumpsBySigmaKappa) {
    const int n = 16;
    MacGrid grid(n, n, n, 1.0 / n);
    PhaseOptions phases;
    phases.rho_liquid = 1000.0;
    phases.rho_gas = 1.0;
    phases.sigma = 0.07;
    const double kappa = 8.0;
    const double h = 0.47;
    const InterfaceInput interface = flat_interface(grid, h, kappa);
    for (FluidMode mode : {FluidMode::two_phase, FluidMode::free_surface}) {
        grid.w().fill(0.0);
        Array3<double> pressure;
        const ProjectionResult result =
            project(grid, interface, phases, mode, 1e-3, tight_options(GetParam()), pressure);
        ASSERT_TRUE(result.solve.converged);
        EXPECT_LT(max_velocity(grid), 1e-12);
        double max_error = 0.0;
        for (int k = 0; k < n; ++k) {
            for (int j = 0; j < n; ++j) {
                for (int i = 0; i < n; ++i) {
                    const bool liquid = interface.phi(i, j, k) < 0.0;
                    if (mode == FluidMode::two_phase && liquid) {
                        // p_liquid − p_gas = σκ between any liquid cell and the gas above it.
                        const double jump = pressure(i, j, k) - pressure(i, j, n - 1);
                        max_error = std::max(max_error, std::abs(jump - phases.sigma * kappa));
                    } else if (mode == FluidMode::free_surface && liquid) {
                        max_error =
                            std::max(max_error, std::abs(pressure(i, j, k) - phases.sigma * kappa));
                    }
                }
            }
        }
        std::printf("%s jump: max |[p] - sigma kappa| = %.3e Pa of %.3f Pa\n",
                    mode == FluidMode::two_phase ? "two-phase" : "free-surface", max_error,
                    phases.sigma * kappa);
        EXPECT_LT(max_error, 1e-8 * phases.sigma * kappa)
            << (mode == FluidMode::two_phase ? "two_phase" : "free_surface");
    }
}

TEST_P(FluidPressureSolverTest, ProjectedVelocityIsDivergenceFreeAroundAGasBubble) {
    const int n = 24;
    MacGrid grid(n, n, n, 1.0 / n);
    PhaseOptions phases;
    phases.rho_liquid = 1000.0;
    phases.rho_gas = 1.0;
    const Eigen::Vector3d centre(0.5, 0.45, 0.52);
    const double radius = 0.25;
    InterfaceInput interface(grid);
    for (int k = 0; k < n; ++k) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                interface.phi(i, j, k) = radius - (grid.cell_centre(i, j, k) - centre).norm();
            }
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        interface.kappa(axis).fill(-2.0 / radius);  // gas bubble: the liquid side is concave
    }
    for (FluidMode mode : {FluidMode::two_phase, FluidMode::free_surface}) {
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> random(-1.0, 1.0);
        for (int axis = 0; axis < 3; ++axis) {
            for (double& value : grid.velocity(axis).storage()) {
                value = random(rng);
            }
        }
        grid.zero_wall_normal_velocity();
        const double before = max_fluid_divergence(grid, interface, mode);
        PressureOptions options = tight_options(GetParam());
        options.iteration.tolerance = 1e-9;
        Array3<double> pressure;
        const ProjectionResult result =
            project(grid, interface, phases, mode, 1e-3, options, pressure);
        ASSERT_TRUE(result.solve.converged);
        std::printf("%s divergence: max |div u| %.3e -> %.3e 1/s in %d iterations\n",
                    mode == FluidMode::two_phase ? "two-phase" : "free-surface", before,
                    result.max_divergence, result.solve.iterations);
        EXPECT_LT(result.max_divergence, 1e-6 * before)
            << "before " << before << " after " << result.max_divergence;
    }
}

TEST_P(FluidPressureSolverTest, AllLiquidClosedBoxIsAConsistentSingularSystem) {
    // No interface and closed walls: a pure-Neumann system whose right-hand side is compatible.
    const int n = 12;
    MacGrid grid(n, n, n, 1.0 / n);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> random(-1.0, 1.0);
    for (int axis = 0; axis < 3; ++axis) {
        for (double& value : grid.velocity(axis).storage()) {
            value = random(rng);
        }
    }
    grid.zero_wall_normal_velocity();
    const InterfaceInput interface(grid);
    for (FluidMode mode : {FluidMode::two_phase, FluidMode::free_surface}) {
        MacGrid projected = grid;
        Array3<double> pressure;
        const ProjectionResult result = project(projected, interface, PhaseOptions{}, mode, 0.01,
                                                tight_options(GetParam()), pressure);
        ASSERT_TRUE(result.solve.converged);
        EXPECT_LT(result.max_divergence, 1e-7);
        double mean = 0.0;
        for (double p : pressure.storage()) {
            mean += p;
        }
        EXPECT_NEAR(mean / pressure.size(), 0.0, 1e-9);
    }
}

INSTANTIATE_TEST_SUITE_P(AllBackends, FluidPressureSolverTest,
                         ::testing::Values(PressureSolver::mic0_pcg, PressureSolver::multigrid_pcg,
                                           PressureSolver::eigen_ic_cg,
                                           PressureSolver::hypre_pfmg_pcg),
                         [](const ::testing::TestParamInfo<PressureSolver>& param_info) {
                             switch (param_info.param) {
                                 case PressureSolver::mic0_pcg:
                                     return std::string("mic0_pcg");
                                 case PressureSolver::multigrid_pcg:
                                     return std::string("multigrid_pcg");
                                 case PressureSolver::eigen_ic_cg:
                                     return std::string("eigen_ic_cg");
                                 case PressureSolver::hypre_pfmg_pcg:
                                     return std::string("hypre_pfmg_pcg");
                             }
                             return std::string("unknown");
                         });

TEST(FluidPressureOptions, ValidateNamesTheField) {
    PressureOptions options;
    options.min_liquid_fraction = 0.0;
    try {
        options.validate();
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("min_liquid_fraction"), std::string::npos);
    }
}

TEST(FluidPressure, LargestDivergenceIsTheGridsOverTheUnknownCells) {
    // max_fluid_divergence() (rows of φ by flat index, planes over threads) and
    // MacGrid::divergence() (the face arrays by flat index) on a box of three different sizes,
    // random velocities and a bubble: the largest |div u| over the unknown cells (every cell
    // two-phase, the liquid ones with a free surface) as a plain loop over the cells of the face
    // differences gives it.
    const int nx = 7, ny = 5, nz = 6;
    MacGrid grid(nx, ny, nz, 0.1);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> random(-1.0, 1.0);
    for (int axis = 0; axis < 3; ++axis)
        for (double& value : grid.velocity(axis).storage())
            value = random(rng);
    InterfaceInput interface(grid);
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                interface.phi(i, j, k) =
                    0.2 - (grid.cell_centre(i, j, k) - Eigen::Vector3d(0.3, 0.2, 0.35)).norm();
    for (FluidMode mode : {FluidMode::two_phase, FluidMode::free_surface}) {
        double largest = 0.0;
        for (int k = 0; k < nz; ++k)
            for (int j = 0; j < ny; ++j)
                for (int i = 0; i < nx; ++i)
                    if (mode == FluidMode::two_phase || interface.phi(i, j, k) < 0.0)
                        largest =
                            std::max(largest, std::abs((grid.u()(i + 1, j, k) - grid.u()(i, j, k) +
                                                        grid.v()(i, j + 1, k) - grid.v()(i, j, k) +
                                                        grid.w()(i, j, k + 1) - grid.w()(i, j, k)) /
                                                       grid.dx()));
        EXPECT_GT(largest, 0.0);
        EXPECT_EQ(max_fluid_divergence(grid, interface, mode), largest);
    }
}

TEST(FluidPressure, GradientAndDivergenceRefuseArraysOfAnotherSize) {
    MacGrid grid(6, 5, 4, 0.1);
    const InterfaceInput interface(grid);
    const PressureOptions options;
    const auto message = [](const auto& call) {
        try {
            call();
        } catch (const std::invalid_argument& error) {
            return std::string(error.what());
        }
        return std::string("no exception");
    };
    const Array3<double> wrong(6, 5, 5, 0.0);
    EXPECT_NE(message([&] {
                  apply_pressure_gradient(grid, interface, PhaseOptions{}, FluidMode::two_phase,
                                          1e-3, options, wrong, BoundaryOptions{});
              }).find("pressure"),
              std::string::npos);
    InterfaceInput bad_kappa(grid);
    bad_kappa.kappa_v.resize(6, 5, 4, 0.0);  // y-faces need ny + 1 = 6 along y
    const Array3<double> pressure(6, 5, 4, 0.0);
    EXPECT_NE(message([&] {
                  apply_pressure_gradient(grid, bad_kappa, PhaseOptions{}, FluidMode::two_phase,
                                          1e-3, options, pressure, BoundaryOptions{});
              }).find("kappa_v"),
              std::string::npos);
    InterfaceInput bad_phi(grid);
    bad_phi.phi = wrong;
    EXPECT_NE(
        message([&] { max_fluid_divergence(grid, bad_phi, FluidMode::two_phase); }).find("phi"),
        std::string::npos);
}

}  // namespace
}  // namespace meniscus::fluid
