// Pressure solvers: the backends agree on one system, the multigrid V-cycle and the fused PCG
// passes against their plain forms, single-precision V-cycles, cancellation.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "fluid/multigrid.h"
#include "fluid/pressure.h"
#include "pressure_test_support.h"

namespace meniscus::fluid {
namespace {

using pressure_test::add_gravity;
using pressure_test::tight_options;

TEST(FluidPressureBackends, AllBackendsAgreeOnABubbleSystem) {
    const int n = 20;
    MacGrid grid(n, n, n, 0.05);
    PhaseOptions phases;
    InterfaceInput interface(grid);
    for (int k = 0; k < n; ++k) {
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                interface.phi(i, j, k) =
                    0.3 - (grid.cell_centre(i, j, k) - Eigen::Vector3d(0.5, 0.5, 0.4)).norm();
            }
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        interface.kappa(axis).fill(-2.0 / 0.3);
    }
    add_gravity(grid, 1e-3);
    Array3<double> p_mic, p_mg, p_eigen;
    const PressureSystem system =
        build_pressure_system(grid, interface, phases, FluidMode::two_phase, 1e-3, {});
    ASSERT_TRUE(system.singular);
    ASSERT_TRUE(
        solve_pressure_system(system, tight_options(PressureSolver::mic0_pcg), p_mic).converged);
    ASSERT_TRUE(solve_pressure_system(system, tight_options(PressureSolver::multigrid_pcg), p_mg)
                    .converged);
    ASSERT_TRUE(solve_pressure_system(system, tight_options(PressureSolver::eigen_ic_cg), p_eigen)
                    .converged);
    double scale = 0.0, diff_mg = 0.0, diff_eigen = 0.0;
    for (std::size_t c = 0; c < p_mic.size(); ++c) {
        scale = std::max(scale, std::abs(p_mic[c]));
        diff_mg = std::max(diff_mg, std::abs(p_mg[c] - p_mic[c]));
        diff_eigen = std::max(diff_eigen, std::abs(p_eigen[c] - p_mic[c]));
    }
    EXPECT_LT(diff_mg, 1e-6 * scale);
    EXPECT_LT(diff_eigen, 1e-6 * scale);
}

TEST(FluidPressureBackends, OneSolverServesManyRightHandSidesLikeFreshSolves) {
    // The coupled scheme's passes reuse one preconditioner (its multigrid scratch vectors too):
    // every solve must equal a fresh solve_pressure_system() bit for bit, for each backend.
    const int n = 12;
    MacGrid grid(n, n, n, 0.05);
    PhaseOptions phases;
    InterfaceInput interface(grid);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                interface.phi(i, j, k) =
                    0.2 - (grid.cell_centre(i, j, k) - Eigen::Vector3d(0.3, 0.3, 0.25)).norm();
    for (int axis = 0; axis < 3; ++axis)
        interface.kappa(axis).fill(-2.0 / 0.2);
    add_gravity(grid, 1e-3);
    PressureSystem system =
        build_pressure_system(grid, interface, phases, FluidMode::two_phase, 1e-3, {});
    for (PressureSolver backend :
         {PressureSolver::mic0_pcg, PressureSolver::multigrid_pcg, PressureSolver::eigen_ic_cg}) {
        const PressureOptions options = tight_options(backend);
        const PressureSystemSolver solver(system, options);
        const std::vector<double> first = system.rhs;
        for (int round = 0; round < 3; ++round) {
            PressureSystem varied = system;
            for (std::size_t c = 0; c < varied.rhs.size(); ++c)
                varied.rhs[c] = first[c] * (1.0 + 0.5 * round) + 0.01 * std::sin(0.1 * c * round);
            Array3<double> reused, fresh;
            const SolveResult a = solver.solve(varied.rhs, reused);
            const SolveResult b = solve_pressure_system(varied, options, fresh);
            EXPECT_TRUE(a.converged);
            EXPECT_EQ(a.iterations, b.iterations);
            EXPECT_EQ(reused.storage(), fresh.storage()) << "round " << round;
        }
        Array3<double> unused;
        EXPECT_THROW(solver.solve(std::vector<double>(3, 0.0), unused), std::invalid_argument);
    }
}

/// Drops over a pool in a grid of `size` cells (dx = 1/32), random κ and random u* with the
/// walls' normal velocity zero.
struct ManyInterfaces {
    MacGrid grid;
    InterfaceInput interface;
};

ManyInterfaces many_interfaces(const int size[3], std::mt19937& rng) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double dx = 1.0 / 32;
    ManyInterfaces m{MacGrid(size[0], size[1], size[2], dx), InterfaceInput()};
    m.interface = InterfaceInput(m.grid);
    const Eigen::Vector3d extent = dx * Eigen::Vector3d(size[0], size[1], size[2]);
    std::vector<Eigen::Vector3d> centres;
    std::vector<double> radii;
    for (int s = 0; s < 5; ++s) {
        centres.push_back(extent.cwiseProduct(Eigen::Vector3d(unit(rng), unit(rng), unit(rng))));
        radii.push_back((0.05 + 0.2 * unit(rng)) * extent.minCoeff());
    }
    for (int k = 0; k < size[2]; ++k) {
        for (int j = 0; j < size[1]; ++j) {
            for (int i = 0; i < size[0]; ++i) {
                const Eigen::Vector3d x = m.grid.cell_centre(i, j, k);
                double phi = x.z() - 0.3 * extent.z();
                for (int s = 0; s < 5; ++s) {
                    phi = std::min(phi, (x - centres[s]).norm() - radii[s]);
                }
                m.interface.phi(i, j, k) = phi;
            }
        }
    }
    for (int axis = 0; axis < 3; ++axis) {
        for (double& kappa : m.interface.kappa(axis).storage()) {
            kappa = 10.0 * unit(rng);
        }
        for (double& velocity : m.grid.velocity(axis).storage()) {
            velocity = unit(rng) - 0.5;
        }
    }
    m.grid.zero_wall_normal_velocity();
    return m;
}

