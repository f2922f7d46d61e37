// Implicit viscosity: plane Poiseuille flow between no-slip walls converges to the parabola, and
// the variational operator has the exact discrete Taylor–Green eigenmode.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/LU>

#include "fluid/forces.h"
#include "fluid/pressure.h"
#include "fluid/surface_viscosity.h"
#include "fluid/viscosity.h"
#include "fluid/viscous_operator.h"

namespace meniscus::fluid {
namespace {

/// Gravity-driven plane Poiseuille flow between no-slip walls at y = 0 and y = H: body force g
/// along x, the x walls prescribe the matching parabolic inflow = outflow
/// u(y) = ρ g y (H − y) / (2μ) (centreline U = ρ g H² / (8μ)); the interior starts at rest and is
/// stepped (gravity, implicit viscosity, projection) until steady. The steady state must be the
/// parabola with no pressure gradient left along the channel (gravity balances the wall shear;
/// this also keeps the projection-splitting error, Δt·∇p/ρ, out of the steady state).
/// Returns the max velocity error relative to U, and |dp/dx| relative to ρ g.
struct PoiseuilleErrors {
    double velocity = 0.0;
    double pressure_gradient = 0.0;
};

PoiseuilleErrors poiseuille_errors(int cells_across) {
    const double height = 1.0, rho = 1.0, mu = 0.5, g = 1.0;
    const double centreline = rho * g * height * height / (8.0 * mu);
    const double dx = height / cells_across;
    const int length_cells = 2 * cells_across;
    MacGrid grid(length_cells, cells_across, 1, dx);
    const auto exact = [&](double y) {
        return 4.0 * centreline * y * (height - y) / (height * height);
    };
    for (int j = 0; j < cells_across; ++j) {
        const double y = grid.face_centre(0, 0, j, 0).y();
        grid.u()(0, j, 0) = exact(y);
        grid.u()(length_cells, j, 0) = exact(y);
    }
    InterfaceInput interface(grid);  // all liquid
    PhaseOptions phases;
    phases.rho_liquid = rho;
    phases.mu_liquid = mu;
    phases.sigma = 0.0;
    // No-slip everywhere except the z walls: at the inflow and outflow planes this states
    // v = 0 with the shear stress μ ∂u/∂y of the prescribed profile, as in Poiseuille flow.
    BoundaryOptions walls = BoundaryOptions::all(BoundaryType::no_slip);
    walls.z_min.type = BoundaryType::free_slip;
    walls.z_max.type = BoundaryType::free_slip;
    ViscosityOptions viscosity;
    viscosity.iteration.tolerance = 1e-12;
    PressureOptions pressure_options;
    pressure_options.iteration.tolerance = 1e-12;
    const double nu = mu / rho;
    const double dt = 0.5 * height * height / nu;
    const int steps = 60;
    Array3<double> pressure;
    for (int step = 0; step < steps; ++step) {
        apply_gravity(grid, Eigen::Vector3d(g, 0.0, 0.0), dt);
        const SolveResult viscous =
            apply_viscosity(grid, interface, phases, FluidMode::two_phase, walls, dt, viscosity);
        EXPECT_TRUE(viscous.converged) << "residual " << viscous.residual;
        const ProjectionResult projection =
            project(grid, interface, phases, FluidMode::two_phase, dt, pressure_options, pressure);
        EXPECT_TRUE(projection.solve.converged);
    }
    PoiseuilleErrors errors;
    for (int j = 0; j < cells_across; ++j) {
        for (int i = 1; i < length_cells; ++i) {
            const double y = grid.face_centre(0, i, j, 0).y();
            errors.velocity = std::max(errors.velocity, std::abs(grid.u()(i, j, 0) - exact(y)));
        }
    }
    errors.velocity /= centreline;
    // Mean pressure gradient over the middle half of the channel.
    const int i0 = length_cells / 4, i1 = 3 * length_cells / 4;
    double gradient = 0.0;
    for (int j = 0; j < cells_across; ++j) {
        gradient += (pressure(i1, j, 0) - pressure(i0, j, 0)) / ((i1 - i0) * dx);
    }
    gradient /= cells_across;
    errors.pressure_gradient = std::abs(gradient) / (rho * g);
    return errors;
}

TEST(FluidViscosity, PoiseuilleFlowConvergesToTheParabolaAtSecondOrder) {
    const PoiseuilleErrors e8 = poiseuille_errors(8);
    const PoiseuilleErrors e16 = poiseuille_errors(16);
    const PoiseuilleErrors e32 = poiseuille_errors(32);
    std::printf("Poiseuille relative max velocity error: N=8 %.3e, N=16 %.3e, N=32 %.3e\n",
                e8.velocity, e16.velocity, e32.velocity);
    std::printf("Poiseuille |dp/dx| / (rho g):           N=8 %.3e, N=16 %.3e, N=32 %.3e\n",
                e8.pressure_gradient, e16.pressure_gradient, e32.pressure_gradient);
    // Measured: 3.9e-3, 1.4e-3, 4.2e-4 (order ≈ 1.5 then 1.7; the entrance corners converge
    // more slowly than the 1D profile, which is second order).
    EXPECT_LT(e8.velocity, 1e-2);
    EXPECT_LT(e32.velocity, 1e-3);
    EXPECT_GT(std::log2(e8.velocity / e16.velocity), 1.3);  // observed order of convergence
    EXPECT_GT(std::log2(e16.velocity / e32.velocity), 1.3);
    EXPECT_LT(e8.pressure_gradient, 1e-2);
    EXPECT_LT(e32.pressure_gradient, 5e-4);
}

/// Two-layer gravity-driven channel flow: liquid (μ_l) below y = h, gas (μ_g = μ_l / 10, same
/// density) above, no-slip walls at y = 0 and y = H, body force g along x. The exact profile is a
/// parabola in each layer, continuous in u and in the shear stress μ ∂u/∂y at y = h. Same set-up
/// as the Poiseuille case; h = H/2 + `offset_cells`·Δx; returns the max velocity error relative
/// to the max velocity.
double two_layer_error(int cells_across, ViscosityWeights weights, double offset_cells) {
    const double height = 1.0, rho = 1.0, g = 1.0;
    const double interface_height = 0.5 * height + offset_cells * height / cells_across;
    const double mu_l = 0.5, mu_g = 0.05;
    // u_l = −ρg y²/(2μ_l) + A y,  u_g = −ρg (y−H)²/(2μ_g) + B (y−H);
    // μ_l A − μ_g B = ρ g H (stress) and u_l(h) = u_g(h) (velocity).
    const double h = interface_height, d = h - height;
    const Eigen::Matrix2d m{{mu_l, -mu_g}, {h, -d}};
    const Eigen::Vector2d rhs(rho * g * height,
                              rho * g * h * h / (2.0 * mu_l) - rho * g * d * d / (2.0 * mu_g));
    const Eigen::Vector2d ab = m.fullPivLu().solve(rhs);
    const auto exact = [&](double y) {
        return y < h ? -rho * g * y * y / (2.0 * mu_l) + ab[0] * y
                     : -rho * g * (y - height) * (y - height) / (2.0 * mu_g) + ab[1] * (y - height);
    };
    const double dx = height / cells_across;
    const int length_cells = 2 * cells_across;
    MacGrid grid(length_cells, cells_across, 1, dx);
    InterfaceInput interface(grid);
    for (int j = 0; j < cells_across; ++j) {
        const double y = grid.face_centre(0, 0, j, 0).y();
        grid.u()(0, j, 0) = exact(y);
        grid.u()(length_cells, j, 0) = exact(y);
        for (int i = 0; i < length_cells; ++i) {
            interface.phi(i, j, 0) = grid.cell_centre(i, j, 0).y() - h;
        }
    }
    PhaseOptions phases;
    phases.rho_liquid = rho;
    phases.rho_gas = rho;
    phases.mu_liquid = mu_l;
    phases.mu_gas = mu_g;
    phases.sigma = 0.0;
    BoundaryOptions walls = BoundaryOptions::all(BoundaryType::no_slip);
    walls.z_min.type = BoundaryType::free_slip;
    walls.z_max.type = BoundaryType::free_slip;
    ViscosityOptions viscosity;
    viscosity.iteration.tolerance = 1e-12;
    viscosity.weights = weights;
    PressureOptions pressure_options;
    pressure_options.iteration.tolerance = 1e-12;
    const double dt = 0.5 * height * height * rho / mu_g;
    Array3<double> pressure;
    for (int step = 0; step < 60; ++step) {
        apply_gravity(grid, Eigen::Vector3d(g, 0.0, 0.0), dt);
        EXPECT_TRUE(
            apply_viscosity(grid, interface, phases, FluidMode::two_phase, walls, dt, viscosity)
                .converged);
        project(grid, interface, phases, FluidMode::two_phase, dt, pressure_options, pressure);
    }
    double max_error = 0.0, max_velocity = 0.0;
    for (int j = 0; j < cells_across; ++j) {
        const double y = grid.face_centre(0, 0, j, 0).y();
        max_velocity = std::max(max_velocity, exact(y));
        for (int i = 1; i < length_cells; ++i) {
            max_error = std::max(max_error, std::abs(grid.u()(i, j, 0) - exact(y)));
        }
    }
    return max_error / max_velocity;
}

/// The two-layer error at 8, 16 and 32 cells across is small and falls at second order.
void expect_two_layer_second_order(ViscosityWeights weights, double offset_cells) {
    const double e8 = two_layer_error(8, weights, offset_cells);
    const double e16 = two_layer_error(16, weights, offset_cells);
    const double e32 = two_layer_error(32, weights, offset_cells);
    std::printf("two-layer channel relative max error: N=8 %.3e, N=16 %.3e, N=32 %.3e\n", e8, e16,
                e32);
    EXPECT_LT(e8, 3e-2);
    EXPECT_LT(e32, 2e-3);
    EXPECT_GT(std::log2(e8 / e16), 1.7);
    EXPECT_GT(std::log2(e16 / e32), 1.7);
}

TEST(FluidViscosity, TwoLayerChannelWithViscosityRatio10ConvergesToTheExactProfile) {
    // The layer interface on a row of cell faces, through the shear edges. Measured: 2.0e-2,
    // 5.0e-3, 1.4e-3 (second order: the harmonic edge viscosity of the sharp weights carries the
    // shear stress across the layer interface exactly).
    expect_two_layer_second_order(ViscosityWeights::sharp, 0.0);
}

/// The pointwise weights (the default) with the layer interface through a row of cell centres:
/// the edges on either side take the μ of their own layer, so the shear stress balance at the
/// interface row is the exact one of the two parabolas, as the harmonic mean is for an interface
/// through the edges. Measured: 2.8e-2, 7.1e-3, 1.8e-3.
TEST(FluidViscosity, TwoLayerChannelWithPointwiseWeightsConvergesToTheExactProfile) {
    expect_two_layer_second_order(ViscosityWeights::pointwise, 0.5);
}

TEST(FluidViscosity, RestStaysAtRestWithVariableViscosity) {
    MacGrid grid(10, 10, 10, 0.1);
    InterfaceInput interface(grid);
    for (int k = 0; k < 10; ++k) {
        for (int j = 0; j < 10; ++j) {
            for (int i = 0; i < 10; ++i) {
                interface.phi(i, j, k) = grid.cell_centre(i, j, k).norm() - 0.5;
            }
        }
    }
    PhaseOptions phases;
    phases.mu_liquid = 1.0;
    phases.mu_gas = 1e-3;
    for (FluidMode mode : {FluidMode::two_phase, FluidMode::free_surface}) {
        const SolveResult result = apply_viscosity(grid, interface, phases, mode,
                                                   BoundaryOptions::all(BoundaryType::no_slip), 0.1, {});
        EXPECT_TRUE(result.converged);
        EXPECT_EQ(grid.max_abs_velocity().maxCoeff(), 0.0);
    }
}

/// The surface term of semi-implicit tension alone (μ = 0, viscosity otherwise off): two surface
/// points, each sampling one x-face, joined by L = [[1, −1], [−1, 1]]. The backward-Euler step
/// (ρ + c SᵀLS) u = ρ u* with c = Δt μ_s / Δx³ keeps their mean and divides their difference by
/// 1 + 2c/ρ exactly.
TEST(FluidViscosity, SurfaceViscosityTermRelaxesTwoCoupledFacesExactly) {
    MacGrid grid(4, 4, 4, 0.5);
    const std::size_t a = grid.u().index(1, 1, 1), b = grid.u().index(2, 2, 1);
    grid.u()(1, 1, 1) = 3.0;
    grid.u()(2, 2, 1) = -1.0;
    InterfaceInput interface(grid);  // all liquid
    auto term = std::make_shared<SurfaceViscosity>();
    term->sample.resize(6, static_cast<Eigen::Index>(grid.u().size() + grid.v().size() +
                                                     grid.w().size()));
    term->sample.insert(0, static_cast<Eigen::Index>(a)) = 1.0;  // point 0, x
    term->sample.insert(3, static_cast<Eigen::Index>(b)) = 1.0;  // point 1, x
    term->stiffness.resize(6, 6);  // L ⊗ I₃ with only the x rows sampled
    term->stiffness.insert(0, 0) = 1.0;
    term->stiffness.insert(0, 3) = -1.0;
    term->stiffness.insert(3, 0) = -1.0;
    term->stiffness.insert(3, 3) = 1.0;
    term->viscosity = 0.05;  // Pa·s·m
    interface.surface_viscosity = term;
    PhaseOptions phases;
    phases.rho_liquid = 2.0;
    phases.rho_gas = 2.0;
    phases.mu_liquid = 0.0;
    phases.mu_gas = 0.0;
    ViscosityOptions options;
    options.iteration.tolerance = 1e-14;
    const double dt = 0.1;
    const double c = dt * term->viscosity / (0.5 * 0.5 * 0.5);
    const SolveResult result = apply_viscosity(grid, interface, phases, FluidMode::two_phase,
                                               BoundaryOptions::all(BoundaryType::free_slip), dt, options);
    EXPECT_TRUE(result.converged);
    EXPECT_GT(result.iterations, 0);
    const double ua = grid.u()(1, 1, 1), ub = grid.u()(2, 2, 1);
    EXPECT_NEAR(ua + ub, 2.0, 1e-12);
    EXPECT_NEAR(ua - ub, 4.0 / (1.0 + 2.0 * c / phases.rho_liquid), 1e-12);
    // Every other face is untouched.
    EXPECT_EQ(grid.v().storage(), std::vector<double>(grid.v().size(), 0.0));
    // A term built for another grid is refused, naming the field.
    MacGrid other(5, 4, 4, 0.5);
    InterfaceInput wrong(other);
    wrong.surface_viscosity = term;
    EXPECT_THROW(apply_viscosity(other, wrong, phases, FluidMode::two_phase,
                                 BoundaryOptions::all(BoundaryType::free_slip), dt, options),
                 std::invalid_argument);
}

TEST(FluidViscosity, TaylorGreenModeIsAnExactDiscreteEigenmode) {
    // u = sin(πx) cos(πy), v = −cos(πx) sin(πy) on the free-slip unit square is discretely
    // divergence-free on the MAC grid and an eigenvector of the discrete ∇·(2με) with eigenvalue
    // −2μ k², k² = (2 sin(π dx/2) / dx)². One backward-Euler step scales it by 1/(1 + 2Δtνk²).
    const int n = 16;
    const double dx = 1.0 / n;
    MacGrid grid(n, n, 1, dx);
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i <= n; ++i) {
            const Eigen::Vector3d x = grid.face_centre(0, i, j, 0);
            grid.u()(i, j, 0) = std::sin(M_PI * x.x()) * std::cos(M_PI * x.y());
        }
    }
    for (int j = 0; j <= n; ++j) {
        for (int i = 0; i < n; ++i) {
            const Eigen::Vector3d x = grid.face_centre(1, i, j, 0);
            grid.v()(i, j, 0) = -std::cos(M_PI * x.x()) * std::sin(M_PI * x.y());
        }
    }
    const MacGrid initial = grid;
    InterfaceInput interface(grid);
    PhaseOptions phases;
    phases.rho_liquid = 2.0;
    phases.mu_liquid = 0.1;
    const double dt = 0.5;
    ViscosityOptions options;
    options.iteration.tolerance = 1e-13;
    const SolveResult result =
        apply_viscosity(grid, interface, phases, FluidMode::two_phase, BoundaryOptions{}, dt, options);
    ASSERT_TRUE(result.converged);
    const double k2 = std::pow(2.0 * std::sin(M_PI * dx / 2.0) / dx, 2);
    const double nu = phases.mu_liquid / phases.rho_liquid;
    const double factor = 1.0 / (1.0 + 2.0 * dt * nu * k2);
    double max_error = 0.0;
    for (int axis = 0; axis < 2; ++axis) {
        for (std::size_t f = 0; f < grid.velocity(axis).size(); ++f) {
            max_error = std::max(
                max_error, std::abs(grid.velocity(axis)[f] - factor * initial.velocity(axis)[f]));
        }
    }
    EXPECT_LT(max_error, 1e-10);
}

