// Periodic faces in the inviscid fluid step (issue 39): sampling, advection and extrapolation
// wrap around the box, so flows cross the seams as if the box repeated.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "fluid/advection.h"
#include "fluid/extrapolation.h"
#include "fluid/fluid_solver.h"

namespace meniscus::fluid {
namespace {

constexpr double PI = 3.14159265358979323846;

BoundaryOptions periodic_in_x_and_y() {
    BoundaryOptions boundaries = BoundaryOptions::all(BoundaryType::free_slip);
    for (int axis = 0; axis < 2; ++axis) {
        boundaries.face(axis, 0).type = BoundaryType::periodic;
        boundaries.face(axis, 1).type = BoundaryType::periodic;
    }
    return boundaries;
}

FluidOptions inviscid(const BoundaryOptions& boundaries) {
    FluidOptions options;
    options.phases.mu_liquid = 0.0;
    options.phases.mu_gas = 0.0;
    options.gravity = Eigen::Vector3d::Zero();
    options.boundaries = boundaries;
    options.pressure.iteration.tolerance = 1e-10;
    return options;
}

// Along a periodic axis a sample between the last sample and the box's end interpolates towards
// the first sample, as if the lattice went on; without periodicity it is clamped.
TEST(PeriodicSampling, WrapsAroundTheSeam) {
    MacGrid grid(4, 3, 2, 1.0);
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i <= 4; ++i)
                grid.u()(i, j, k) = i == 4 ? 10.0 : 10.0 + i;  // the face at 4 repeats the one at 0
    const Eigen::Vector3d beyond(3.25, 1.5, 1.0);              // between faces 3 and 4 (≡ 0)
    EXPECT_NEAR(grid.sample_component(0, beyond), 13.0 - 0.25 * 3.0, 1e-12);
    grid.set_periodic({true, false, false});
    // Cell centres of v along x: 0.5 … 3.5; x = 3.75 lies a quarter of the way from the last
    // (3) to the first (0) beyond the seam.
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j <= 3; ++j)
            for (int i = 0; i < 4; ++i)
                grid.v()(i, j, k) = i;
    EXPECT_NEAR(grid.sample_component(1, Eigen::Vector3d(3.75, 1.0, 1.0)), 2.25, 1e-12);
    EXPECT_NEAR(grid.sample_component(1, Eigen::Vector3d(-0.25, 1.0, 1.0)), 2.25, 1e-12);
    EXPECT_NEAR(grid.sample_component(1, Eigen::Vector3d(4.0 + 1.5, 1.0, 1.0)), 1.0, 1e-12);
    // u along x has period 4 (faces 0 … 3 distinct): x = 3.25 → 13 + 0.25 (10 − 13).
    EXPECT_NEAR(grid.sample_component(0, beyond), 13.0 - 0.75, 1e-12);
}

/// Taylor–Green cells of wavenumber k = 2π/L across x and y carried along x by a uniform U0:
/// u = U0 + A sin(kx) cos(ky), v = −A cos(kx) sin(ky) (a steady Euler flow, Galilean-shifted).
void set_translated_taylor_green(MacGrid& grid, double u0, double amplitude, double shift) {
    const double length = grid.nx() * grid.dx();
    const double k = 2.0 * PI / length;
    for (int axis = 0; axis < 2; ++axis) {
        Array3<double>& faces = grid.velocity(axis);
        for (int kk = 0; kk < faces.nk(); ++kk)
            for (int j = 0; j < faces.nj(); ++j)
                for (int i = 0; i < faces.ni(); ++i) {
                    const Eigen::Vector3d x = grid.face_centre(axis, i, j, kk);
                    const double s = k * (x.x() - shift), t = k * x.y();
                    faces(i, j, kk) = axis == 0 ? u0 + amplitude * std::sin(s) * std::cos(t)
                                                : -amplitude * std::cos(s) * std::sin(t);
                }
    }
    grid.w().fill(0.0);
}

/// Largest difference of u and v from the translated Taylor–Green field, over its amplitude.
double taylor_green_error(const MacGrid& grid, double u0, double amplitude, double shift) {
    MacGrid exact(grid.nx(), grid.ny(), grid.nz(), grid.dx(), grid.origin());
    set_translated_taylor_green(exact, u0, amplitude, shift);
    double largest = 0.0;
    for (int axis = 0; axis < 2; ++axis)
        for (std::size_t f = 0; f < exact.velocity(axis).size(); ++f)
            largest = std::max(largest, std::abs(grid.velocity(axis)[f] - exact.velocity(axis)[f]));
    return largest / amplitude;
}

