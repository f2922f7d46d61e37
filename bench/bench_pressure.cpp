// Pressure Poisson solve on a 128³ box of water with a gas bubble (density ratio 1000), to a
// relative residual of 1e-6, with every backend side by side; and a stream copy to put the bytes
// each PCG iteration moves next to the machine's memory bandwidth.
//
// Run: bench_pressure [--benchmark_filter=...]; MENISCUS_BENCH_CELLS=<n> changes the grid size.
// The `_1thread` / `_2threads` cases cap TBB's parallelism (hypre itself is sequential here: one
// MPI process, Debian's libHYPRE built without OpenMP); their setup_s is the preconditioner's
// set-up (for hypre: grid, matrix copy and the PCG/PFMG set-up), included in the solve time.
#include <benchmark/benchmark.h>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cstdlib>
#include <memory>
#include <vector>

#include "fluid/pressure.h"

namespace {

using meniscus::fluid::Array3;
using meniscus::fluid::FluidMode;
using meniscus::fluid::InterfaceInput;
using meniscus::fluid::MacGrid;
using meniscus::fluid::PhaseOptions;
using meniscus::fluid::PressureOptions;
using meniscus::fluid::PressureSolver;
using meniscus::fluid::PressureSystem;

constexpr int DEFAULT_CELLS = 128;
constexpr double TOLERANCE = 1e-6;
constexpr int MAX_ITERATIONS = 5000;
constexpr double BUBBLE_RADIUS = 0.25;  // of the unit box
constexpr double TIME_STEP = 1e-3;      // s
constexpr double GRAVITY = 9.81;        // m/s², along −z
constexpr std::size_t BYTES_PER_DOUBLE = sizeof(double);
constexpr double GIGA = 1e9;

// Memory traffic model per PCG iteration, in doubles per cell, from the kernels in fluid/:
// PCG core (pure-Neumann system, pcg.cpp's four fused passes): A·p with p·q 6 (diag, 3
// off-diagonals, p, q), x and r updated with r·r and Σr 6, r·z with Σz 2, p = (z − mean) + βp 4
// (z, p, diag, p out).
constexpr double PCG_CORE_DOUBLES = 18.0;
// MIC(0): clear z 1, forward sweep 6 (r, pivot, 3 off-diagonals, q), backward sweep 6.
constexpr double MIC0_DOUBLES = 13.0;
// Multigrid V-cycle on the finest level, counted in doubles: four pipelined red-black pairs
// (multigrid.h), each streaming diag, 3 off-diagonals, b and x in and x out (7), plus an eighth
// of that again for the slab-edge planes of their second pass: 31.5; the residual 9; the
// restriction one axis at a time 2.6 and the prolongation 4.6 (their scratch arrays included) =
// 47.7. The cycle runs in float (the default): half of that, plus r into float (1.5) and the
// correction back into z (1.5): 26.85. Coarser levels add 1/8 + 1/64 + ... ≈ 1/7.
constexpr double MULTIGRID_DOUBLES = (47.7 / 2.0 + 3.0) * 8.0 / 7.0;
// Eigen IC-CG, per row: CSR A·p with 7 entries of 8-byte values and 4-byte indices (84 B) plus
// p and q (16 B); two triangular solves with the IC factor (≈ 4 entries per row each, 96 B,
// plus 32 B of vectors); CG vector updates and dots (≈ 10 vectors, 80 B): about 308 B.
constexpr double EIGEN_IC_CG_BYTES = 308.0;

int grid_cells() {
    const char* text = std::getenv("MENISCUS_BENCH_CELLS");
    return text != nullptr ? std::atoi(text) : DEFAULT_CELLS;
}

/// Water with a gas bubble at rest; u* is one step of gravity, κ = −2/R on the crossed faces.
const PressureSystem& bubble_system() {
    static const std::unique_ptr<PressureSystem> system = [] {
        const int n = grid_cells();
        MacGrid grid(n, n, n, 1.0 / n);
        InterfaceInput interface(grid);
        const Eigen::Vector3d centre(0.5, 0.5, 0.5);
        for (int k = 0; k < n; ++k) {
            for (int j = 0; j < n; ++j) {
                for (int i = 0; i < n; ++i) {
                    interface.phi(i, j, k) =
                        BUBBLE_RADIUS - (grid.cell_centre(i, j, k) - centre).norm();
                }
            }
        }
        for (int axis = 0; axis < 3; ++axis) {
            interface.kappa(axis).fill(-2.0 / BUBBLE_RADIUS);
        }
        for (int k = 1; k < n; ++k) {
            for (int j = 0; j < n; ++j) {
                for (int i = 0; i < n; ++i) {
                    grid.w()(i, j, k) = -GRAVITY * TIME_STEP;
                }
            }
        }
        PhaseOptions phases;
        phases.rho_liquid = 1000.0;
        phases.rho_gas = 1.0;
        phases.sigma = 0.0728;
        return std::make_unique<PressureSystem>(meniscus::fluid::build_pressure_system(
            grid, interface, phases, FluidMode::two_phase, TIME_STEP, PressureOptions{}));
    }();
    return *system;
}

double bytes_per_iteration(PressureSolver solver, std::size_t cells) {
    switch (solver) {
        case PressureSolver::mic0_pcg:
            return (PCG_CORE_DOUBLES + MIC0_DOUBLES) * BYTES_PER_DOUBLE * cells;
        case PressureSolver::multigrid_pcg:
            return (PCG_CORE_DOUBLES + MULTIGRID_DOUBLES) * BYTES_PER_DOUBLE * cells;
        case PressureSolver::eigen_ic_cg:
            return EIGEN_IC_CG_BYTES * cells;
        case PressureSolver::hypre_pfmg_pcg:
            return 0.0;  // no traffic model for hypre's kernels
    }
    return 0.0;
}

/// `threads` > 0 caps TBB's parallelism for the whole case (0: TBB's default).
void BM_PressureSolve(benchmark::State& state, PressureSolver solver, int max_iterations,
                      int threads = 0) {
    std::unique_ptr<tbb::global_control> cap;
    if (threads > 0)
        cap = std::make_unique<tbb::global_control>(
            tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    const PressureSystem& system = bubble_system();
    PressureOptions options;
    options.solver = solver;
    options.iteration.tolerance = TOLERANCE;
    options.iteration.max_iterations = max_iterations;
    Array3<double> pressure;
    meniscus::fluid::SolveResult result;
    for (auto _ : state) {
        result = meniscus::fluid::solve_pressure_system(system, options, pressure);
        benchmark::DoNotOptimize(pressure.data());
    }
    // Preconditioner set-up time alone, to separate it from the iterations.
    double setup_seconds = 0.0;
    const auto start = std::chrono::steady_clock::now();
    if (solver == PressureSolver::mic0_pcg) {
        const meniscus::fluid::Mic0Preconditioner setup(system.matrix);
        setup_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    } else if (solver == PressureSolver::multigrid_pcg) {
        const meniscus::fluid::MultigridPreconditioner setup(system.matrix);
        setup_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        state.counters["levels"] = setup.levels();
    } else if (solver == PressureSolver::hypre_pfmg_pcg) {
        const meniscus::fluid::HypreStructSolver setup(system.matrix, system.singular);
        setup_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    const double bytes = bytes_per_iteration(solver, system.matrix.size());
    state.counters["cells"] = static_cast<double>(system.matrix.size());
    state.counters["cg_iterations"] = result.iterations;
    state.counters["residual"] = result.residual;
    state.counters["converged"] = result.converged ? 1.0 : 0.0;
    state.counters["setup_s"] = setup_seconds;
    state.counters["MB_per_iteration"] = bytes / 1e6;
    // Effective bandwidth of the iterations: modelled bytes over wall time (the set-up is
    // included, so this is a lower bound; Eigen's IC factorisation is not timed separately).
    state.counters["iteration_GBps"] = benchmark::Counter(
        bytes * result.iterations / GIGA, benchmark::Counter::kIsIterationInvariantRate);
}

/// STREAM-style copy b ← a over arrays far larger than the caches; counts read + write bytes.
void BM_StreamCopy(benchmark::State& state) {
    const std::size_t count = static_cast<std::size_t>(state.range(0));
    const bool parallel = state.range(1) != 0;
    std::vector<double> a(count, 1.0), b(count, 0.0);
    for (auto _ : state) {
        if (parallel) {
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count),
                              [&](const tbb::blocked_range<std::size_t>& range) {
                                  for (std::size_t c = range.begin(); c != range.end(); ++c) {
                                      b[c] = a[c];
                                  }
                              });
        } else {
            for (std::size_t c = 0; c < count; ++c) {
                b[c] = a[c];
            }
        }
        benchmark::DoNotOptimize(b.data());
        benchmark::ClobberMemory();
    }
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                            static_cast<std::int64_t>(2 * count * BYTES_PER_DOUBLE));
}