TEST(Viscosity, StopsWhenCancelled) {
    // A shear flow to diffuse: the CG loop checks the token every iteration.
    MacGrid grid(8, 8, 1, 0.125);
    for (int j = 0; j < 8; ++j)
        for (int i = 1; i < 8; ++i)
            grid.u()(i, j, 0) = j < 4 ? 1.0 : -1.0;
    InterfaceInput interface(grid);
    PhaseOptions phases;
    phases.mu_liquid = 1.0;
    std::atomic<bool> stop{true};
    ViscosityOptions options;
    options.iteration.cancel = CancellationToken(&stop);
    EXPECT_THROW(apply_viscosity(grid, interface, phases, FluidMode::two_phase,
                                 BoundaryOptions::all(BoundaryType::no_slip), 0.01, options),
                 Cancelled);
    stop = false;
    EXPECT_TRUE(apply_viscosity(grid, interface, phases, FluidMode::two_phase,
                                BoundaryOptions::all(BoundaryType::no_slip), 0.01, options)
                    .converged);
}

/// A cube of n³ cells of edge 1/n whose face velocities are a deterministic scramble (every
/// mode present), with zero normal velocity on the walls.
MacGrid scrambled_grid(int n) {
    MacGrid grid(n, n, n, 1.0 / n);
    for (int axis = 0; axis < 3; ++axis) {
        std::vector<double>& u = grid.velocity(axis).storage();
        for (std::size_t f = 0; f < u.size(); ++f)
            u[f] = std::sin(0.37 * static_cast<double>(f) + axis);
    }
    grid.zero_wall_normal_velocity();
    return grid;
}