/// max |a − reference| over max |reference|.
double max_relative_difference(const std::vector<double>& a, const std::vector<double>& reference) {
    double scale = 0.0, difference = 0.0;
    for (std::size_t c = 0; c < reference.size(); ++c) {
        scale = std::max(scale, std::abs(reference[c]));
        difference = std::max(difference, std::abs(a[c] - reference[c]));
    }
    return difference / scale;
}

TEST(FluidPressureBackends, MultigridMatchesMic0OnOddGridsWithManyInterfaces) {
    // Odd, unequal grid sizes (ragged coarsening), drops over a pool, random κ and u*: the
    // multigrid preconditioner must give the same pressure as MIC(0) in both modes.
    std::mt19937 rng(3);
    const int sizes[2][3] = {{19, 42, 9}, {35, 27, 41}};
    for (const auto& size : sizes) {
        const ManyInterfaces m = many_interfaces(size, rng);
        PhaseOptions phases;
        phases.rho_liquid = 1000.0;
        phases.rho_gas = 1.0;
        for (FluidMode mode : {FluidMode::two_phase, FluidMode::free_surface}) {
            const PressureSystem system =
                build_pressure_system(m.grid, m.interface, phases, mode, 1e-3, PressureOptions{});
            Array3<double> p_mic, p_mg;
            PressureOptions options = tight_options(PressureSolver::mic0_pcg);
            options.iteration.tolerance = 1e-9;
            ASSERT_TRUE(solve_pressure_system(system, options, p_mic).converged);
            options.solver = PressureSolver::multigrid_pcg;
            const SolveResult mg = solve_pressure_system(system, options, p_mg);
            ASSERT_TRUE(mg.converged);
            EXPECT_LT(mg.iterations, 30);
            EXPECT_LT(max_relative_difference(p_mg.storage(), p_mic.storage()), 1e-6);
        }
    }
}

