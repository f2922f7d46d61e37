// Seconds per coupled step, per phase (rasterize: mesh → φ and κ; fluid: the Navier–Stokes step;
// interpolate: grid → vertex velocities; tracker: improve, topology, collision-safe integrate),
// for scenes/drop_merge.json and scenes/bubble_merge.json refined so that the longest box axis
// has 64 cells (tracker edge = edge_length_cells · Δx as in the scene). Each benchmark iteration
// is one Simulation::step() from the scene's initial state (initial velocities applied as
// `meniscus run` does); the counters are per-step means over the iterations (wall seconds per
// phase, and cpu_s: process CPU seconds of all threads, which a loaded machine inflates less),
// plus the live triangle counts before the first and after the last step.
//
// Run: bench_coupling [--benchmark_filter=drop]; MENISCUS_BENCH_CELLS=<n> changes the 64 and
// MENISCUS_BENCH_STEPS=<n> the number of steps (default 20).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <string>

#include "app/run.h"
#include "app/scene.h"
#include "coupling/simulation.h"

namespace {

using namespace meniscus;

constexpr int DEFAULT_LONGEST_AXIS_CELLS = 64;
constexpr int DEFAULT_STEPS = 20;

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

void coupled_step(benchmark::State& state, const std::string& name) {
    const app::Scene scene =
        refined_scene(name, env_int("MENISCUS_BENCH_CELLS", DEFAULT_LONGEST_AXIS_CELLS));
    std::unique_ptr<coupling::Simulation> sim =
        std::make_unique<coupling::Simulation>(app::make_fluid_simulation(scene));
    const fluid::MacGrid& grid = sim->fluid().grid();
    double rasterize = 0.0, fluid_step = 0.0, interpolate = 0.0, tracker_step = 0.0, dt = 0.0;
    const int initial_triangles = sim->tracker().mesh().count_live_triangles();
    const std::clock_t cpu_start = std::clock();
    for (auto _ : state) {
        const coupling::SimulationStepReport report = sim->step(scene.time.dt);
        rasterize += report.rasterize_seconds;
        fluid_step += report.fluid_seconds;
        interpolate += report.interpolate_seconds;
        tracker_step += report.tracker_seconds;
        dt += report.dt;
    }
    const double cpu = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    const auto mean = [&](double total) {
        return benchmark::Counter(total, benchmark::Counter::kAvgIterations);
    };
    state.counters["rasterize_s"] = mean(rasterize);
    state.counters["fluid_s"] = mean(fluid_step);
    state.counters["interpolate_s"] = mean(interpolate);
    state.counters["tracker_s"] = mean(tracker_step);
    state.counters["cpu_s"] = mean(cpu);
    state.counters["dt_s"] = mean(dt);
    state.counters["cells"] = static_cast<double>(grid.nx()) * grid.ny() * grid.nz();
    state.counters["tris_start"] = initial_triangles;
    state.counters["tris_end"] = sim->tracker().mesh().count_live_triangles();
    state.SetLabel(std::to_string(grid.nx()) + "x" + std::to_string(grid.ny()) + "x" +
                   std::to_string(grid.nz()) + " cells");
}

void BM_DropMerge(benchmark::State& state) {
    coupled_step(state, "drop_merge");
}
void BM_BubbleMerge(benchmark::State& state) {
    coupled_step(state, "bubble_merge");
}

const int STEPS = env_int("MENISCUS_BENCH_STEPS", DEFAULT_STEPS);
BENCHMARK(BM_DropMerge)->Iterations(STEPS)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BubbleMerge)->Iterations(STEPS)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