TEST(FluidViscosity, ReusedSolverRebuildsForANewInterfaceOrStep) {
    // The solver keeps its operator while φ and Δt stay the same (the coupled scheme's Uzawa
    // passes); any change must rebuild it: every reused solve equals a fresh solver's, bit for bit.
    const int n = 10;
    const double dx = 1.0 / n;
    const MacGrid start = scrambled_grid(n);
    PhaseOptions phases;
    phases.rho_liquid = 1000.0;
    phases.rho_gas = 1.0;
    phases.mu_liquid = 1.0;
    phases.mu_gas = 0.01;
    const BoundaryOptions walls = BoundaryOptions::all(BoundaryType::no_slip);
    ViscosityOptions options;
    options.iteration.tolerance = 1e-10;
    const auto drop = [&](double radius) {
        InterfaceInput interface(start);
        for (int k = 0; k < n; ++k)
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i)
                    interface.phi(i, j, k) =
                        (Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5) * dx -
                         Eigen::Vector3d::Constant(0.5))
                            .norm() -
                        radius;
        return interface;
    };
    const InterfaceInput small = drop(0.2), large = drop(0.3);
    struct Case {
        const InterfaceInput* interface;
        double dt;
    };
    ViscositySolver reused;
    for (const Case& c : {Case{&small, 0.1}, Case{&small, 0.1}, Case{&large, 0.1},
                          Case{&large, 0.05}, Case{&small, 0.05}}) {
        MacGrid a = start, b = start;
        reused.solve(a, *c.interface, phases, FluidMode::two_phase, walls, c.dt, options);
        ViscositySolver fresh;
        fresh.solve(b, *c.interface, phases, FluidMode::two_phase, walls, c.dt, options);
        for (int axis = 0; axis < 3; ++axis)
            EXPECT_EQ(a.velocity(axis).storage(), b.velocity(axis).storage()) << "axis " << axis;
    }
}

