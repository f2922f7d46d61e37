// The coupled scheme's passes on the box of the cells that need them
// (ViscousPressureOptions::local_passes): two air bubbles in water, the bench's pair, give the
// coupled step as closely as passes on the whole grid do.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/binary_io.h"
#include "fluid/fluid_solver.h"
#include "fluid/viscous_pressure.h"

namespace meniscus::fluid {
namespace {

constexpr int N = 48;
constexpr double BOX = 0.01;  // m
constexpr double DX = BOX / N;
constexpr double RADIUS = 0.0015;
constexpr double DT = 1.0e-4;  // s, near the capillary limit at this Δx
constexpr int WARM = 1;        // the state after one step takes 4 passes
const Eigen::Vector3d CENTRES[2] = {{0.00335, 0.005, 0.004}, {0.00665, 0.005, 0.004}};

double bubble_phi(const Eigen::Vector3d& x) {
    // Negative in the liquid: the distance into the nearer bubble is positive.
    double phi = -1e9;
    for (const Eigen::Vector3d& c : CENTRES)
        phi = std::max(phi, RADIUS - (x - c).norm());
    return phi;
}

InterfaceInput bubble_pair(const MacGrid& grid) {
    InterfaceInput interface(grid);
    for (int k = 0; k < N; ++k)
        for (int j = 0; j < N; ++j)
            for (int i = 0; i < N; ++i)
                interface.phi(i, j, k) = bubble_phi(grid.cell_centre(i, j, k));
    for (int axis = 0; axis < 3; ++axis)
        interface.kappa(axis).fill(-2.0 / RADIUS);  // read on crossed faces only
    return interface;
}

FluidOptions water_and_air() {
    FluidOptions options;
    options.mode = FluidMode::two_phase;
    options.phases = PhaseOptions{};  // water and air
    options.gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
    options.boundaries = BoundaryOptions::all(BoundaryType::no_slip);
    return options;
}

/// A solver of `options` in the state `state` (FluidSolver::save_state()).
FluidSolver restored(const FluidOptions& options, const BinaryWriter& state) {
    FluidSolver solver(N, N, N, DX, Eigen::Vector3d::Zero(), options);
    BinaryReader in(state.bytes().data(), state.bytes().size());
    solver.load_state(in);
    return solver;
}

TEST(LocalPasses, ABubblePairsStepMatchesThePassesOnTheWholeGrid) {
    // A few steps of the default scheme from the bubbles pushed towards each other at 0.05 m/s.
    FluidOptions options = water_and_air();
    options.viscous_pressure.local_passes = false;
    FluidSolver start(N, N, N, DX, Eigen::Vector3d::Zero(), options);
    const InterfaceInput interface = bubble_pair(start.grid());
    for (int k = 0; k < N; ++k)
        for (int j = 0; j < N; ++j)
            for (int i = 0; i <= N; ++i) {
                const Eigen::Vector3d x = (Eigen::Vector3d(i, j + 0.5, k + 0.5)) * DX;
                if (bubble_phi(x) > 0.0)
                    start.grid().u()(i, j, k) = x.x() < 0.5 * BOX ? 0.05 : -0.05;
            }
    for (int step = 0; step < WARM; ++step)
        start.step(DT, interface);
    BinaryWriter state;
    start.save_state(state);

    // The coupled step solved to 1e-8, and the default passes on the whole grid and locally.
    FluidOptions exact_options = options;
    exact_options.viscous_pressure.pass_tolerance = 1e-8;
    exact_options.viscous_pressure.max_passes = 100;
    FluidSolver exact = restored(exact_options, state);
    const StepResult exact_result = exact.step(DT, interface);
    ASSERT_TRUE(exact_result.converged_passes);

    FluidSolver whole = restored(options, state);
    const StepResult whole_result = whole.step(DT, interface);
    FluidOptions local_options = options;
    local_options.viscous_pressure.local_passes = true;
    FluidSolver local = restored(local_options, state);
    const StepResult local_result = local.step(DT, interface);

    const double speed = exact.grid().max_abs_velocity().maxCoeff();
    const double whole_error = max_velocity_difference(whole.grid(), exact.grid()) / speed;
    const double local_error = max_velocity_difference(local.grid(), exact.grid()) / speed;
    std::printf(
        "speed %.4g  whole: %d passes on %zu cells, error %.3e  local: %d passes on %zu "
        "cells, error %.3e  local vs whole %.3e\n",
        speed, whole_result.passes, whole_result.pass_cells, whole_error, local_result.passes,
        local_result.pass_cells, local_error,
        max_velocity_difference(local.grid(), whole.grid()) / speed);
    EXPECT_GE(whole_result.passes, 2);
    EXPECT_LT(local_result.pass_cells, whole_result.pass_cells / 2);
    EXPECT_LT(local_error, 1.5 * whole_error);
}

/// ‖∇·u‖₂ over the cells, in 1/s.
double divergence_norm(const MacGrid& grid) {
    double sum = 0.0;
    for (int k = 0; k < grid.nz(); ++k)
        for (int j = 0; j < grid.ny(); ++j)
            for (int i = 0; i < grid.nx(); ++i)
                sum += grid.divergence(i, j, k) * grid.divergence(i, j, k);
    return std::sqrt(sum);
}

TEST(LocalPasses, TheFinalProjectionLeavesWhatTheIncrementalSchemesProjectionLeaves) {
    // After the passes the final projection's tolerance is relative to the divergence before
    // them (the incremental scheme's projection's right-hand side): from the same state the
    // coupled step's velocity is as divergence-free as the incremental step's, while its
    // projection, starting from the passes' smaller divergence, needs fewer iterations than it
    // would to reach the tolerance relative to that.
    FluidOptions options = water_and_air();
    FluidSolver start(N, N, N, DX, Eigen::Vector3d::Zero(), options);
    const InterfaceInput interface = bubble_pair(start.grid());
    for (int step = 0; step < 2; ++step)
        start.step(DT, interface);
    BinaryWriter state;
    start.save_state(state);
    FluidSolver coupled = restored(options, state);
    const StepResult coupled_result = coupled.step(DT, interface);
    FluidOptions incremental_options = options;
    incremental_options.viscous_pressure.coupling = ViscousPressureCoupling::incremental;
    FluidSolver incremental = restored(incremental_options, state);
    incremental.step(DT, interface);
    const double coupled_norm = divergence_norm(coupled.grid());
    const double incremental_norm = divergence_norm(incremental.grid());
    std::printf("|div u|_2: coupled (%d passes) %.3e, incremental %.3e 1/s\n",
                coupled_result.passes, coupled_norm, incremental_norm);
    ASSERT_GE(coupled_result.passes, 1);
    EXPECT_LT(coupled_norm, 2.0 * incremental_norm);
    EXPECT_GT(coupled_norm, 0.0);
}

TEST(LocalPasses, TheRegionBoundsTheCellsWhoseOwnEstimateExceedsTheTolerance) {
    // 12³ cells of water with a gas cell at (3, 4, 5): with the same |r| everywhere, only the gas
    // cell and its face neighbours (the air's ν, 15× the water's) exceed the tolerance.
    Array3<double> phi(12, 12, 12, -1.0);
    phi(3, 4, 5) = 1.0;
    const PhaseOptions water_air;
    const double dt = 1e-4, dx = 1e-4, speed = 0.1;
    const double d_gas = water_air.mu_gas / water_air.rho_gas * dt / (dx * dx);  // 0.15
    // |r| between the two thresholds (tolerance·speed / (D/(1 + D)·Δx) of each; the water's is
    // 13× the air's here).
    const double tolerance = 1e-3;
    const double r_value = 3.0 * tolerance * speed / (d_gas / (1.0 + d_gas) * dx);
    std::vector<double> r(phi.size(), r_value);
    const PassRegion region =
        pass_region(r, phi, water_air, FluidMode::two_phase, dt, dx, speed, tolerance, 2);
    const CellBox& box = region.box;
    // The water cells left out report their own estimate, about a quarter of the tolerance.
    const double d_water = water_air.mu_liquid / water_air.rho_liquid * dt / (dx * dx);
    const double water_estimate = d_water / (1.0 + d_water) * r_value * dx / speed;
    EXPECT_NEAR(region.settled, water_estimate, 1e-12 * tolerance);
    EXPECT_LT(region.settled, tolerance);
    EXPECT_EQ(box.lo, (std::array<int, 3>{0, 1, 2}));  // 3 − 1 − 2 …
    EXPECT_EQ(box.hi, (std::array<int, 3>{7, 8, 9}));  // … 3 + 1 + 1 + 2
    // Nothing needs passes below both thresholds; the margin is clipped at the grid.
    std::vector<double> small(phi.size(), 0.1 * r_value);
    EXPECT_TRUE(
        pass_region(small, phi, water_air, FluidMode::two_phase, dt, dx, speed, tolerance, 2)
            .box.empty());
    const CellBox wide =
        pass_region(r, phi, water_air, FluidMode::two_phase, dt, dx, speed, tolerance, 20).box;
    EXPECT_TRUE(wide == CellBox::whole(phi));
}

TEST(LocalPasses, TheRegionsCutFacesAreOutflowsAndItsOwnFacesKeepTheirConditions) {
    BoundaryOptions walls = BoundaryOptions::all(BoundaryType::no_slip);
    walls.z_max.type = BoundaryType::free_slip;
    CellBox box;
    box.lo = {0, 2, 3};
    box.hi = {5, 10, 8};
    const BoundaryOptions cut = box_boundaries(walls, box, {10, 10, 8});
    EXPECT_EQ(cut.at(0, 0), BoundaryType::no_slip);  // reaches x = 0
    EXPECT_EQ(cut.at(0, 1), BoundaryType::outflow);
    EXPECT_EQ(cut.at(1, 0), BoundaryType::outflow);
    EXPECT_EQ(cut.at(1, 1), BoundaryType::no_slip);  // reaches y = 10
    EXPECT_EQ(cut.at(2, 0), BoundaryType::outflow);
    EXPECT_EQ(cut.at(2, 1), BoundaryType::free_slip);
    EXPECT_EQ(cut.face(0, 1).pressure, 0.0);

    // The interface copied cell by cell and face by face.
    MacGrid grid(10, 10, 8, 0.1);
    InterfaceInput interface(grid);
    interface.phi(4, 9, 7) = 0.25;
    interface.kappa(2)(4, 9, 8) = 7.0;
    const InterfaceInput inside = interface_in_box(interface, box);
    EXPECT_EQ(inside.phi.ni(), 5);
    EXPECT_EQ(inside.phi.nj(), 8);
    EXPECT_EQ(inside.phi.nk(), 5);
    EXPECT_EQ(inside.phi(4, 7, 4), 0.25);
    EXPECT_EQ(inside.kappa(2).nk(), 6);
    EXPECT_EQ(inside.kappa(2)(4, 7, 5), 7.0);
    EXPECT_THROW(interface_in_box(interface, CellBox{}), std::invalid_argument);
}

TEST(LocalPasses, APartIsCopiedOutOfAndAddedBackIntoItsPlace) {
    Array3<double> whole(5, 4, 3, 0.0);
    for (std::size_t c = 0; c < whole.size(); ++c)
        whole[c] = static_cast<double>(c);
    const Array3<double> part = part_at(whole, {1, 2, 1}, 3, 2, 2);
    EXPECT_EQ(part(0, 0, 0), whole(1, 2, 1));
    EXPECT_EQ(part(2, 1, 1), whole(3, 3, 2));
    Array3<double> sum = whole;
    add_part_at(sum, {1, 2, 1}, 2.0, part);
    EXPECT_EQ(sum(3, 3, 2), 3.0 * whole(3, 3, 2));
    EXPECT_EQ(sum(0, 2, 1), whole(0, 2, 1));  // outside the part: unchanged
    EXPECT_EQ(sum(4, 3, 2), whole(4, 3, 2));
    EXPECT_THROW(part_at(whole, {3, 0, 0}, 3, 1, 1), std::invalid_argument);
    EXPECT_THROW(add_part_at(sum, {0, 3, 0}, 1.0, part), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::fluid
