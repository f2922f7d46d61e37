// The coupled step (Simulation::step) by phase, in µs of CPU and of wall time per cell per step.
//
// BM_DropMerge, BM_BubbleMerge: scenes/drop_merge.json and scenes/bubble_merge.json refined so
// that the longest box axis has 64 cells (MENISCUS_BENCH_CELLS), tracker edge =
// edge_length_cells · Δx as in the scene, MENISCUS_BENCH_STEPS steps (default 20) from the
// scene's initial state.
//
// BM_BubblePairCube/N/T: the resolution study of issue 36 — two 1.5 mm air bubbles in water
// (density ratio 1000, μ and σ of water, gravity) in a 1 cm cube of N³ cells, pushed towards
// each other as in bubble_merge, with T TBB threads (tbb::global_control). One untimed step
// first (it builds the first pressure and the solver's workspaces), then
// MENISCUS_BENCH_CUBE_STEPS timed steps (default 3); MENISCUS_BENCH_SCHUR sets
// /fluid/viscous_pressure/preconditioner (default v_cycle, as scenes); MENISCUS_BENCH_FLUID
// replaces that by any /fluid keys.
//
// Counters: <phase>_cpu_us and <phase>_wall_us, µs per cell per step, for the coupling's phases
// (rasterize, curvature, fluid, interpolate, volume_correction, tracker), the fluid step's
// (advection, forces, viscosity, pressure_build, pressure_solve, extrapolation) and the total;
// pcg_its, visc_cg_its, passes: pressure PCG and viscous CG iterations and the coupled scheme's
// Uzawa passes, per step.
// CPU is the process's (all threads), so at 2 threads CPU ≈ 2 × wall when both are busy. After
// the run a table of the same figures is printed, one column per benchmark.
//
// Run: bench_coupling [--benchmark_filter=Cube/128]
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "app/run.h"
#include "app/scene.h"
#include "app/scene_setup.h"
#include "bench/bubble_pair_cube.h"
#include "common/phase_clock.h"
#include "coupling/simulation.h"

namespace {

using namespace meniscus;

constexpr int DEFAULT_LONGEST_AXIS_CELLS = 64;
constexpr int DEFAULT_STEPS = 20;
constexpr int DEFAULT_CUBE_STEPS = 3;

int env_int(const char* name, int fallback) {
    const char* value = std::getenv(name);
    return value != nullptr ? std::max(1, std::atoi(value)) : fallback;
}

/// The scene `name` from scenes/, refined to `cells` along its longest axis.
app::Scene refined_scene(const std::string& name, int cells) {
    app::Scene scene = app::load_scene(std::string(MENISCUS_SCENES_DIR) + "/" + name + ".json");
    const Eigen::Vector3d& size = scene.domain.size;
    scene.domain.cells = static_cast<int>(std::lround(cells * size.x() / size.maxCoeff()));
    if (scene.coupling.edge_length_cells > 0.0)
        scene.surface.edge_length =
            scene.coupling.edge_length_cells * size.x() / scene.domain.cells;
    return scene;
}

/// bubble_pair_cube.h's scene with MENISCUS_BENCH_SCHUR's Schur preconditioner, or with the
/// /fluid keys of MENISCUS_BENCH_FLUID instead (JSON members, e.g. `"viscosity_scheme":
/// "explicit_when_stable", "viscous_pressure": {"coupling": "split"}`).
app::Scene bubble_pair_cube(int cells) {
    if (const char* fluid = std::getenv("MENISCUS_BENCH_FLUID"))
        return bench::bubble_pair_cube(cells, fluid);
    const char* schur_env = std::getenv("MENISCUS_BENCH_SCHUR");
    const std::string schur = schur_env != nullptr ? schur_env : "v_cycle";
    return bench::bubble_pair_cube(cells,
                                   R"("viscous_pressure": {"preconditioner": ")" + schur + R"("})");
}

/// Phase seconds summed over the timed steps.
struct PhaseTotals {
    std::vector<std::pair<std::string, PhaseSeconds>> phases;

    void add(const std::string& name, const PhaseSeconds& seconds) {
        for (auto& [n, s] : phases)
            if (n == name) {
                s += seconds;
                return;
            }
        phases.emplace_back(name, seconds);
    }

