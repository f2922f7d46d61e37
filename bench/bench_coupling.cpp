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
// Uzawa passes, per step (pass_pcg_its, pass_visc_cg_its: those of the passes, on their region).
// A second table sets a memory traffic model of advection, viscosity and the pressure solve over
// the measured stream copy bandwidth beside the measured CPU time.
// CPU is the process's (all threads), so at 2 threads CPU ≈ 2 × wall when both are busy. After
// the run a table of the same figures is printed, one column per benchmark.
//
// Run: bench_coupling [--benchmark_filter=Cube/128]
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

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

// Memory traffic model of the fluid step's three large phases, in doubles moved (read or
// written) per cell per step, counted from the kernels in fluid/ for the incremental and split
// schemes with MacCormack advection, the Jacobi viscous CG and the multigrid pressure PCG. A
// model (±30 %): it counts each array a kernel streams once, and nothing kept in cache between
// kernels. Divided by the stream copy bandwidth it gives the time the phase would take if it
// were bound by memory alone (the "bound" table). The coupled scheme's Uzawa passes are not
// modelled.
// Advection: the grid's copy 6; per component its copy 2, the forward pass (the field, u, v, w,
// forward, lower, upper and their allocation) 10, the fused backward pass (forward, u, v, w, φ0,
// lower, upper, φ0 out) 8: 6 + 3 × 20 = 66.
constexpr double ADVECTION_DOUBLES = 66.0;
// Viscosity per CG iteration (3 face arrays, so 3 doubles per cell per vector): the operator
// (normal stresses 9, shear stresses 12, their divergence with the mass term, the mask and p·q
// 18.4), the fused update 24, p = z + βp 9: 72. Per step besides: the operator's build (μ, edge
// weights, face densities and masks, its scratch) 28, the diagonal 12, u* split and b 64, the first
// residual 63, the result 15: about 180.
constexpr double VISCOSITY_ITERATION_DOUBLES = 72.0;
constexpr double VISCOSITY_STEP_DOUBLES = 180.0;
// Pressure per PCG iteration: the PCG core 18 (four fused passes: A·p with p·q 6, the x and r
// updates with r·r 6, r·z 2, the new direction 4) and one V-cycle in float 30.7
// (bench_pressure.cpp's counts). Per step besides: the hierarchy 6, its float copy and inverse
// diagonals 8, the first residual and V-cycle 46, the gradient 12, the divergence check 4,
// adding the increment and its mean 7: about 83.
constexpr double PRESSURE_ITERATION_DOUBLES = 48.7;
constexpr double PRESSURE_STEP_DOUBLES = 83.0;
constexpr double BYTES_PER_DOUBLE = sizeof(double);

/// STREAM-style copy bandwidth, bytes/s, with `threads` TBB threads: b ← a over two 256 MiB
/// arrays, the best of 5 (the first touches the pages).
double stream_copy_bandwidth(int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(threads));
    const std::size_t count = std::size_t{1} << 25;
    std::vector<double> a(count, 1.0), b(count, 0.0);
    double best = 0.0;
    for (int repeat = 0; repeat < 5; ++repeat) {
        PhaseClock clock;
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t c = range.begin(); c != range.end(); ++c)
                                  b[c] = a[c] + static_cast<double>(repeat);
                          });
        benchmark::DoNotOptimize(b.data());
        const double seconds = clock.lap().wall;
        best = std::max(best, 2.0 * BYTES_PER_DOUBLE * static_cast<double>(count) / seconds);
    }
    return best;
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

/// Per benchmark: the iterations per step and the threads, for the traffic model.
struct ModelInputs {
    std::string label;
    double pressure_iterations = 0.0;
    double viscosity_iterations = 0.0;
    int threads = 0;                                           ///< 0: TBB's default (all cores)
    std::vector<std::pair<std::string, double>> measured_cpu;  ///< µs per cell per step
};
std::vector<ModelInputs> g_model;

/// µs per cell per step of every benchmark that ran, by phase: {benchmark: {phase: (cpu, wall)}}.
std::vector<std::pair<std::string, std::vector<std::pair<std::string, std::pair<double, double>>>>>
    g_table;

