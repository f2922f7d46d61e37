// The grid split over MPI ranks (issue 40): the pressure solve and the whole coupled step of the
// bubble pair of bench_coupling (two 1.5 mm air bubbles in water, density ratio 1000, μ and σ of
// water, gravity, a 1 cm cube of N³ cells), on as many ranks as mpirun starts:
//
//   bench_distributed                                       # one process
//   mpirun -n 2 --bind-to none bench_distributed --threads 1   (as root: --allow-run-as-root)
//
// BM_PressureSolve/N: the first step's pressure system (the projection of the body force and
// the σκ jump, assembled on each rank's block) solved by hypre's PFMG-preconditioned PCG over the
// ranks to a relative residual of 1e-8 (fluid/distributed_projection.h); one process also times
// our multigrid PCG on the same system. BM_ViscousSolve/N/pc/mu: the implicit viscosity solve of
// the flow after one coupled step (Δt = 1e-4 s), with the liquid's μ = mu mPa·s (1: water,
// νΔt/Δx² ≈ 0.016 at 128³; 1000: a glycerol-like liquid, ≈ 16), to a relative residual of 1e-8,
// its CG preconditioned by pc = 0 the diagonal, 1 our multigrid V-cycles (one process only),
// 2 hypre's PFMG V-cycles (fluid/viscosity.h); the time includes building the operator and the
// preconditioner, as every step does. BM_CoupledStep/N: Simulation::step, one untimed step
// first, then MENISCUS_BENCH_CUBE_STEPS timed steps (default 3).
//
// Every rank runs every benchmark a fixed number of times (the collective calls must match);
// times are the slowest rank's (manual time). Rank 0 reports. Counters: µs of wall time per cell
// per step (whole grid), ranks, cells per rank, peak RSS of the largest rank (MB), bytes sent to
// other ranks per rank per step by our halo exchanges and gathers (hypre's own messages are not
// counted), reductions per step, and the step's phases in µs per cell per step.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "app/scene.h"
#include "app/scene_setup.h"
#include "bench/bubble_pair_cube.h"
#include "coupling/rasterize.h"
#include "coupling/simulation.h"
#include "coupling/surface_tension.h"
#include "fluid/distributed_projection.h"
#include "fluid/forces.h"
#include "fluid/rank_communicator.h"
#include "fluid/viscosity.h"

