// The pressure system through hypre (issue 40): HYPRE_StructPCG + PFMG on one MPI process,
// against our multigrid-preconditioned CG on the systems the multigrid is tested on — a static
// drop and a bubble at density ratio 1000 with the ghost-fluid jump, a periodic box (even and odd
// cell counts), an outflow's Dirichlet faces, free-surface mode with inactive gas cells and a
// singular closed box — and the MPI set-up of a plain run (no mpirun; as root on CI).
#include <gtest/gtest.h>

#include <dirent.h>
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "fluid/forces.h"
#include "fluid/hypre_struct_solver.h"
#include "fluid/pressure.h"

namespace meniscus::fluid {
namespace {

constexpr double DX = 1e-3;  // m
constexpr double DT = 1e-3;  // s
/// Relative residual both solvers are asked for.
constexpr double TOL = 1e-9;
/// Allowed max |p_hypre − p_multigrid| over the pressure scale (max |p|). Two solutions with
/// relative residuals ≤ TOL differ by up to cond(A)·TOL in the worst case; what both solvers
/// reach measures 1e-11–1e-8 on these systems (printed), so 1e-6 leaves room without letting a
/// wrong matrix (a sign, a missing seam or Dirichlet face gives O(1) differences) through.
constexpr double PRESSURE_AGREEMENT = 1e-6;
/// Allowed max |∇·u| after the projection, relative to its value before (residual TOL).
constexpr double DIVERGENCE_REDUCTION = 1e-6;

PressureOptions options_for(PressureSolver solver) {
    PressureOptions options;
    options.solver = solver;
    options.iteration.tolerance = TOL;
    options.iteration.max_iterations = 2000;
    return options;
}

BoundaryOptions walls_with(std::array<bool, 3> periodic) {
    BoundaryOptions boundaries = BoundaryOptions::all(BoundaryType::free_slip);
    for (int axis = 0; axis < 3; ++axis)
        if (periodic[static_cast<std::size_t>(axis)]) {
            boundaries.face(axis, 0).type = BoundaryType::periodic;
            boundaries.face(axis, 1).type = BoundaryType::periodic;
        }
    return boundaries;
}

PhaseOptions water_and_air() {
    PhaseOptions phases;
    phases.rho_liquid = 1000.0;
    phases.rho_gas = 1.0;
    phases.sigma = 0.072;
    return phases;
}

/// A sphere of radius `radius` at `centre`: `inside_liquid` a drop (φ < 0 inside), else a bubble;
/// distances to the nearest periodic image along the flagged axes; κ of the sphere on every face.
InterfaceInput sphere(const MacGrid& grid, const Eigen::Vector3d& centre, double radius,
                      bool inside_liquid, std::array<bool, 3> periodic = {false, false, false}) {
    InterfaceInput interface(grid);
    const Eigen::Vector3d size = grid.dx() * Eigen::Vector3d(grid.nx(), grid.ny(), grid.nz());
    for (int k = 0; k < grid.nz(); ++k)
        for (int j = 0; j < grid.ny(); ++j)
            for (int i = 0; i < grid.nx(); ++i) {
                Eigen::Vector3d d = grid.cell_centre(i, j, k) - centre;
                for (int a = 0; a < 3; ++a)
                    if (periodic[static_cast<std::size_t>(a)])
                        d[a] -= size[a] * std::round(d[a] / size[a]);
                const double distance = d.norm() - radius;
                interface.phi(i, j, k) = inside_liquid ? distance : -distance;
            }
    for (int axis = 0; axis < 3; ++axis)
        interface.kappa(axis).fill(inside_liquid ? 2.0 / radius : -2.0 / radius);
    return interface;
}

/// One case: the grid holds u*, the rest says how to build the system.
struct Case {
    const char* name;
    MacGrid grid;
    InterfaceInput interface;
    PhaseOptions phases;
    FluidMode mode;
    BoundaryOptions boundaries;
};

struct Comparison {
    SolveResult hypre, multigrid;
    double scale = 0.0;       ///< max |p_multigrid|, Pa
    double difference = 0.0;  ///< max |p_hypre − p_multigrid|, Pa
    double divergence_before = 0.0, divergence_after = 0.0;  ///< max |∇·u|, 1/s
    bool singular = false;
    std::size_t inactive = 0;
    double mean = 0.0;  ///< mean of hypre's pressure over the unknown cells, Pa
};

/// Solves the case's system with both solvers, then projects a copy of u* with hypre.
Comparison compare(const Case& c) {
    Comparison out;
    const PressureSystem system =
        build_pressure_system(c.grid, c.interface, c.phases, c.mode, DT,
                              options_for(PressureSolver::multigrid_pcg), c.boundaries);
    out.singular = system.singular;
    out.inactive = system.matrix.size() - system.matrix.active_count();
    Array3<double> p_hypre, p_mg;
    out.multigrid =
        solve_pressure_system(system, options_for(PressureSolver::multigrid_pcg), p_mg);
    out.hypre = solve_pressure_system(system, options_for(PressureSolver::hypre_pfmg_pcg), p_hypre);
    std::size_t unknowns = 0;
    for (std::size_t i = 0; i < p_mg.size(); ++i) {
        out.scale = std::max(out.scale, std::abs(p_mg[i]));
        out.difference = std::max(out.difference, std::abs(p_hypre[i] - p_mg[i]));
        if (system.matrix.diag[i] > 0.0) {
            out.mean += p_hypre[i];
            ++unknowns;
        } else {
            EXPECT_EQ(p_hypre[i], 0.0) << c.name << ": an inactive cell's pressure, cell " << i;
        }
    }
    out.mean /= static_cast<double>(std::max<std::size_t>(unknowns, 1));

    MacGrid projected = c.grid;
    out.divergence_before = max_fluid_divergence(projected, c.interface, c.mode);
    Array3<double> pressure;
    const ProjectionResult projection =
        project(projected, c.interface, c.phases, c.mode, DT,
                options_for(PressureSolver::hypre_pfmg_pcg), pressure, c.boundaries);
    out.divergence_after = projection.max_divergence;
    std::printf(
        "[ measured ] %s: hypre PFMG-PCG %d iterations (residual %.2e), multigrid PCG %d "
        "(%.2e); max |p_hypre - p_mg| = %.3e Pa of %.3e Pa (%.2e); max |div u| %.3e -> %.3e "
        "1/s; %s, %zu inactive cells\n",
        c.name, out.hypre.iterations, out.hypre.residual, out.multigrid.iterations,
        out.multigrid.residual, out.difference, out.scale, out.difference / out.scale,
        out.divergence_before, out.divergence_after, out.singular ? "singular" : "regular",
        out.inactive);
    return out;
}

void expect_agreement(const Comparison& r, const char* name) {
    EXPECT_TRUE(r.hypre.converged) << name << ": residual " << r.hypre.residual;
    EXPECT_LE(r.hypre.residual, TOL) << name;
    EXPECT_GT(r.hypre.iterations, 0) << name;
    EXPECT_TRUE(r.multigrid.converged) << name;
    EXPECT_GT(r.scale, 0.0) << name;
    EXPECT_LE(r.difference, PRESSURE_AGREEMENT * r.scale) << name;
    EXPECT_GT(r.divergence_before, 0.0) << name;
    EXPECT_LE(r.divergence_after, DIVERGENCE_REDUCTION * r.divergence_before) << name;
}

TEST(HyprePressure, StaticDropAtDensityRatio1000MatchesMultigrid) {
    // A water drop in air, its Laplace jump σκ on the crossed faces, one step of gravity as u*;
    // closed box: singular.
    const int n = 24;
    MacGrid grid(n, n, n, DX);
    const InterfaceInput interface =
        sphere(grid, DX * Eigen::Vector3d(12.3, 11.7, 12.1), 7.0 * DX, true);
    apply_gravity(grid, Eigen::Vector3d(0, 0, -9.81), DT, walls_with({false, false, false}));
    const Case c{"static drop 24^3", grid, interface, water_and_air(), FluidMode::two_phase,
                 walls_with({false, false, false})};
    const Comparison r = compare(c);
    EXPECT_TRUE(r.singular);
    EXPECT_NEAR(r.mean, 0.0, 1e-9 * r.scale);
    expect_agreement(r, c.name);
}

TEST(HyprePressure, BubbleAtDensityRatio1000OnARaggedGridMatchesMultigrid) {
    // An air bubble in water on 23 × 26 × 21 cells (odd, not powers of two).
    MacGrid grid(23, 26, 21, DX);
    const InterfaceInput interface =
        sphere(grid, DX * Eigen::Vector3d(11.0, 13.4, 9.6), 6.5 * DX, false);
    apply_gravity(grid, Eigen::Vector3d(0, 0, -9.81), DT, walls_with({false, false, false}));
    const Case c{"bubble 23x26x21", grid, interface, water_and_air(), FluidMode::two_phase,
                 walls_with({false, false, false})};
    const Comparison r = compare(c);
    EXPECT_TRUE(r.singular);
    EXPECT_NEAR(r.mean, 0.0, 1e-9 * r.scale);
    expect_agreement(r, c.name);
}

TEST(HyprePressure, PeriodicBoxWithABubbleAcrossEverySeamMatchesMultigrid) {
    // The bubble's centre near the corner: it crosses the seams of all three periodic axes.
    for (const int n : {16, 15}) {
        MacGrid grid(n, n, n, DX);
        const std::array<bool, 3> periodic = {true, true, true};
        const InterfaceInput interface =
            sphere(grid, DX * Eigen::Vector3d(0.1, 0.2, 0.3), 0.2 * n * DX, false, periodic);
        apply_gravity(grid, Eigen::Vector3d(0, 0, -9.81), DT, walls_with(periodic));
        // Gravity alone is balanced by a periodic system only through the bubble: add a random
        // flow so that every face, the seams' too, carries a velocity to project.
        std::mt19937 rng(5);
        std::uniform_real_distribution<double> random(-0.01, 0.01);
        for (int axis = 0; axis < 3; ++axis)
            for (double& value : grid.velocity(axis).storage())
                value += random(rng);
        apply_boundary_velocity(grid, walls_with(periodic));
        const std::string name = "periodic box " + std::to_string(n) + "^3";
        const Case c{name.c_str(), grid, interface, water_and_air(), FluidMode::two_phase,
                     walls_with(periodic)};
        const Comparison r = compare(c);
        EXPECT_TRUE(r.singular);
        expect_agreement(r, c.name);
    }
}

TEST(HyprePressure, PeriodicAlongOneAxisOnlyMatchesMultigrid) {
    // x periodic, the other axes walls, with an outflow on top: the seam and Dirichlet faces
    // together, 20 × 12 × 14 cells.
    MacGrid grid(20, 12, 14, DX);
    const std::array<bool, 3> periodic = {true, false, false};
    BoundaryOptions boundaries = walls_with(periodic);
    boundaries.z_max.type = BoundaryType::outflow;
    const InterfaceInput interface =
        sphere(grid, DX * Eigen::Vector3d(1.0, 6.0, 6.5), 4.0 * DX, true, periodic);
    apply_gravity(grid, Eigen::Vector3d(0, 0, -9.81), DT, boundaries);
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> random(-0.01, 0.01);
    for (int axis = 0; axis < 3; ++axis)
        for (double& value : grid.velocity(axis).storage())
            value += random(rng);
    apply_boundary_velocity(grid, boundaries);
    const Case c{"x-periodic drop, outflow top", grid, interface, water_and_air(),
                 FluidMode::two_phase, boundaries};
    const Comparison r = compare(c);
    EXPECT_FALSE(r.singular);
    expect_agreement(r, c.name);
}

TEST(HyprePressure, OutflowDirichletFacesMatchMultigrid) {
    // A bubble rising towards an outflow top at 50 Pa: a regular system, the Dirichlet faces
    // half a cell beyond the last cell centres.
    const int n = 24;
    MacGrid grid(n, n, n, DX);
    BoundaryOptions boundaries;
    boundaries.z_max.type = BoundaryType::outflow;
    boundaries.z_max.pressure = 50.0;
    const InterfaceInput interface =
        sphere(grid, DX * Eigen::Vector3d(12.0, 12.0, 9.0), 5.0 * DX, false);
    apply_gravity(grid, Eigen::Vector3d(0, 0, -9.81), DT, boundaries);
    const Case c{"outflow top 24^3", grid, interface, water_and_air(), FluidMode::two_phase,
                 boundaries};
    const Comparison r = compare(c);
    EXPECT_FALSE(r.singular);
    expect_agreement(r, c.name);
}

TEST(HyprePressure, FreeSurfaceWithInactiveGasCellsMatchesMultigrid) {
    // A pool below z = 0.4 of the box and a drop above it, free-surface mode: the gas cells are
    // not unknowns (identity rows in hypre), the liquid's faces to them are θ-weighted Dirichlet
    // faces at p = σκ; random u*.
    const int n = 24;
    MacGrid grid(n, n, n, DX);
    InterfaceInput interface = sphere(grid, DX * Eigen::Vector3d(12.0, 11.0, 16.5), 4.5 * DX, true);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                interface.phi(i, j, k) =
                    std::min(interface.phi(i, j, k), grid.cell_centre(i, j, k).z() - 0.4 * n * DX);
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> random(-0.05, 0.05);
    for (int axis = 0; axis < 3; ++axis)
        for (double& value : grid.velocity(axis).storage())
            value = random(rng);
    grid.zero_wall_normal_velocity();
    const Case c{"free surface 24^3", grid, interface, water_and_air(), FluidMode::free_surface,
                 walls_with({false, false, false})};
    const Comparison r = compare(c);
    EXPECT_FALSE(r.singular);
    EXPECT_GT(r.inactive, static_cast<std::size_t>(n * n * n / 2));
    expect_agreement(r, c.name);
}

TEST(HyprePressure, SingularClosedBoxMatchesMultigridWithZeroMean) {
    // All water, closed free-slip walls, random u*: pure Neumann with a compatible right-hand
    // side; hypre's pressure has zero mean, as the multigrid's.
    const int n = 20;
    MacGrid grid(n, n, n, DX);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> random(-1.0, 1.0);
    for (int axis = 0; axis < 3; ++axis)
        for (double& value : grid.velocity(axis).storage())
            value = random(rng);
    grid.zero_wall_normal_velocity();
    InterfaceInput interface(grid);  // φ < 0: liquid everywhere
    const Case c{"closed box 20^3", grid, interface, water_and_air(), FluidMode::two_phase,
                 walls_with({false, false, false})};
    const Comparison r = compare(c);
    EXPECT_TRUE(r.singular);
    EXPECT_NEAR(r.mean, 0.0, 1e-12 * r.scale);
    expect_agreement(r, c.name);
}

/// A bubble system for the solver-object tests.
PressureSystem bubble_system(int n) {
    MacGrid grid(n, n, n, DX);
    const InterfaceInput interface =
        sphere(grid, DX * Eigen::Vector3d(0.5 * n, 0.45 * n, 0.4 * n), 0.25 * n * DX, false);
    apply_gravity(grid, Eigen::Vector3d(0, 0, -9.81), DT, {});
    return build_pressure_system(grid, interface, water_and_air(), FluidMode::two_phase, DT, {});
}

TEST(HyprePressure, OneSolverServesManyRightHandSidesLikeFreshSolves) {
    const PressureSystem system = bubble_system(12);
    const PressureOptions options = options_for(PressureSolver::hypre_pfmg_pcg);
    const PressureSystemSolver solver(system, options);
    for (int round = 0; round < 3; ++round) {
        PressureSystem varied = system;
        for (std::size_t c = 0; c < varied.rhs.size(); ++c)
            varied.rhs[c] = system.rhs[c] * (1.0 + 0.5 * round) + 0.01 * std::sin(0.1 * c * round);
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

TEST(HyprePressure, OnePfmgCycleIsASymmetricPreconditionerThatReducesTheResidual) {
    // PressureSystemSolver::precondition() with hypre is one PFMG V-cycle: symmetric (as PCG and
    // the Uzawa passes need: ⟨M r1, r2⟩ = ⟨r1, M r2⟩) and a good approximate inverse.
    const PressureSystem system = bubble_system(16);
    const PressureSystemSolver solver(system, options_for(PressureSolver::hypre_pfmg_pcg));
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> random(-1.0, 1.0);
    std::vector<double> r1(system.rhs.size()), r2(system.rhs.size());
    for (std::size_t c = 0; c < r1.size(); ++c) {
        r1[c] = random(rng);
        r2[c] = random(rng);
    }
    remove_active_mean(system.matrix, r1);
    remove_active_mean(system.matrix, r2);
    Array3<double> z1, z2;
    const SolveResult once = solver.precondition(r1, z1);
    solver.precondition(r2, z2);
    EXPECT_EQ(once.iterations, 1);
    const double m12 = dot(z1.storage(), r2), m21 = dot(r1, z2.storage());
    const double m11 = dot(z1.storage(), r1);
    std::vector<double> residual;
    system.matrix.residual(z1.storage(), r1, residual);
    remove_active_mean(system.matrix, residual);
    const double reduction = std::sqrt(dot(residual, residual) / dot(r1, r1));
    std::printf("[ measured ] one PFMG V-cycle: <Mr1,r2> = %.6e, <r1,Mr2> = %.6e (asymmetry "
                "%.2e), <Mr1,r1> = %.3e > 0, residual reduced to %.3f of the input\n",
                m12, m21, std::abs(m12 - m21) / std::abs(m11), m11, reduction);
    EXPECT_GT(m11, 0.0);
    EXPECT_LE(std::abs(m12 - m21), 1e-10 * std::abs(m11));
    EXPECT_LT(reduction, 0.5);
}

TEST(HyprePressure, ACancelledSolveThrows) {
    const PressureSystem system = bubble_system(8);
    std::atomic<bool> stop{true};
    PressureOptions options = options_for(PressureSolver::hypre_pfmg_pcg);
    options.iteration.cancel = CancellationToken(&stop);
    Array3<double> pressure;
    EXPECT_THROW(solve_pressure_system(system, options, pressure), Cancelled);
    stop = false;
    EXPECT_TRUE(solve_pressure_system(system, options, pressure).converged);
}

TEST(HyprePressure, ANonConvergedSolveIsReportedNotThrown) {
    const PressureSystem system = bubble_system(16);
    PressureOptions options = options_for(PressureSolver::hypre_pfmg_pcg);
    options.iteration.max_iterations = 2;
    Array3<double> pressure;
    const SolveResult result = solve_pressure_system(system, options, pressure);
    EXPECT_FALSE(result.converged);
    EXPECT_EQ(result.iterations, 2);
    EXPECT_GT(result.residual, TOL);
}

/// Child processes of this process (from /proc/<pid>/task/*/children).
std::vector<std::string> child_processes() {
    std::vector<std::string> children;
    const std::string tasks = "/proc/" + std::to_string(getpid()) + "/task";
    DIR* dir = opendir(tasks.c_str());
    if (dir == nullptr)
        return children;
    while (const dirent* entry = readdir(dir)) {
        if (entry->d_name[0] == '.')
            continue;
        std::ifstream file(tasks + "/" + entry->d_name + "/children");
        std::string pid;
        while (file >> pid)
            children.push_back(pid);
    }
    closedir(dir);
    return children;
}

TEST(HyprePressure, PlainRunInitialisesMpiOnceWithoutAHelperDaemon) {
    // Without mpirun (as root on CI) MPI must come up by itself, as one process of its own: an
    // isolated singleton, no `orted` forked (see ensure_mpi_initialized()).
    ensure_mpi_initialized();
    ensure_mpi_initialized();  // idempotent
    int initialized = 0, size = 0, thread_level = 0;
    MPI_Initialized(&initialized);
    EXPECT_TRUE(initialized);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    EXPECT_EQ(size, 1);
    MPI_Query_thread(&thread_level);
    EXPECT_GE(thread_level, MPI_THREAD_SERIALIZED);
    const std::vector<std::string> children = child_processes();
    std::string listed;
    for (const std::string& pid : children) {
        std::ifstream comm("/proc/" + pid + "/comm");
        std::string name;
        comm >> name;
        listed += pid + " (" + name + ") ";
    }
    EXPECT_TRUE(children.empty()) << "child processes after MPI_Init: " << listed;
}

}  // namespace
}  // namespace meniscus::fluid