TEST(FluidPressureBackends, PipelinedSweepsGiveTheSameVCycleBitForBit) {
    // The pipelined red–black sweep (a slab's planes in one pass, its first and last planes'
    // second colour after all slabs) must reproduce the two half sweeps exactly: plane counts
    // below, at and across the slab size, one and two smoothing sweeps.
    std::mt19937 rng(7);
    const int sizes[4][3] = {{19, 42, 9}, {35, 27, 41}, {12, 10, 16}, {17, 9, 33}};
    PhaseOptions phases;
    phases.rho_liquid = 1000.0;
    phases.rho_gas = 1.0;
    for (const auto& size : sizes) {
        const ManyInterfaces m = many_interfaces(size, rng);
        const PressureSystem system = build_pressure_system(
            m.grid, m.interface, phases, FluidMode::two_phase, 1e-3, PressureOptions{});
        for (int sweeps : {1, 2}) {
            MultigridOptions options;
            options.smoothing_sweeps = sweeps;
            options.pipelined_sweeps = false;
            const MultigridPreconditioner plain(system.matrix, options);
            options.pipelined_sweeps = true;
            const MultigridPreconditioner pipelined(system.matrix, options);
            ASSERT_GT(plain.levels(), 1);
            std::vector<double> z_plain, z_pipelined;
            plain.apply(system.rhs, z_plain);
            pipelined.apply(system.rhs, z_pipelined);
            ASSERT_EQ(z_plain.size(), z_pipelined.size());
            std::size_t differing = 0;
            for (std::size_t c = 0; c < z_plain.size(); ++c)
                differing += z_plain[c] != z_pipelined[c] ? 1 : 0;
            EXPECT_EQ(differing, 0u)
                << size[0] << "x" << size[1] << "x" << size[2] << ", " << sweeps << " sweeps";
        }
    }
}

/// The textbook PCG, one vector operation at a time, projecting r and z onto zero mean every
/// iteration when `singular`: the reference for solve_pcg()'s fused passes.
SolveResult textbook_pcg(const PoissonMatrix& a, const std::vector<double>& b,
                         const Preconditioner& m, double tolerance, bool singular,
                         std::vector<double>& x) {
    const std::size_t n = a.size();
    x.assign(n, 0.0);
    std::vector<double> r = b, z, p, q;
    for (std::size_t c = 0; c < n; ++c)
        if (a.diag[c] <= 0.0)
            r[c] = 0.0;
    if (singular)
        remove_active_mean(a, r);
    const double b_norm = std::sqrt(dot(r, r));
    m.apply(r, z);
    if (singular)
        remove_active_mean(a, z);
    p = z;
    double rz = dot(r, z);
    SolveResult result;
    for (int iteration = 1; iteration <= 1000; ++iteration) {
        a.apply(p, q);
        const double alpha = rz / dot(p, q);
        axpy(alpha, p, x);
        axpy(-alpha, q, r);
        if (singular)
            remove_active_mean(a, r);
        result.iterations = iteration;
        result.residual = std::sqrt(dot(r, r)) / b_norm;
        if (result.residual <= tolerance) {
            result.converged = true;
            break;
        }
        m.apply(r, z);
        if (singular)
            remove_active_mean(a, z);
        const double rz_new = dot(r, z);
        xpby(z, rz_new / rz, p);
        rz = rz_new;
    }
    if (singular)
        remove_active_mean(a, x);
    return result;
}