namespace {

using namespace meniscus;
using Clock = std::chrono::steady_clock;

fluid::RankCommunicator g_ranks = fluid::RankCommunicator::self();

int env_int(const char* name, int fallback) {
    const char* value = std::getenv(name);
    return value != nullptr ? std::max(1, std::atoi(value)) : fallback;
}

/// Peak resident memory of this process (MB), from /proc/self/status (VmHWM).
double peak_rss_mb() {
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
        if (line.rfind("VmHWM:", 0) == 0)
            return std::atof(line.c_str() + 6) / 1024.0;
    return 0.0;
}

std::unique_ptr<coupling::Simulation> make_simulation(int cells) {
    const app::Scene scene =
        bench::bubble_pair_cube(cells, R"("pressure_solver": "hypre_pfmg_pcg")");
    std::string report;
    double xi = 0.0;
    tracker::SurfaceMesh initial = app::build_initial_surface(scene, &report, &xi);
    return std::make_unique<coupling::Simulation>(
        app::make_fluid_simulation(scene, std::move(initial), xi, g_ranks));
}

void set_common_counters(benchmark::State& state, double cells, double steps,
                         const fluid::CommunicationCounts& before, int rank_cells) {
    const fluid::CommunicationCounts after = fluid::communication_counts();
    state.counters["ranks"] = g_ranks.size();
    state.counters["cells_per_rank"] = g_ranks.max(rank_cells);
    state.counters["peak_rss_MB"] = g_ranks.max(peak_rss_mb());
    state.counters["halo_MB_per_rank_step"] =
        g_ranks.max(static_cast<double>(after.exchanged_bytes - before.exchanged_bytes)) / 1e6 /
        steps;
    state.counters["reductions_per_step"] =
        static_cast<double>(after.reductions - before.reductions) / steps;
    state.counters["cells"] = cells;
}

void BM_PressureSolve(benchmark::State& state) {
    const int cells = static_cast<int>(state.range(0));
    const bool own = state.range(1) != 0;
    if (own && g_ranks.size() > 1) {
        state.SkipWithError("our multigrid PCG runs on one process only");
        for (auto _ : state)
            state.SetIterationTime(0.0);
        return;
    }
    const std::unique_ptr<coupling::Simulation> sim = make_simulation(cells);
    const fluid::FluidSolver& solver = sim->fluid();
    // The first step's system: the body force and the σκ jump of the bubbles at rest.
    fluid::MacGrid body = solver.grid();
    for (int a = 0; a < 3; ++a)
        body.velocity(a).fill(0.0);
    const double dt = 1e-4;
    fluid::apply_gravity(body, solver.options().gravity, dt, solver.grid_boundaries());
    solver.blocks().exchange(body);
    // φ and κ of the bubbles on this rank's block, as the coupled step makes them.
    const coupling::RasterizeResult raster =
        coupling::rasterize_mesh(sim->tracker().mesh(), solver.grid());
    fluid::InterfaceInput interface;
    coupling::face_curvatures(sim->tracker().mesh(), solver.grid(), raster, {}, interface);
    interface.phi = raster.phi;
    fluid::PressureOptions options = solver.options().pressure;
    options.iteration.tolerance = 1e-8;
    options.solver =
        own ? fluid::PressureSolver::multigrid_pcg : fluid::PressureSolver::hypre_pfmg_pcg;
    const fluid::CommunicationCounts before = fluid::communication_counts();
    long long iterations = 0, steps = 0;
    for (auto _ : state) {
        fluid::MacGrid grid = body;
        fluid::Array3<double> pressure;
        g_ranks.barrier();
        const auto start = Clock::now();
        const fluid::ProjectionResult r = fluid::project_block(
            grid, interface, solver.options().phases, solver.options().mode, dt, options, pressure,
            solver.options().boundaries, solver.blocks().decomposition(), g_ranks);
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        state.SetIterationTime(g_ranks.max(seconds));
        iterations += r.solve.iterations;
        ++steps;
    }
    const double whole = static_cast<double>(cells) * cells * cells;
    set_common_counters(state, whole, static_cast<double>(steps), before,
                        solver.grid().nx() * solver.grid().ny() *
                            (solver.blocks().decomposition().owned_end(g_ranks.rank()) -
                             solver.blocks().decomposition().owned_begin(g_ranks.rank())));
    state.counters["pcg_its"] = static_cast<double>(iterations) / static_cast<double>(steps);
    state.SetLabel(own ? "multigrid PCG (one process)" : "hypre PFMG-PCG");
}

void BM_ViscousSolve(benchmark::State& state) {
    const int cells = static_cast<int>(state.range(0));
    const auto kind = static_cast<fluid::ViscousPreconditioner>(state.range(1));
    const double mu_liquid = 1e-3 * static_cast<double>(state.range(2));
    if (kind == fluid::ViscousPreconditioner::multigrid && g_ranks.size() > 1) {
        state.SkipWithError("our multigrid V-cycles run on one process only");
        for (auto _ : state)
            state.SetIterationTime(0.0);
        return;
    }
    const std::unique_ptr<coupling::Simulation> sim = make_simulation(cells);
    const double dt = 1e-4;
    sim->step(dt);  // a velocity field to diffuse: the bubbles' first rise and the σκ jump
    const fluid::FluidSolver& solver = sim->fluid();
    const coupling::RasterizeResult raster =
        coupling::rasterize_mesh(sim->tracker().mesh(), solver.grid());
    fluid::InterfaceInput interface(solver.grid());
    interface.phi = raster.phi;
    fluid::PhaseOptions phases = solver.options().phases;
    phases.mu_liquid = mu_liquid;
    fluid::ViscosityOptions options = solver.options().viscosity;
    options.preconditioner = kind;
    options.iteration.tolerance = 1e-8;
    options.iteration.max_iterations = 100000;
    const fluid::CommunicationCounts before = fluid::communication_counts();
    long long iterations = 0, steps = 0;
    for (auto _ : state) {
        fluid::MacGrid grid = solver.grid();
        fluid::ViscositySolver viscosity;
        if (g_ranks.size() > 1)
            viscosity.distribute(solver.blocks().decomposition(), g_ranks);
        g_ranks.barrier();
        const auto start = Clock::now();
        const fluid::SolveResult r = viscosity.solve(grid, interface, phases, solver.options().mode,
                                                     solver.grid_boundaries(), dt, options);
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        state.SetIterationTime(g_ranks.max(seconds));
        if (!r.converged)
            state.SkipWithError("the viscous solve did not converge");
        iterations += r.iterations;
        ++steps;
    }
    const double whole = static_cast<double>(cells) * cells * cells;
    const fluid::SlabDecomposition& d = solver.blocks().decomposition();
    set_common_counters(state, whole, static_cast<double>(steps), before,
                        solver.grid().nx() * solver.grid().ny() *
                            (d.owned_end(g_ranks.rank()) - d.owned_begin(g_ranks.rank())));
    state.counters["cg_its"] = static_cast<double>(iterations) / static_cast<double>(steps);
    state.SetLabel(kind == fluid::ViscousPreconditioner::jacobi      ? "Jacobi CG"
                   : kind == fluid::ViscousPreconditioner::multigrid ? "multigrid-CG (one process)"
                                                                     : "hypre PFMG-CG");
}

void BM_CoupledStep(benchmark::State& state) {
    const int cells = static_cast<int>(state.range(0));
    const std::unique_ptr<coupling::Simulation> sim = make_simulation(cells);
    sim->step(0.01);  // builds the first pressure and the workspaces
    const fluid::CommunicationCounts before = fluid::communication_counts();
    double wall = 0.0, fluid_s = 0.0, pressure_s = 0.0, viscosity_s = 0.0, grid_side = 0.0,
           tracker_s = 0.0;
    long long steps = 0;
    for (auto _ : state) {
        g_ranks.barrier();
        const auto start = Clock::now();
        const coupling::SimulationStepReport report = sim->step(0.01);
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        state.SetIterationTime(g_ranks.max(seconds));
        wall += g_ranks.max(seconds);
        fluid_s += g_ranks.max(report.timings.fluid.wall);
        pressure_s += g_ranks.max(report.fluid.timings.pressure_build.wall +
                                  report.fluid.timings.pressure_solve.wall);
        viscosity_s += g_ranks.max(report.fluid.timings.viscosity.wall);
        grid_side += g_ranks.max(report.timings.rasterize.wall + report.timings.curvature.wall +
                                 report.timings.interpolate.wall);
        tracker_s +=
            g_ranks.max(report.timings.tracker.wall + report.timings.volume_correction.wall);
        ++steps;
    }
    const double whole = static_cast<double>(cells) * cells * cells;
    const double per = 1e6 / (whole * static_cast<double>(steps));
    const fluid::SlabDecomposition& d = sim->fluid().blocks().decomposition();
    set_common_counters(state, whole, static_cast<double>(steps), before,
                        sim->fluid().grid().nx() * sim->fluid().grid().ny() *
                            (d.owned_end(g_ranks.rank()) - d.owned_begin(g_ranks.rank())));
    state.counters["step_wall_us"] = wall * per;
    state.counters["fluid_wall_us"] = fluid_s * per;
    state.counters["pressure_wall_us"] = pressure_s * per;
    state.counters["viscosity_wall_us"] = viscosity_s * per;
    state.counters["grid_side_wall_us"] = grid_side * per;  // rasterize, curvature, interpolate
    state.counters["tracker_wall_us"] = tracker_s * per;    // tracker, volume correction
    state.counters["ghost_layers"] = d.ghost_layers();
}

const int CUBE_STEPS = env_int("MENISCUS_BENCH_CUBE_STEPS", 3);
BENCHMARK(BM_PressureSolve)
    ->ArgsProduct({{128, 192}, {0, 1}})
    ->ArgNames({"cells", "own"})
    ->Iterations(2)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ViscousSolve)
    ->ArgsProduct({{128}, {0, 1, 2}, {1, 1000}})
    ->ArgNames({"cells", "pc", "mu"})
    ->Iterations(2)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CoupledStep)
    ->Arg(128)
    ->Arg(192)
    ->ArgName("cells")
    ->Iterations(CUBE_STEPS)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

/// Reports nothing (the ranks other than 0).
class SilentReporter : public benchmark::BenchmarkReporter {
public:
    bool ReportContext(const Context&) override { return true; }
    void ReportRuns(const std::vector<Run>&) override {}
};

}  // namespace

int main(int argc, char** argv) {
    int threads = 0;
    std::vector<char*> args;
    for (int i = 0; i < argc; ++i) {
        if (std::strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
            threads = std::atoi(argv[++i]);
            continue;
        }
        args.push_back(argv[i]);
    }
    int count = static_cast<int>(args.size());
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      static_cast<std::size_t>(threads));
    if (fluid::launched_by_mpi_launcher())
        g_ranks = fluid::RankCommunicator::world();
    benchmark::Initialize(&count, args.data());
    if (g_ranks.rank() == 0) {
        benchmark::RunSpecifiedBenchmarks();
    } else {
        SilentReporter silent;
        benchmark::RunSpecifiedBenchmarks(&silent);
    }
    benchmark::Shutdown();
    return 0;
}