constexpr std::int64_t STREAM_DOUBLES = std::int64_t{1} << 25;  // 256 MiB per array

}  // namespace

BENCHMARK(BM_StreamCopy)
    ->Args({STREAM_DOUBLES, 0})
    ->Args({STREAM_DOUBLES, 1})
    ->ArgNames({"doubles", "parallel"})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PressureSolve, mic0_pcg, PressureSolver::mic0_pcg, MAX_ITERATIONS)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_PressureSolve, multigrid_pcg, PressureSolver::multigrid_pcg, MAX_ITERATIONS)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_PressureSolve, eigen_ic_cg, PressureSolver::eigen_ic_cg, MAX_ITERATIONS)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);
// hypre PFMG-PCG against our multigrid PCG on one rank: one thread each, and the multigrid
// also on two (its V-cycle and vector kernels are TBB-parallel).
BENCHMARK_CAPTURE(BM_PressureSolve, hypre_pfmg_pcg_1thread, PressureSolver::hypre_pfmg_pcg,
                  MAX_ITERATIONS, 1)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_PressureSolve, multigrid_pcg_1thread, PressureSolver::multigrid_pcg,
                  MAX_ITERATIONS, 1)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_PressureSolve, multigrid_pcg_2threads, PressureSolver::multigrid_pcg,
                  MAX_ITERATIONS, 2)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);
// Eigen's CSR assembly and IncompleteCholesky factorisation plus a single CG iteration: subtract
// from the full solve to get Eigen's time per iteration.
BENCHMARK_CAPTURE(BM_PressureSolve, eigen_ic_cg_setup_and_1_iteration, PressureSolver::eigen_ic_cg,
                  1)
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kSecond);

BENCHMARK_MAIN();