/// The translated Taylor–Green run's outcome.
struct TaylorGreenRun {
    double error = 0.0;  ///< largest |u − exact|, |v − exact| over the amplitude
    /// Largest difference between the error of a column of u faces (its max over y) and that of
    /// the column half a box further along x: the flow is symmetric under a shift of (L/2, L/2),
    /// so anything the seam did differently from the inside of the box would show here.
    double asymmetry = 0.0;
};

/// Runs the translated Taylor–Green flow for one period L/U0 on n × n × 2 cells (periodic in x
/// and y); the cells should be back where they started.
TaylorGreenRun taylor_green_after_one_period(int n) {
    const double length = 1e-2, u0 = 0.1, amplitude = 0.02;
    const double dx = length / n;
    FluidSolver solver(n, n, 2, dx, Eigen::Vector3d::Zero(), inviscid(periodic_in_x_and_y()));
    set_translated_taylor_green(solver.grid(), u0, amplitude, 0.0);
    const InterfaceInput liquid(solver.grid());
    const double period = length / u0;
    const int steps = static_cast<int>(std::ceil(period / (0.5 * dx / (u0 + amplitude))));
    for (int s = 0; s < steps; ++s) {
        const StepResult result = solver.step(period / steps, liquid);
        EXPECT_TRUE(result.pressure.converged);
    }
    const MacGrid& grid = solver.grid();
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < n; ++j) {
            EXPECT_EQ(grid.u()(n, j, k), grid.u()(0, j, k));
            for (int i = 0; i < n; ++i)
                EXPECT_LT(std::abs(grid.divergence(i, j, k)), 1e-8 * u0 / dx);
        }
    MacGrid exact(n, n, 2, dx);
    set_translated_taylor_green(exact, u0, amplitude, 0.0);
    std::vector<double> column(static_cast<std::size_t>(n), 0.0);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            column[static_cast<std::size_t>(i)] =
                std::max(column[static_cast<std::size_t>(i)],
                         std::abs(grid.u()(i, j, 0) - exact.u()(i, j, 0)) / amplitude);
    TaylorGreenRun run;
    run.error = taylor_green_error(grid, u0, amplitude, 0.0);
    for (int i = 0; i < n / 2; ++i)
        run.asymmetry =
            std::max(run.asymmetry, std::abs(column[static_cast<std::size_t>(i)] -
                                             column[static_cast<std::size_t>(i + n / 2)]));
    return run;
}

// A uniform stream through a box periodic along it stays exactly uniform: nothing drifts, piles
// up or is lost at the seam (with walls across the stream it could not exist at all).
TEST(PeriodicFlow, UniformStreamThroughTheSeamStaysUniform) {
    const int n = 12;
    const double dx = 1e-3, u0 = 0.05, v0 = -0.02;
    FluidSolver solver(n, n, 3, dx, Eigen::Vector3d::Zero(), inviscid(periodic_in_x_and_y()));
    solver.grid().u().fill(u0);
    solver.grid().v().fill(v0);
    const InterfaceInput liquid(solver.grid());
    for (int s = 0; s < 40; ++s)
        solver.step(0.4 * dx / u0, liquid);
    for (std::size_t f = 0; f < solver.grid().u().size(); ++f)
        ASSERT_NEAR(solver.grid().u()[f], u0, 1e-12 * u0);
    for (std::size_t f = 0; f < solver.grid().v().size(); ++f)
        ASSERT_NEAR(solver.grid().v()[f], v0, 1e-12 * u0);
}

// Taylor–Green cells carried once around a periodic box by a uniform stream come back where
// they started (an exact solution of the Euler equations). The error is the advection's
// dissipation and falls under refinement (0.19 and 0.072 of the amplitude at 16 and 32 cells),
// and it is the same on the columns at the seam as on those half a box away: the seam is no
// different from the inside of the box.
TEST(PeriodicFlow, TaylorGreenCellsCarriedOnceAroundComeBack) {
    const TaylorGreenRun coarse = taylor_green_after_one_period(16);
    const TaylorGreenRun fine = taylor_green_after_one_period(32);
    std::printf(
        "translated Taylor-Green after one period: error %.3e (16 cells), %.3e (32), "
        "order %.2f; column asymmetry %.1e, %.1e\n",
        coarse.error, fine.error, std::log2(coarse.error / fine.error), coarse.asymmetry,
        fine.asymmetry);
    EXPECT_LT(fine.error, 0.08);
    EXPECT_LT(fine.error, 0.5 * coarse.error);
    EXPECT_LT(coarse.asymmetry, 1e-6);
    EXPECT_LT(fine.asymmetry, 1e-6);
}