TEST(FluidViscosity, MultigridAndHyprePreconditionersGiveTheJacobiAnswerInFewerIterations) {
    // A gas bubble in a very viscous liquid at a viscous diffusion number of order 10 (liquid)
    // and 10⁴ (gas): both preconditioners solve the same system, so the velocities agree to the
    // solver tolerance, and the V-cycles need several times fewer iterations. Both modes, one
    // wall of each type.
    const int n = 16;
    const double dx = 1.0 / n;
    const MacGrid start = scrambled_grid(n);
    InterfaceInput interface(start);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                interface.phi(i, j, k) =
                    0.3 - (Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5) * dx -
                           Eigen::Vector3d::Constant(0.5))
                              .norm();  // liquid outside the sphere
    PhaseOptions phases;
    phases.rho_liquid = 1000.0;
    phases.rho_gas = 1.0;
    phases.mu_liquid = 2.0;
    phases.mu_gas = 2e-3;
    BoundaryOptions walls = BoundaryOptions::all(BoundaryType::no_slip);
    walls.z_max.type = BoundaryType::free_slip;
    const double dt = 10.0 * phases.rho_liquid * dx * dx / phases.mu_liquid;
    for (FluidMode mode : {FluidMode::two_phase, FluidMode::free_surface}) {
        SCOPED_TRACE(mode == FluidMode::two_phase ? "two_phase" : "free_surface");
        ViscosityOptions jacobi;
        jacobi.iteration.tolerance = 1e-10;
        jacobi.preconditioner = ViscousPreconditioner::jacobi;
        ViscosityOptions multigrid = jacobi;
        multigrid.preconditioner = ViscousPreconditioner::multigrid;
        ViscosityOptions hypre = jacobi;
        hypre.preconditioner = ViscousPreconditioner::hypre_pfmg;
        MacGrid a = start, b = start, c = start;
        const SolveResult with_jacobi =
            apply_viscosity(a, interface, phases, mode, walls, dt, jacobi);
        const SolveResult with_multigrid =
            apply_viscosity(b, interface, phases, mode, walls, dt, multigrid);
        const SolveResult with_hypre =
            apply_viscosity(c, interface, phases, mode, walls, dt, hypre);
        ASSERT_TRUE(with_jacobi.converged);
        ASSERT_TRUE(with_multigrid.converged);
        ASSERT_TRUE(with_hypre.converged);
        std::printf("CG iterations: Jacobi %d, multigrid %d, hypre PFMG %d\n",
                    with_jacobi.iterations, with_multigrid.iterations, with_hypre.iterations);
        // Measured: two_phase 112 → 39 with the pointwise weights (the default; 2.9×), 3.3× and
        // more with the sharp ones; free_surface 100 → 18.
        EXPECT_LT(2.5 * with_multigrid.iterations, with_jacobi.iterations);
        EXPECT_LT(2.5 * with_hypre.iterations, with_jacobi.iterations);
        for (const MacGrid* other : {&b, &c}) {
            double largest = 0.0, difference = 0.0;
            for (int axis = 0; axis < 3; ++axis)
                for (std::size_t f = 0; f < a.velocity(axis).size(); ++f) {
                    largest = std::max(largest, std::abs(a.velocity(axis)[f]));
                    difference = std::max(difference,
                                          std::abs(a.velocity(axis)[f] - other->velocity(axis)[f]));
                }
            EXPECT_LT(difference, 1e-7 * largest);
        }
    }
    ViscosityOptions bad;
    bad.preconditioner = static_cast<ViscousPreconditioner>(7);
    EXPECT_THROW(bad.validate(), std::invalid_argument);
}

