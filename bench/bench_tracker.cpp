// Broad phase, static intersection check and a whole collision-safe integrate() step at
// 10k, 50k and 200k triangles (issue 3), collision resolution on A4 curl-noise states, and the
// two mean-curvature operators (Meyer's cotangent K, the quartic two-ring fit) per evaluation. Meshes: spheres meshed at an edge length chosen for
// the triangle count; motion: a smooth swirl plus a random jitter of 5 % of an edge per step.
#include "tests/tracker/curl_noise_a4_states.h"
#include "tracker/broadphase.h"
#include "tracker/collision_resolution.h"
#include "tracker/flows/curl_noise.h"
#include "tracker/flows/flow_runner.h"
#include "tracker/flows/mean_curvature.h"
#include "tracker/implicit_mesher.h"
#include "tracker/mesh_intersections.h"
#include "tracker/mesh_io.h"
#include "tracker/surface_tracker.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <random>
#include <string>

namespace {

using namespace meniscus::tracker;

/// Edge length giving about `triangles` triangles on two spheres of radius 0.3.
double edge_for(int triangles) {
    const double area = 2 * 4 * M_PI * 0.09;
    return std::sqrt(area / (triangles * std::sqrt(3.0) / 4.0));
}

const SurfaceMesh& mesh_with(int triangles) {
    static std::map<int, SurfaceMesh> cache;
    auto it = cache.find(triangles);
    if (it == cache.end()) {
        ImplicitMeshOptions o;
        o.edge_length = edge_for(triangles);
        o.remesh_iterations = 3;
        it = cache
                 .emplace(triangles,
                          mesh_implicit_shape(*make_union({make_sphere({-0.31, 0, 0}, 0.3),
                                                           make_sphere({0.31, 0, 0}, 0.3)}),
                                              o))
                 .first;
    }
    return it->second;
}

std::vector<Vec3> velocities(const SurfaceMesh& m, double edge, double dt, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, 0.05 * edge / dt);
    std::vector<Vec3> v(static_cast<size_t>(m.num_vertices()));
    for (int vi = 0; vi < m.num_vertices(); ++vi) {
        const Vec3& p = m.position(vi);
        v[static_cast<size_t>(vi)] = Vec3(-p.y(), p.x(), 0.0) + Vec3(n(rng), n(rng), n(rng));
    }
    return v;
}

void BM_BroadPhaseSwept(benchmark::State& state) {
    const SurfaceMesh& m = mesh_with(static_cast<int>(state.range(0)));
    const double dt = 0.01, edge = edge_for(static_cast<int>(state.range(0)));
    const auto v = velocities(m, edge, dt, 1);
    std::vector<Vec3> x1 = m.positions();
    for (size_t i = 0; i < x1.size(); ++i)
        x1[i] += dt * v[i];
    size_t pairs = 0;
    for (auto _ : state) {
        const BroadPhase broad(m, m.positions(), x1, 0.0);
        pairs = broad.vertex_triangle_pairs().size() + broad.edge_edge_pairs().size();
        benchmark::DoNotOptimize(pairs);
    }
    state.counters["triangles"] = m.count_live_triangles();
    state.counters["candidate_pairs"] = static_cast<double>(pairs);
}

void BM_StaticIntersectionCheck(benchmark::State& state) {
    const SurfaceMesh& m = mesh_with(static_cast<int>(state.range(0)));
    for (auto _ : state)
        benchmark::DoNotOptimize(is_intersection_free(m));
    state.counters["triangles"] = m.count_live_triangles();
}

void BM_Integrate(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    const double dt = 0.01, edge = edge_for(n);
    TrackerOptions options;
    SurfaceTracker tracker(mesh_with(n), options);
    unsigned seed = 0;
    int collisions = 0;
    for (auto _ : state) {
        state.PauseTiming();
        const auto v = velocities(tracker.mesh(), edge, dt, ++seed);
        state.ResumeTiming();
        const IntegrateResult r = tracker.integrate(v, dt);
        collisions += r.collisions.collisions_first_sweep;
    }
    state.counters["triangles"] = tracker.mesh().count_live_triangles();
    state.counters["collisions_per_step"] =
        benchmark::Counter(collisions, benchmark::Counter::kAvgIterations);
}