// The velocity of a liquid slab against the seam at x = 0 is extrapolated across the seam into
// the gas at the far end of the box.
TEST(PeriodicFlow, ExtrapolationCrossesTheSeam) {
    MacGrid grid(8, 2, 2, 1.0);
    grid.set_periodic({true, false, false});
    InterfaceInput interface(grid);
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 8; ++i)
                interface.phi(i, j, k) = i < 2 ? -0.5 : 0.5;  // liquid in cells 0 and 1
    grid.v().fill(0.0);
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j <= 2; ++j)
            for (int i = 0; i < 2; ++i)
                grid.v()(i, j, k) = 3.0;
    grid.u().fill(0.0);
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i <= 2; ++i)
                grid.u()(i, j, k) = 1.0;  // the seam's face (0) is next to liquid cell 0
    extrapolate_velocity(grid, interface, 1);
    EXPECT_DOUBLE_EQ(grid.v()(7, 1, 1), 3.0);  // one layer beyond the seam
    EXPECT_DOUBLE_EQ(grid.v()(6, 1, 1), 0.0);  // two layers: beyond the reach
    EXPECT_DOUBLE_EQ(grid.u()(7, 1, 1), 1.0);  // u at x = 7: next to face 0 through the seam
    EXPECT_DOUBLE_EQ(grid.u()(8, 1, 1), grid.u()(0, 1, 1));
}

/// (4/Δx²) sin²(kΔx/2): the eigenvalue of the second difference for a wave of wavenumber k.
double discrete_wavenumber_squared(double k, double dx) {
    const double s = std::sin(0.5 * k * dx);
    return 4.0 * s * s / (dx * dx);
}

// A shear wave across each periodic axis in turn (u = U sin(k y), v = V sin(k z), w = W sin(k x)),
// in a box periodic along every axis, decays by exactly the backward-Euler factor of its
// discrete mode, 1/(1 + ν Δt λ_h) per step: the viscous shear terms wrap around the seams (a
// wall there would pin or mirror the wave). Advection leaves such a wave unchanged. The v wave
// is solved with the multigrid-preconditioned viscous CG, the others with Jacobi.
TEST(PeriodicViscousFlow, ShearWavesAcrossEverySeamDecayAtTheirDiscreteRate) {
    const std::array<int, 3> n = {8, 12, 10};
    const double dx = 1e-3, amplitude = 1e-3;
    FluidOptions options = inviscid(BoundaryOptions::all(BoundaryType::periodic));
    options.phases.mu_liquid = 1e-3;
    const double nu = options.phases.mu_liquid / options.phases.rho_liquid;
    for (int a = 0; a < 3; ++a) {
        // Both preconditioners of the viscous CG (the multigrid one on each component's block).
        options.viscosity.preconditioner =
            a == 1 ? ViscousPreconditioner::multigrid : ViscousPreconditioner::jacobi;
        const int across = (a + 1) % 3;  // the wave varies across this axis
        const double k = 2.0 * PI / (n[static_cast<std::size_t>(across)] * dx);
        FluidSolver solver(n[0], n[1], n[2], dx, Eigen::Vector3d::Zero(), options);
        Array3<double>& faces = solver.grid().velocity(a);
        for (int kk = 0; kk < faces.nk(); ++kk)
            for (int j = 0; j < faces.nj(); ++j)
                for (int i = 0; i < faces.ni(); ++i)
                    faces(i, j, kk) =
                        amplitude * std::sin(k * solver.grid().face_centre(a, i, j, kk)[across]);
        const Array3<double> start = faces;
        const InterfaceInput liquid(solver.grid());
        const double dt = 0.5 * dx * dx / nu;  // a viscous diffusion number of 0.5
        const int steps = 10;
        for (int s = 0; s < steps; ++s)
            ASSERT_TRUE(solver.step(dt, liquid).viscosity.converged);
        const double factor = std::pow(1.0 + nu * dt * discrete_wavenumber_squared(k, dx), -steps);
        ASSERT_LT(factor, 0.5);  // the wave has decayed substantially
        double largest = 0.0;
        for (std::size_t f = 0; f < faces.size(); ++f)
            largest = std::max(largest, std::abs(solver.grid().velocity(a)[f] - factor * start[f]));
        EXPECT_LT(largest, 1e-6 * amplitude) << "component " << a;
        for (int b = 0; b < 3; ++b) {
            if (b != a) {  // what the solver's tolerance leaves in the other components
                EXPECT_LT(solver.grid().max_abs_velocity()[b], 1e-6 * amplitude);
            }
        }
    }
}