TEST(FluidPressureBackends, FusedPcgFollowsTheTextbookIterates) {
    // solve_pcg() fuses its vector work into four passes and removes z's mean through sums
    // (r's only at the start): on a pure-Neumann two-phase system, a free-surface one with
    // inactive cells and a Dirichlet one, the same iterations (±1) and solution as the
    // one-operation-at-a-time PCG, with zero mean and zero inactive entries.
    std::mt19937 rng(13);
    const int size[3] = {23, 19, 27};
    PhaseOptions phases;
    phases.rho_liquid = 1000.0;
    phases.rho_gas = 1.0;
    const ManyInterfaces m = many_interfaces(size, rng);
    BoundaryOptions outflow;
    outflow.face(2, 1).type = BoundaryType::outflow;
    const std::tuple<FluidMode, BoundaryOptions, bool> cases[] = {
        {FluidMode::two_phase, BoundaryOptions{}, true},
        {FluidMode::free_surface, BoundaryOptions{}, false},
        {FluidMode::two_phase, outflow, false}};
    for (const auto& [mode, boundaries, singular] : cases) {
        const PressureSystem system = build_pressure_system(m.grid, m.interface, phases, mode, 1e-3,
                                                            PressureOptions{}, boundaries);
        ASSERT_EQ(system.singular, singular);
        const MultigridPreconditioner preconditioner(system.matrix);
        IterativeSolverOptions iteration;
        iteration.tolerance = 1e-10;
        iteration.max_iterations = 1000;
        std::vector<double> fused, textbook;
        const SolveResult a =
            solve_pcg(system.matrix, system.rhs, preconditioner, iteration, singular, fused);
        const SolveResult b =
            textbook_pcg(system.matrix, system.rhs, preconditioner, 1e-10, singular, textbook);
        ASSERT_TRUE(a.converged);
        ASSERT_TRUE(b.converged);
        EXPECT_LE(std::abs(a.iterations - b.iterations), 1);
        double scale = 0.0, difference = 0.0, inactive = 0.0, sum = 0.0;
        for (std::size_t c = 0; c < fused.size(); ++c) {
            scale = std::max(scale, std::abs(textbook[c]));
            difference = std::max(difference, std::abs(fused[c] - textbook[c]));
            if (system.matrix.diag[c] > 0.0) {
                sum += fused[c];
            } else {
                inactive = std::max(inactive, std::abs(fused[c]));
            }
        }
        EXPECT_LT(difference, 1e-8 * scale);
        EXPECT_EQ(inactive, 0.0);
        if (singular) {
            EXPECT_LT(std::abs(sum), 1e-9 * scale * static_cast<double>(fused.size()));
        }
    }
}

TEST(FluidPressureBackends, FusedJacobiCgPassesGiveTheSeparateOperationsBitForBit) {
    // Several of the reductions' chunks and a ragged last one.
    const std::size_t n = 70001;
    std::mt19937 random(11);
    std::uniform_real_distribution<double> value(-1.0, 1.0), positive(0.5, 4.0);
    std::vector<double> b(n), q(n), d(n), p0(n), x0(n);
    for (std::size_t c = 0; c < n; ++c) {
        b[c] = value(random);
        q[c] = value(random);
        d[c] = positive(random);
        p0[c] = value(random);
        x0[c] = value(random);
    }
    // The start: r = b − q, z = r / d, p = z, r·r and r·z.
    std::vector<double> r(n), z(n);
    for (std::size_t c = 0; c < n; ++c) {
        r[c] = b[c] - q[c];
        z[c] = r[c] / d[c];
    }
    std::vector<double> fused_r, fused_z, fused_p;
    const ResidualDots start = jacobi_cg_start(b, q, d, fused_r, fused_z, fused_p);
    EXPECT_EQ(fused_r, r);
    EXPECT_EQ(fused_z, z);
    EXPECT_EQ(fused_p, z);
    EXPECT_EQ(start.rr, dot(r, r));
    EXPECT_EQ(start.rz, dot(r, z));
    // An update: x += αp, r −= αq, z = r / d, r·r and r·z.
    const double alpha = 0.37;
    std::vector<double> x = x0;
    axpy(alpha, p0, x);
    axpy(-alpha, q, r);
    for (std::size_t c = 0; c < n; ++c)
        z[c] = r[c] / d[c];
    std::vector<double> fused_x = x0;
    const ResidualDots update = jacobi_cg_update(alpha, p0, q, d, fused_x, fused_r, fused_z);
    EXPECT_EQ(fused_x, x);
    EXPECT_EQ(fused_r, r);
    EXPECT_EQ(fused_z, z);
    EXPECT_EQ(update.rr, dot(r, r));
    EXPECT_EQ(update.rz, dot(r, z));
}

