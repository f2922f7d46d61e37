// Moving walls (issue 39): a no-slip wall that slides along itself drags the liquid with it. In a
// long closed channel the flow away from its end walls is plane Couette flow, with the return
// flow of a Poiseuille profile when the walls carry liquid towards one end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>

#include "fluid/fluid_solver.h"
#include "steady_channel.h"

namespace meniscus::fluid {
namespace {

constexpr double HEIGHT = testing::CHANNEL_HEIGHT;  ///< H, m
constexpr double MU = testing::CHANNEL_MU;          ///< ν = 1 m²/s
constexpr double SPEED = 0.01;  ///< U, m/s: Re = U H / ν = 0.01, Stokes flow
constexpr int LENGTH = 8;       ///< channel length in H

struct ChannelErrors {
    double velocity = 0.0;           ///< max |u − exact| over the middle cross-section, / U
    double pressure_gradient = 0.0;  ///< mean dp/dx over the middle quarter, Pa/m
};

/// Steady flow in a box of 8H × H × one cell: the y walls no-slip and sliding along x at
/// `u_bottom` and `u_top`, the x walls (the channel's closed ends) no-slip at rest, the z walls
/// free-slip (plane flow). Compares u on the cross-section half-way along with `exact(y / H)`.
ChannelErrors channel(int cells_across, double u_bottom, double u_top,
                      const std::function<double(double)>& exact) {
    FluidOptions options;
    options.boundaries = BoundaryOptions::all(BoundaryType::no_slip);
    options.boundaries.z_min.type = options.boundaries.z_max.type = BoundaryType::free_slip;
    options.boundaries.y_min.velocity = Eigen::Vector3d(u_bottom, 0.0, 0.0);
    options.boundaries.y_max.velocity = Eigen::Vector3d(u_top, 0.0, 0.0);
    const double dx = HEIGHT / cells_across;
    const int nx = LENGTH * cells_across;
    const FluidSolver solver = testing::steady_channel(options, cells_across, LENGTH, SPEED);
    ChannelErrors errors;
    const MacGrid& grid = solver.grid();
    for (int j = 0; j < cells_across; ++j) {
        const double eta = grid.face_centre(0, nx / 2, j, 0).y() / HEIGHT;
        errors.velocity =
            std::max(errors.velocity, std::abs(grid.u()(nx / 2, j, 0) - SPEED * exact(eta)));
    }
    errors.velocity /= SPEED;
    const int i0 = 3 * nx / 8, i1 = 5 * nx / 8;
    for (int j = 0; j < cells_across; ++j)
        errors.pressure_gradient +=
            (solver.pressure()(i1, j, 0) - solver.pressure()(i0, j, 0)) / ((i1 - i0) * dx);
    errors.pressure_gradient /= cells_across;
    return errors;
}

TEST(MovingWalls, WallsSlidingApartGiveThePlaneCouetteProfile) {
    // Walls at ∓U: u = U (2η − 1), no net flux towards either end, so no pressure gradient.
    const auto couette = [](double eta) { return 2.0 * eta - 1.0; };
    const ChannelErrors e = channel(16, -SPEED, SPEED, couette);
    std::printf(
        "[ measured ] Couette, 16 cells across: max |u - exact| / U = %.3e, "
        "dp/dx = %.3e Pa/m\n",
        e.velocity, e.pressure_gradient);
    // Linear profiles are exact for the mirrored wall strain: what is left is the solver's.
    EXPECT_LT(e.velocity, 1e-5);
    EXPECT_LT(std::abs(e.pressure_gradient), 1e-4 * MU * SPEED / (HEIGHT * HEIGHT));
}

TEST(MovingWalls, LidOverAClosedChannelDrivesTheCouettePoiseuilleReturnFlow) {
    // Only the top wall moves, at U: the lid drags liquid to the far end, which pushes it back
    // along the bottom. Zero net flux through every cross-section makes u = U η (3η − 2) with
    // dp/dx = 6 μ U / H² (μ u'' = dp/dx, u(0) = 0, u(1) = U, ∫u dη = 0).
    const auto lid = [](double eta) { return eta * (3.0 * eta - 2.0); };
    const double gradient = 6.0 * MU * SPEED / (HEIGHT * HEIGHT);
    const ChannelErrors e8 = channel(8, 0.0, SPEED, lid);
    const ChannelErrors e16 = channel(16, 0.0, SPEED, lid);
    const ChannelErrors e32 = channel(32, 0.0, SPEED, lid);
    std::printf(
        "[ measured ] lid-driven channel, max |u - exact| / U: N=8 %.3e, N=16 %.3e, "
        "N=32 %.3e; dp/dx / (6 mu U / H^2): %.5f, %.5f, %.5f\n",
        e8.velocity, e16.velocity, e32.velocity, e8.pressure_gradient / gradient,
        e16.pressure_gradient / gradient, e32.pressure_gradient / gradient);
    EXPECT_LT(e16.velocity, 0.01);  // within 1 % of U at 16 cells across
    EXPECT_NEAR(e16.pressure_gradient / gradient, 1.0, 0.01);
    EXPECT_GT(std::log2(e8.velocity / e16.velocity), 1.5);  // observed order in Δx
    EXPECT_GT(std::log2(e16.velocity / e32.velocity), 1.5);
}

TEST(MovingWalls, OptionsNameTheWallThatCannotMove) {
    BoundaryOptions walls = BoundaryOptions::all(BoundaryType::no_slip);
    walls.y_max.velocity = Eigen::Vector3d(0.0, 1.0, 0.0);  // along the wall's normal
    try {
        walls.validate();
        ADD_FAILURE() << "a wall moving along its normal was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("y_max/velocity"), std::string::npos) << e.what();
    }
    walls.y_max.velocity = Eigen::Vector3d(1.0, 0.0, 0.0);
    EXPECT_NO_THROW(walls.validate());
    EXPECT_TRUE(walls.moving());
    EXPECT_FALSE(walls.at_rest().moving());
    walls.y_max.type = BoundaryType::free_slip;
    try {
        walls.validate();
        ADD_FAILURE() << "a moving free-slip wall was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("y_max/velocity: only a no_slip wall"), std::string::npos) << e.what();
    }
    walls.y_max.type = BoundaryType::no_slip;
    walls.x_min.velocity = Eigen::Vector3d(0.0, NAN, 0.0);
    EXPECT_THROW(walls.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::fluid