void coupled_steps(benchmark::State& state, const app::Scene& scene, int warmup_steps,
                   const std::string& label, int threads = 0) {
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
    long long pass_pressure_iterations = 0, pass_viscosity_iterations = 0;
    double model_pressure = 0.0, model_viscosity = 0.0;
    for (auto _ : state) {
        const coupling::SimulationStepReport report = sim->step(scene.time.dt);
        totals.add(report);
        dt += report.dt;
        pressure_iterations += report.fluid.pressure.iterations;
        viscosity_iterations += report.fluid.viscosity.iterations;
        // The traffic model's iterations are the whole grid's: the passes' count at the share
        // of the cells they ran on (local_passes).
        const double share = static_cast<double>(report.fluid.pass_cells) / cells;
        model_pressure += report.fluid.pressure.iterations +
                          (share - 1.0) * report.fluid.pass_pressure_iterations;
        model_viscosity += report.fluid.viscosity.iterations +
                           (share - 1.0) * report.fluid.pass_viscosity_iterations;
        passes += report.fluid.passes;
        pass_pressure_iterations += report.fluid.pass_pressure_iterations;
        pass_viscosity_iterations += report.fluid.pass_viscosity_iterations;
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
    state.counters["pass_pcg_its"] = static_cast<double>(pass_pressure_iterations) / n;
    state.counters["pass_visc_cg_its"] = static_cast<double>(pass_viscosity_iterations) / n;
    ModelInputs inputs;
    inputs.label = label;
    inputs.pressure_iterations = model_pressure / n;
    inputs.viscosity_iterations = model_viscosity / n;
    inputs.threads = threads;
    for (const auto& [name, figures] : row)
        inputs.measured_cpu.emplace_back(name, figures.first);
    g_model.push_back(std::move(inputs));
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
                  "cube " + std::to_string(cells) + "^3 " + std::to_string(threads) + "T", threads);
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

/// The traffic model's time per phase (modelled bytes over the stream copy bandwidth at the
/// benchmark's thread count) beside the measured CPU time, µs per cell per step. At 2 threads
/// the bound is wall time and the measured figure CPU time (≈ 2 × wall when both work).
void print_bandwidth_bound() {
    if (g_model.empty())
        return;
    std::map<int, double> bandwidth;  // by thread count
    for (const ModelInputs& m : g_model)
        if (bandwidth.count(m.threads) == 0)
            bandwidth[m.threads] = stream_copy_bandwidth(
                m.threads > 0 ? m.threads : tbb::this_task_arena::max_concurrency());
    std::printf(
        "\nbandwidth bound (modelled bytes / stream copy bandwidth) beside the measured "
        "CPU time, µs per cell per step\n%-20s",
        "phase");
    for (const ModelInputs& m : g_model)
        std::printf(" | %-19s", m.label.c_str());
    std::printf("\n%-20s", "stream copy GB/s");
    for (const ModelInputs& m : g_model)
        std::printf(" | %19.1f", bandwidth[m.threads] / 1e9);
    std::printf("\n");
    const auto measured = [](const ModelInputs& m, const std::string& phase) {
        for (const auto& [name, cpu] : m.measured_cpu)
            if (name == phase)
                return cpu;
        return 0.0;
    };
    const char* phases[] = {"  advection", "  viscosity", "  pressure_solve"};
    for (int p = 0; p < 3; ++p) {
        std::printf("%-20s", phases[p]);
        for (const ModelInputs& m : g_model) {
            const double doubles =
                p == 0 ? ADVECTION_DOUBLES
                : p == 1
                    ? VISCOSITY_STEP_DOUBLES + VISCOSITY_ITERATION_DOUBLES * m.viscosity_iterations
                    : PRESSURE_STEP_DOUBLES + PRESSURE_ITERATION_DOUBLES * m.pressure_iterations;
            const double bound = 1e6 * doubles * BYTES_PER_DOUBLE / bandwidth[m.threads];
            std::printf(" | %8.3f / %8.3f", bound, measured(m, phases[p]));
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
    print_bandwidth_bound();
    return 0;
}