    void add(const coupling::SimulationStepReport& report) {
        const coupling::SimulationTimings& c = report.timings;
        const fluid::StepTimings& f = report.fluid.timings;
        add("rasterize", c.rasterize);
        add("curvature", c.curvature);
        add("fluid", c.fluid);
        add("  advection", f.advection);
        add("  forces", f.forces);
        add("  viscosity", f.viscosity);
        add("  pressure_build", f.pressure_build);
        add("  pressure_solve", f.pressure_solve);
        add("  extrapolation", f.extrapolation);
        add("interpolate", c.interpolate);
        add("volume_correction", c.volume_correction);
        add("tracker", c.tracker);
        add("total", c.total);
    }
};

/// µs per cell per step of every benchmark that ran, by phase: {benchmark: {phase: (cpu, wall)}}.
std::vector<std::pair<std::string, std::vector<std::pair<std::string, std::pair<double, double>>>>>
    g_table;

void coupled_steps(benchmark::State& state, const app::Scene& scene, int warmup_steps,
                   const std::string& label) {
    std::unique_ptr<coupling::Simulation> sim =
        std::make_unique<coupling::Simulation>(app::make_fluid_simulation(scene));
    const fluid::MacGrid& grid = sim->fluid().grid();
    const double cells = static_cast<double>(grid.nx()) * grid.ny() * grid.nz();
    for (int i = 0; i < warmup_steps; ++i)
        sim->step(scene.time.dt);
    const int initial_triangles = sim->tracker().mesh().count_live_triangles();
    PhaseTotals totals;
    double dt = 0.0;
    long long steps = 0, pressure_iterations = 0, viscosity_iterations = 0, passes = 0;
    for (auto _ : state) {
        const coupling::SimulationStepReport report = sim->step(scene.time.dt);
        totals.add(report);
        dt += report.dt;
        pressure_iterations += report.fluid.pressure.iterations;
        viscosity_iterations += report.fluid.viscosity.iterations;
        passes += report.fluid.passes;
        ++steps;
    }
    const double per = 1e6 / (cells * static_cast<double>(std::max<long long>(steps, 1)));
    std::vector<std::pair<std::string, std::pair<double, double>>> row;
    for (const auto& [name, seconds] : totals.phases) {
        std::string key = name;
        key.erase(0, key.find_first_not_of(' '));
        state.counters[key + "_cpu_us"] = seconds.cpu * per;
        state.counters[key + "_wall_us"] = seconds.wall * per;
        row.emplace_back(name, std::make_pair(seconds.cpu * per, seconds.wall * per));
    }
    const double n = static_cast<double>(std::max<long long>(steps, 1));
    state.counters["dt_s"] = dt / n;
    state.counters["pcg_its"] = static_cast<double>(pressure_iterations) / n;
    state.counters["visc_cg_its"] = static_cast<double>(viscosity_iterations) / n;
    state.counters["passes"] = static_cast<double>(passes) / n;
    state.counters["cells"] = cells;
    state.counters["tris_start"] = initial_triangles;
    state.counters["tris_end"] = sim->tracker().mesh().count_live_triangles();
    state.SetLabel(std::to_string(grid.nx()) + "x" + std::to_string(grid.ny()) + "x" +
                   std::to_string(grid.nz()) + " cells");
    g_table.emplace_back(label, std::move(row));
}

void BM_DropMerge(benchmark::State& state) {
    const int cells = env_int("MENISCUS_BENCH_CELLS", DEFAULT_LONGEST_AXIS_CELLS);
    coupled_steps(state, refined_scene("drop_merge", cells), 0,
                  "drop_merge " + std::to_string(cells));
}
void BM_BubbleMerge(benchmark::State& state) {
    const int cells = env_int("MENISCUS_BENCH_CELLS", DEFAULT_LONGEST_AXIS_CELLS);
    coupled_steps(state, refined_scene("bubble_merge", cells), 0,
                  "bubble_merge " + std::to_string(cells));
}

void BM_BubblePairCube(benchmark::State& state) {
    const int cells = static_cast<int>(state.range(0));
    const int threads = static_cast<int>(state.range(1));
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(threads));
    coupled_steps(state, bubble_pair_cube(cells), 1,
                  "cube " + std::to_string(cells) + "^3 " + std::to_string(threads) + "T");
}

const int STEPS = env_int("MENISCUS_BENCH_STEPS", DEFAULT_STEPS);
const int CUBE_STEPS = env_int("MENISCUS_BENCH_CUBE_STEPS", DEFAULT_CUBE_STEPS);
BENCHMARK(BM_DropMerge)->Iterations(STEPS)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BubbleMerge)->Iterations(STEPS)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BubblePairCube)
    ->ArgsProduct({{64, 128, 192}, {1, 2}})
    ->ArgNames({"cells", "threads"})
    ->Iterations(CUBE_STEPS)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// The table of µs per cell per step, CPU / wall, one column per benchmark that ran.
void print_table() {
    if (g_table.empty())
        return;
    std::printf("\nµs per cell per step, CPU / wall\n%-20s", "phase");
    for (const auto& [label, row] : g_table)
        std::printf(" | %-19s", label.c_str());
    std::printf("\n");
    for (std::size_t p = 0; p < g_table.front().second.size(); ++p) {
        std::printf("%-20s", g_table.front().second[p].first.c_str());
        for (const auto& [label, row] : g_table) {
            const auto& [cpu, wall] = row[p].second;
            std::printf(" | %8.3f / %8.3f", cpu, wall);
        }
        std::printf("\n");
    }
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv))
        return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    print_table();
    return 0;
}