// Taylor–Green cells (u = U sin(kx) cos(ky), v = −U cos(kx) sin(ky)) in a periodic box decay
// at the rate of their discrete mode, 1/(1 + 2 ν Δt λ_h) per step: the normal stresses across
// the x and y seams wrap as well as the shear stresses. The amplitude is small enough that what
// advection changes is below the tolerance.
TEST(PeriodicViscousFlow, TaylorGreenCellsDecayAtTheirDiscreteRate) {
    const int n = 16;
    const double dx = 1e-3, amplitude = 1e-7;
    FluidOptions options = inviscid(BoundaryOptions::all(BoundaryType::periodic));
    options.phases.mu_liquid = 1e-3;
    const double nu = options.phases.mu_liquid / options.phases.rho_liquid;
    FluidSolver solver(n, n, 2, dx, Eigen::Vector3d::Zero(), options);
    set_translated_taylor_green(solver.grid(), 0.0, amplitude, 0.0);
    const MacGrid start = solver.grid();
    const InterfaceInput liquid(solver.grid());
    const double dt = dx * dx / nu;
    const int steps = 8;
    for (int s = 0; s < steps; ++s)
        ASSERT_TRUE(solver.step(dt, liquid).viscosity.converged);
    const double k = 2.0 * PI / (n * dx);
    const double factor =
        std::pow(1.0 + 2.0 * nu * dt * discrete_wavenumber_squared(k, dx), -steps);
    ASSERT_LT(factor, 0.5);
    double largest = 0.0;
    for (int axis = 0; axis < 2; ++axis)
        for (std::size_t f = 0; f < start.velocity(axis).size(); ++f)
            largest = std::max(largest, std::abs(solver.grid().velocity(axis)[f] -
                                                 factor * start.velocity(axis)[f]));
    std::printf(
        "Taylor-Green decay factor %.6f over %d steps, largest deviation %.2e of the "
        "amplitude\n",
        factor, steps, largest / amplitude);
    EXPECT_LT(largest, 1e-5 * amplitude);
}

/// Plane Poiseuille flow driven by a body force g along a periodic x between no-slip walls at
/// y = 0 and H (z periodic too), stepped to its steady state; returns the largest |u − exact|
/// over the peak speed, exact u = g y (H − y)/(2ν).
double body_force_poiseuille_error(int cells_across) {
    const double height = 1e-3, g = 0.1;
    const double dx = height / cells_across;
    BoundaryOptions boundaries = BoundaryOptions::all(BoundaryType::periodic);
    boundaries.y_min.type = boundaries.y_max.type = BoundaryType::no_slip;
    FluidOptions options = inviscid(boundaries);
    options.phases.mu_liquid = 1e-3;
    options.gravity = Eigen::Vector3d(g, 0.0, 0.0);
    const double nu = options.phases.mu_liquid / options.phases.rho_liquid;
    FluidSolver solver(4, cells_across, 2, dx, Eigen::Vector3d::Zero(), options);
    const InterfaceInput liquid(solver.grid());
    for (int s = 0; s < 40; ++s)  // backward Euler: each step takes the slowest mode by ~1/11
        EXPECT_TRUE(solver.step(height * height / nu, liquid).viscosity.converged);
    const double peak = g * height * height / (8.0 * nu);
    double largest = 0.0;
    const Array3<double>& u = solver.grid().u();
    for (int k = 0; k < u.nk(); ++k)
        for (int j = 0; j < u.nj(); ++j)
            for (int i = 0; i < u.ni(); ++i) {
                const double y = solver.grid().face_centre(0, i, j, k).y();
                largest =
                    std::max(largest, std::abs(u(i, j, k) - g * y * (height - y) / (2.0 * nu)));
            }
    EXPECT_LT(solver.grid().max_abs_velocity()[1], 1e-9 * peak);  // no cross flow
    return largest / peak;
}

// A channel periodic along the flow, driven by a body force (the classic periodic Poiseuille
// set-up): the steady profile converges to the parabola at second order, with nothing at the
// seam (the flow is the same on every column).
TEST(PeriodicViscousFlow, BodyForceDrivesPoiseuilleFlowAlongAPeriodicChannel) {
    const double coarse = body_force_poiseuille_error(8);
    const double fine = body_force_poiseuille_error(16);
    std::printf(
        "body-force Poiseuille: max error %.3e / %.3e of the peak at 8 / 16 cells across, "
        "order %.2f\n",
        coarse, fine, std::log2(coarse / fine));
    EXPECT_LT(fine, 0.01);
    EXPECT_GT(std::log2(coarse / fine), 1.8);
}

}  // namespace
}  // namespace meniscus::fluid