/// One evaluation of the curvature normals of every vertex: arg 0 Meyer's cotangent formula,
/// 1 the quartic fit, 2 the quartic fit with its sphere refit (mean_curvature.h,
/// CurvatureOperator, MeanCurvatureFlowOptions::fit_sphere_refit).
void BM_CurvatureNormals(benchmark::State& state) {
    const SurfaceMesh& m = mesh_with(static_cast<int>(state.range(0)));
    const int variant = static_cast<int>(state.range(1));
    for (auto _ : state) {
        const std::vector<Vec3> k =
            variant > 0 ? fitted_mean_curvature_normals(m, 1.0, nullptr, nullptr, variant == 2)
                        : mean_curvature_normals(m);
        benchmark::DoNotOptimize(k.data());
    }
    state.SetLabel(variant == 0 ? "cotangent" : variant == 1 ? "quartic fit" : "quartic fit, refit");
    state.counters["triangles"] = m.num_triangles();
}
BENCHMARK(BM_CurvatureNormals)
    ->Args({10000, 0})
    ->Args({10000, 1})
    ->Args({10000, 2})
    ->Args({50000, 0})
    ->Args({50000, 1})
    ->Args({50000, 2})
    ->Unit(benchmark::kMillisecond);

BENCHMARK(BM_BroadPhaseSwept)->Arg(10000)->Arg(50000)->Arg(200000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StaticIntersectionCheck)
    ->Arg(10000)
    ->Arg(50000)
    ->Arg(200000)
    ->Unit(benchmark::kMillisecond);
/// Contact-heavy: a sphere of about `triangles` triangles crushed towards its centre by
/// −2 x plus unit random noise (the CollisionStress test's field), one step per iteration from
/// where the last one left off; a fixed number of iterations keeps the load the same from run
/// to run.
void BM_IntegrateCrushed(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    ImplicitMeshOptions o;
    o.edge_length = std::sqrt(4 * M_PI * 0.09 / (n * std::sqrt(3.0) / 4.0));
    SurfaceTracker tracker(mesh_implicit_shape(*make_sphere({0, 0, 0}, 0.3), o), TrackerOptions{});
    std::mt19937 rng(11);
    std::normal_distribution<double> noise(0.0, 1.0);
    int collisions = 0;
    for (auto _ : state) {
        state.PauseTiming();
        const SurfaceMesh& m = tracker.mesh();
        std::vector<Vec3> v(static_cast<size_t>(m.num_vertices()));
        for (int vi = 0; vi < m.num_vertices(); ++vi)
            v[static_cast<size_t>(vi)] =
                -2.0 * m.position(vi) + Vec3(noise(rng), noise(rng), noise(rng));
        state.ResumeTiming();
        collisions += tracker.integrate(v, 0.01).collisions.collisions_first_sweep;
    }
    state.counters["triangles"] = tracker.mesh().count_live_triangles();
    state.counters["collisions_per_step"] =
        benchmark::Counter(collisions, benchmark::Counter::kAvgIterations);
}

/// Contact-heavy, from a real run: one collision resolution of A4 curl noise (ξ = 0.04, the
/// three-octave field) on thin sheets pressed together, from the states kept for the collision regression
/// tests (tests/data/regression): t = 27.2 (54 914 triangles, where an active-set impact-zone
/// solve cycled and halved the step twice) and t = 28.1 (44 794 triangles).
void BM_ResolveCurlNoiseSheets(benchmark::State& state, const char* file, double t) {
    const SurfaceMesh mesh = to_surface_mesh(
        read_ply(std::string(MENISCUS_TEST_DATA_DIR) + "/regression/" + file), file);
    namespace recorded = meniscus::tracker::testing;
    const CurlNoiseField field(recorded::recorded_a4_field());
    const FlowStep step = VelocityFieldStepper(field).step(mesh, t, recorded::RECORDED_A4_DT);
    std::vector<Vec3> requested = mesh.positions();
    for (size_t i = 0; i < requested.size(); ++i)
        requested[i] += step.displacements[i];
    CollisionOptions options;
    options.proximity_epsilon = TrackerOptions{}.proximity_fraction * 0.040977574596089125;
    CollisionReport report;
    for (auto _ : state) {
        std::vector<Vec3> x1 = requested;
        report = resolve_collisions(mesh, mesh.positions(), x1, step.dt, options);
        benchmark::DoNotOptimize(x1.data());
    }
    state.counters["triangles"] = mesh.count_live_triangles();
    state.counters["first_sweep_hits"] = report.collisions_first_sweep;
    state.counters["impact_zone_rounds"] = report.impact_zone_iterations;
    state.counters["step_shortenings"] = report.step_shortenings;
}

// Integrate steps evolve the mesh, so later steps differ from earlier ones: a fixed iteration
// count makes runs comparable.
BENCHMARK(BM_Integrate)
    ->Arg(10000)
    ->Arg(50000)
    ->Arg(200000)
    ->Iterations(20)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IntegrateCrushed)->Arg(2000)->Arg(10000)->Iterations(40)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ResolveCurlNoiseSheets, t27_2, "curl_noise_a4_t27.2.ply", 27.200000000000003)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ResolveCurlNoiseSheets, t28_1, "curl_noise_a4_t28.1.ply", 28.100000000000264)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