TEST(FluidPressureBackends, SinglePrecisionVCyclesConvergeLikeDoubleOnes) {
    // The float V-cycle inside the double PCG: on odd grids with drops over a pool at density
    // ratio 1000 (and free surfaces), to a relative residual of 1e-10 — far below float's
    // rounding — the same iterations (±1) and the same pressure as the double cycle.
    std::mt19937 rng(11);
    const int sizes[2][3] = {{19, 42, 9}, {35, 27, 41}};
    PhaseOptions phases;
    phases.rho_liquid = 1000.0;
    phases.rho_gas = 1.0;
    for (const auto& size : sizes) {
        const ManyInterfaces m = many_interfaces(size, rng);
        for (FluidMode mode : {FluidMode::two_phase, FluidMode::free_surface}) {
            const PressureSystem system =
                build_pressure_system(m.grid, m.interface, phases, mode, 1e-3, PressureOptions{});
            PressureOptions options = tight_options(PressureSolver::multigrid_pcg);
            ASSERT_TRUE(options.multigrid.single_precision);  // the default
            ASSERT_TRUE(
                MultigridPreconditioner(system.matrix, options.multigrid).single_precision());
            Array3<double> p_float, p_double;
            const SolveResult single = solve_pressure_system(system, options, p_float);
            options.multigrid.single_precision = false;
            ASSERT_FALSE(
                MultigridPreconditioner(system.matrix, options.multigrid).single_precision());
            const SolveResult twice = solve_pressure_system(system, options, p_double);
            ASSERT_TRUE(single.converged);
            ASSERT_TRUE(twice.converged);
            EXPECT_LE(std::abs(single.iterations - twice.iterations), 1)
                << single.iterations << " float-cycle vs " << twice.iterations << " iterations";
            EXPECT_LT(max_relative_difference(p_float.storage(), p_double.storage()), 1e-8);
        }
    }
}

TEST(FluidPressureBackends, SinglePrecisionVCyclesScaleWhatLeavesFloatsRange) {
    // A system 2^200 times larger (matrix and right-hand side: beyond float's 3.4e38) and a
    // right-hand side 2^-200 times smaller (below float's 1.2e-38): the float cycle scales both
    // by powers of two, so PCG takes the same iterations and gives the scaled pressure.
    std::mt19937 rng(5);
    const int size[3] = {21, 18, 23};
    PhaseOptions phases;
    phases.rho_liquid = 1000.0;
    phases.rho_gas = 1.0;
    const ManyInterfaces m = many_interfaces(size, rng);
    const PressureSystem system = build_pressure_system(
        m.grid, m.interface, phases, FluidMode::two_phase, 1e-3, PressureOptions{});
    const IterativeSolverOptions iteration = tight_options(PressureSolver::multigrid_pcg).iteration;
    std::vector<double> x_plain;
    const SolveResult plain =
        solve_pcg(system.matrix, system.rhs, MultigridPreconditioner(system.matrix), iteration,
                  system.singular, x_plain);
    ASSERT_TRUE(plain.converged);
    const double big = std::ldexp(1.0, 200);
    PoissonMatrix scaled = system.matrix;
    for (Array3<double>* part : {&scaled.diag, &scaled.off_x, &scaled.off_y, &scaled.off_z})
        for (double& v : part->storage())
            v *= big;
    std::vector<double> b_big = system.rhs, b_small = system.rhs;
    for (std::size_t c = 0; c < b_big.size(); ++c) {
        b_big[c] *= big;
        b_small[c] /= big;
    }
    const MultigridPreconditioner large(scaled);
    EXPECT_TRUE(large.single_precision());
    std::vector<double> x_big, x_small;
    const SolveResult both = solve_pcg(scaled, b_big, large, iteration, system.singular, x_big);
    const SolveResult small =
        solve_pcg(system.matrix, b_small, MultigridPreconditioner(system.matrix), iteration,
                  system.singular, x_small);
    ASSERT_TRUE(both.converged);
    ASSERT_TRUE(small.converged);
    EXPECT_EQ(both.iterations, plain.iterations);
    EXPECT_EQ(small.iterations, plain.iterations);
    double scale = 0.0, big_difference = 0.0, small_difference = 0.0;
    for (std::size_t c = 0; c < x_plain.size(); ++c) {
        scale = std::max(scale, std::abs(x_plain[c]));
        big_difference = std::max(big_difference, std::abs(x_big[c] - x_plain[c]));
        small_difference = std::max(small_difference, std::abs(x_small[c] * big - x_plain[c]));
    }
    EXPECT_LT(big_difference, 1e-8 * scale);
    EXPECT_LT(small_difference, 1e-8 * scale);
}