/// φ of a gas bubble of `radius` (m) at the centre of the grid's box (liquid outside, φ < 0).
Array3<double> centred_bubble(const MacGrid& grid, double radius) {
    Array3<double> phi(grid.nx(), grid.ny(), grid.nz());
    const Eigen::Vector3d centre =
        0.5 * grid.dx() * Eigen::Vector3d(grid.nx(), grid.ny(), grid.nz());
    for (int k = 0; k < grid.nz(); ++k)
        for (int j = 0; j < grid.ny(); ++j)
            for (int i = 0; i < grid.nx(); ++i)
                phi(i, j, k) = radius - (grid.cell_centre(i, j, k) - centre).norm();
    return phi;
}

TEST(FluidViscosity, OperatorsDiagonalIsTheProductsOnTheUnitVectors) {
    // diagonal() (interior faces by rows, the rest face by face) against e_f · A e_f for every
    // face of a bubble in water: unknowns within round-off, fixed faces 1.
    const int n[3] = {9, 8, 7};
    const double dx = 1e-3;
    for (const BoundaryType wall : {BoundaryType::no_slip, BoundaryType::free_slip}) {
        const MacGrid grid(n[0], n[1], n[2], dx);
        const Array3<double> phi = centred_bubble(grid, 2.6 * dx);
        ViscousOperator op;
        op.build(grid, phi, PhaseOptions{}, FluidMode::two_phase, BoundaryOptions::all(wall), 1e-4,
                 DEFAULT_MIN_LIQUID_FRACTION, ViscosityWeights::pointwise, nullptr);
        std::vector<double> d;
        op.diagonal(d);
        ASSERT_EQ(d.size(), op.size());
        std::vector<double> e(op.size(), 0.0), column;
        int unknowns = 0;
        for (std::size_t f = 0; f < op.size(); ++f) {
            if (!op.unknown()[f]) {
                EXPECT_EQ(d[f], 1.0) << f;
                continue;
            }
            ++unknowns;
            e[f] = 1.0;
            op.apply(e, column);
            e[f] = 0.0;
            EXPECT_NEAR(d[f], column[f], 1e-12 * column[f]) << f;
        }
        EXPECT_GT(unknowns, 1000);
    }
}

TEST(FluidViscosity, OperatorsFusedDotIsTheDotOfItsProduct) {
    // The viscous CG takes p·q from the operator's last pass, which also adds the mass term and
    // zeroes the fixed faces: the product bit for bit K x + ρ x on the unknowns (0 elsewhere),
    // the dot that of dot() to round-off and the same on 1 and 2 threads (a bubble in water,
    // no-slip walls, odd sizes over several tasks).
    const int n[3] = {37, 29, 33};
    const double dx = 1e-3;
    const MacGrid grid(n[0], n[1], n[2], dx);
    const Array3<double> phi = centred_bubble(grid, 8.0 * dx);
    ViscousOperator op;
    op.build(grid, phi, PhaseOptions{}, FluidMode::two_phase,
             BoundaryOptions::all(BoundaryType::no_slip), 1e-4, DEFAULT_MIN_LIQUID_FRACTION,
             ViscosityWeights::pointwise, nullptr);
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::vector<double> x(op.size()), y_plain, y_fused;
    for (std::size_t f = 0; f < x.size(); ++f)
        x[f] = op.unknown()[f] ? unit(rng) : 0.0;
    op.stiffness(x, y_plain);
    for (std::size_t f = 0; f < x.size(); ++f)
        y_plain[f] = op.unknown()[f] ? y_plain[f] + op.density()[f] * x[f] : 0.0;
    const double fused = op.apply_dot(x, y_fused);
    EXPECT_NEAR(fused, dot(x, y_plain), 1e-13 * std::abs(fused));
    EXPECT_GT(fused, 0.0);
    ASSERT_EQ(y_plain.size(), y_fused.size());
    for (std::size_t f = 0; f < y_plain.size(); ++f)
        ASSERT_EQ(y_plain[f], y_fused[f]) << f;
    std::vector<double> y_one_thread;
    double one_thread = 0.0;
    tbb::task_arena(1).execute([&] { one_thread = op.apply_dot(x, y_one_thread); });
    EXPECT_EQ(one_thread, fused);
}

}  // namespace
}  // namespace meniscus::fluid