TEST(FluidPressureBackends, AMatrixSpanningMoreThanFloatsRangeCyclesInDouble) {
    // One unknown whose diagonal is 1e-32 of the others' (decoupled from its neighbours): in
    // float, scaled to the largest entry, it would underflow (an unknown dropped), so the
    // preconditioner asked for float cycles in double: the same z, bit for bit.
    const int n = 12;
    PoissonMatrix a;
    a.resize(n, n, n);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                a.diag(i, j, k) = 7.0;  // a Dirichlet part of 1 keeps it definite
                if (i + 1 < n)
                    a.off_x(i, j, k) = -1.0;
                if (j + 1 < n)
                    a.off_y(i, j, k) = -1.0;
                if (k + 1 < n)
                    a.off_z(i, j, k) = -1.0;
            }
    const int c = 5;
    a.off_x(c - 1, c, c) = a.off_x(c, c, c) = 0.0;
    a.off_y(c, c - 1, c) = a.off_y(c, c, c) = 0.0;
    a.off_z(c, c, c - 1) = a.off_z(c, c, c) = 0.0;
    MultigridOptions single, twice;
    twice.single_precision = false;
    EXPECT_TRUE(MultigridPreconditioner(a, single).single_precision());
    a.diag(c, c, c) = 7e-32;
    const MultigridPreconditioner asked_single(a, single);
    EXPECT_FALSE(asked_single.single_precision());
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::vector<double> r(a.size()), z_asked, z_double;
    for (double& v : r)
        v = unit(rng);
    asked_single.apply(r, z_asked);
    MultigridPreconditioner(a, twice).apply(r, z_double);
    ASSERT_EQ(z_asked.size(), z_double.size());
    for (std::size_t cell = 0; cell < z_asked.size(); ++cell)
        ASSERT_EQ(z_asked[cell], z_double[cell]) << cell;
    EXPECT_NEAR(z_asked[a.diag.index(c, c, c)] * 7e-32, r[a.diag.index(c, c, c)], 1e-12);
}

TEST(FluidPressureBackends, PcgStopsWhenCancelled) {
    // A random velocity to project; a requested stop throws from the first PCG iteration.
    const int n = 12;
    MacGrid grid(n, n, n, 1.0 / n);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> random(-1.0, 1.0);
    for (int axis = 0; axis < 3; ++axis)
        for (double& value : grid.velocity(axis).storage())
            value = random(rng);
    grid.zero_wall_normal_velocity();
    const InterfaceInput interface(grid);
    for (PressureSolver solver : {PressureSolver::multigrid_pcg, PressureSolver::mic0_pcg}) {
        std::atomic<bool> stop{true};
        PressureOptions options = tight_options(solver);
        options.iteration.cancel = CancellationToken(&stop);
        Array3<double> pressure;
        MacGrid copy = grid;
        EXPECT_THROW(
            project(copy, interface, PhaseOptions{}, FluidMode::two_phase, 1e-3, options, pressure),
            Cancelled);
        stop = false;
        copy = grid;
        EXPECT_TRUE(
            project(copy, interface, PhaseOptions{}, FluidMode::two_phase, 1e-3, options, pressure)
                .solve.converged);
    }
}

}  // namespace
}  // namespace meniscus::fluid
