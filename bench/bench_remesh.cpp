// Time per step of collision-safe mesh improvement (improve_mesh: split, flip, collapse,
// separation, flip, null-space smoothing) and of topology changes (change_topology: merge,
// separation) at about 10k, 50k and 200k triangles (paper Table 4.4, "Improvement" and
// "Topology" columns).
//
// Improvement: a sphere of radius 0.5 meshed at the edge length giving the requested triangle
// count, then stretched by 1.5 along x and 1/√1.5 along y and z (as one step of a flow would),
// so that edges leave [β, α] in both directions; each iteration improves a fresh copy. Steady
// state: that mesh once improved, then stretched by another 2 % (a typical step's work).
// Topology:
// two such spheres (half the triangles each) 0.02 ξ apart, so the merge pass finds proximal
// edges and zips; each iteration works on a fresh copy. Counters are per iteration.
// Thin-sheet sizing: the EdgeSizing measurement (curvature, facing distances, grading) on a
// spherical shell (outer sphere and a reversed inner one, half the triangles each) whose
// thickness is SHELL_SAG_FRACTION times the chord sag of an edge of length α = 1.5 ξ, so every
// vertex faces the other side nearer than the sag allows and is refined.

#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_measures.h"
#include "tracker/remesh/improve.h"
#include "tracker/remesh/sizing.h"
#include "tracker/topology/change_topology.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <vector>

namespace {

using meniscus::tracker::SurfaceMesh;
using meniscus::tracker::Triangle;
using meniscus::tracker::Vec3;

constexpr double RADIUS = 0.5;
constexpr double STRETCH = 1.5;
constexpr double MERGE_GAP_FRACTION = 0.02;  // of ξ, below the default merge distance 0.1 ξ
constexpr double SHELL_SAG_FRACTION = 0.25;  // shell thickness / ((1.5 ξ)² / (8 RADIUS))

/// Edge length giving about `triangles` triangles on a sphere of radius r (equilateral).
double edge_length_for(int triangles, double r) {
    const double area = 4.0 * M_PI * r * r;
    return std::sqrt(area / (triangles * std::sqrt(3.0) / 4.0));
}

SurfaceMesh sphere_mesh(int triangles, double r, const Vec3& center) {
    meniscus::tracker::ImplicitMeshOptions options;
    options.edge_length = edge_length_for(triangles, r);
    SurfaceMesh m =
        meniscus::tracker::mesh_implicit_shape(*meniscus::tracker::make_sphere(center, r), options);
    m.compact();
    return m;
}

std::map<int, double>& unstretched_xi() {
    static std::map<int, double> xi;
    return xi;
}

double unstretched_mean_edge_length(int triangles) {
    return unstretched_xi().at(triangles);
}

const SurfaceMesh& stretched_sphere(int triangles) {
    static std::map<int, SurfaceMesh> cache;
    auto it = cache.find(triangles);
    if (it != cache.end())
        return it->second;
    SurfaceMesh m = sphere_mesh(triangles, RADIUS, Vec3::Zero());
    unstretched_xi()[triangles] = meniscus::tracker::edge_length_stats(m).mean;
    const double squeeze = 1.0 / std::sqrt(STRETCH);
    for (int vi = 0; vi < m.num_vertices(); ++vi) {
        const Vec3& p = m.position(vi);
        m.set_position(vi, Vec3(STRETCH * p.x(), squeeze * p.y(), squeeze * p.z()));
    }
    return cache.emplace(triangles, std::move(m)).first->second;
}

/// Two mirror-image spheres (half the triangles each) whose closest vertices face each other
/// across a gap of MERGE_GAP_FRACTION · ξ.
const SurfaceMesh& touching_spheres(int triangles) {
    static std::map<int, SurfaceMesh> cache;
    auto it = cache.find(triangles);
    if (it != cache.end())
        return it->second;
    const double r = RADIUS / std::sqrt(2.0);
    const double xi = edge_length_for(triangles / 2, r);
    const double offset = r + 0.5 * MERGE_GAP_FRACTION * xi;
    SurfaceMesh a = sphere_mesh(triangles / 2, r, Vec3(-offset, 0, 0));
    // Shift so the rightmost vertex sits exactly gap/2 left of the plane x = 0.
    double max_x = -1e300;
    for (int vi = 0; vi < a.num_vertices(); ++vi)
        max_x = std::max(max_x, a.position(vi).x());
    std::vector<Vec3> positions;
    const double shift = -0.5 * MERGE_GAP_FRACTION * xi - max_x;
    for (int vi = 0; vi < a.num_vertices(); ++vi)
        positions.push_back(a.position(vi) + Vec3(shift, 0, 0));
    const int n = a.num_vertices();
    for (int vi = 0; vi < n; ++vi) {
        Vec3 p = positions[static_cast<size_t>(vi)];
        p.x() = -p.x();
        positions.push_back(p);
    }
    std::vector<Triangle> tris;
    for (int ti = 0; ti < a.num_triangles(); ++ti)
        tris.push_back(a.triangle(ti));
    for (int ti = 0; ti < a.num_triangles(); ++ti) {
        const Triangle& t = a.triangle(ti);
        tris.push_back({t[0] + n, t[2] + n, t[1] + n});
    }
    return cache.emplace(triangles, SurfaceMesh(positions, tris)).first->second;
}

void BM_ImproveMesh(benchmark::State& state) {
    const int triangles = static_cast<int>(state.range(0));
    const SurfaceMesh& base = stretched_sphere(triangles);
    meniscus::tracker::RemeshOptions options;
    meniscus::tracker::ImproveContext context;
    context.xi = unstretched_mean_edge_length(triangles);
    context.collision.proximity_epsilon = 1e-3 * context.xi;
    meniscus::tracker::ImproveReport report;
    for (auto _ : state) {
        state.PauseTiming();
        SurfaceMesh mesh = base;
        state.ResumeTiming();
        report = meniscus::tracker::improve_mesh(mesh, options, context);
        benchmark::DoNotOptimize(mesh);
    }
    state.counters["triangles"] = base.count_live_triangles();
    state.counters["splits"] = report.split.splits;
    state.counters["flips"] = report.flip.flips;
    state.counters["collapses"] = report.collapse.collapses;
    state.counters["refused"] = report.flip.refused_total() + report.collapse.refused_total();
    state.counters["split_s"] = report.split.seconds;
    state.counters["flip_s"] = report.flip.seconds;
    state.counters["collapse_s"] = report.collapse.seconds;
    state.counters["separate_s"] = report.separation.seconds;
    state.counters["smooth_s"] = report.smooth.seconds;
}

/// The stretched sphere after one improve_mesh, stretched again by STEADY_STRETCH: the
/// small amount of work of a typical time step.
constexpr double STEADY_STRETCH = 1.02;

const SurfaceMesh& steady_state_sphere(int triangles) {
    static std::map<int, SurfaceMesh> cache;
    auto it = cache.find(triangles);
    if (it != cache.end())
        return it->second;
    SurfaceMesh m = stretched_sphere(triangles);
    meniscus::tracker::ImproveContext context;
    context.xi = unstretched_mean_edge_length(triangles);
    context.collision.proximity_epsilon = 1e-3 * context.xi;
    meniscus::tracker::improve_mesh(m, meniscus::tracker::RemeshOptions{}, context);
    m.compact();
    for (int vi = 0; vi < m.num_vertices(); ++vi) {
        const Vec3& p = m.position(vi);
        m.set_position(vi, Vec3(STEADY_STRETCH * p.x(), p.y(), p.z()));
    }
    return cache.emplace(triangles, std::move(m)).first->second;
}

void BM_ImproveMeshSteadyState(benchmark::State& state) {
    const int triangles = static_cast<int>(state.range(0));
    const SurfaceMesh& base = steady_state_sphere(triangles);
    meniscus::tracker::RemeshOptions options;
    meniscus::tracker::ImproveContext context;
    context.xi = unstretched_mean_edge_length(triangles);
    context.collision.proximity_epsilon = 1e-3 * context.xi;
    meniscus::tracker::ImproveReport report;
    for (auto _ : state) {
        state.PauseTiming();
        SurfaceMesh mesh = base;
        state.ResumeTiming();
        report = meniscus::tracker::improve_mesh(mesh, options, context);
        benchmark::DoNotOptimize(mesh);
    }
    state.counters["triangles"] = base.count_live_triangles();
    state.counters["splits"] = report.split.splits;
    state.counters["flips"] = report.flip.flips;
    state.counters["collapses"] = report.collapse.collapses;
    state.counters["smooth_s"] = report.smooth.seconds;
}

void BM_ChangeTopology(benchmark::State& state) {
    const int triangles = static_cast<int>(state.range(0));
    const SurfaceMesh& base = touching_spheres(triangles);
    meniscus::tracker::TopologyOptions options;
    meniscus::tracker::TopologyContext context;
    context.xi = meniscus::tracker::edge_length_stats(base).mean;
    meniscus::tracker::TopologyReport report;
    for (auto _ : state) {
        state.PauseTiming();
        SurfaceMesh mesh = base;
        state.ResumeTiming();
        report = meniscus::tracker::change_topology(mesh, options, context);
        benchmark::DoNotOptimize(mesh);
    }
    state.counters["triangles"] = base.count_live_triangles();
    state.counters["candidates"] = report.merge.candidates;
    state.counters["merges"] = report.merge.merges;
    state.counters["merge_s"] = report.merge.seconds;
    state.counters["separate_s"] = report.separation.seconds;
}

/// The topology phase of a step in which nothing merges or pinches (the common case): one
/// sphere, nothing within the merge distance; then compaction, as SurfaceTracker does.
void BM_ChangeTopologyQuiet(benchmark::State& state) {
    const SurfaceMesh base = sphere_mesh(static_cast<int>(state.range(0)), RADIUS, Vec3::Zero());
    meniscus::tracker::TopologyOptions options;
    meniscus::tracker::TopologyContext context;
    context.xi = meniscus::tracker::edge_length_stats(base).mean;
    meniscus::tracker::TopologyReport report;
    SurfaceMesh mesh = base;
    for (auto _ : state) {
        report = meniscus::tracker::change_topology(mesh, options, context);
        benchmark::DoNotOptimize(mesh);
    }
    state.counters["triangles"] = base.count_live_triangles();
    state.counters["merge_s"] = report.merge.seconds;
    state.counters["separate_s"] = report.separation.seconds;
}

/// A sphere mesh of about `triangles` triangles after a tenth of its edges were split (the
/// split triangles are dead slots, the new ones appended).
SurfaceMesh sphere_with_dead_slots(int triangles) {
    SurfaceMesh base = sphere_mesh(triangles, RADIUS, Vec3::Zero());
    for (int ei = 0, n = base.num_edges(); ei < n; ei += 10)
        if (base.edge_alive(ei)) {
            const auto e = base.edge(ei);
            base.split_edge(ei, 0.5 * (base.position(e[0]) + base.position(e[1])));
        }
    return base;
}

/// SurfaceMesh::compact() of sphere_with_dead_slots() (copying the mesh and freeing it are not
/// timed: freeing its adjacency lists cost more than the compaction).
void BM_Compact(benchmark::State& state) {
    const SurfaceMesh base = sphere_with_dead_slots(static_cast<int>(state.range(0)));
    for (auto _ : state) {
        state.PauseTiming();
        SurfaceMesh mesh = base;
        state.ResumeTiming();
        mesh.compact();
        benchmark::DoNotOptimize(mesh);
        state.PauseTiming();
        { const SurfaceMesh gone = std::move(mesh); }
        state.ResumeTiming();
    }
    state.counters["triangles"] = base.count_live_triangles();
}

/// SurfaceMesh::sort_spatially() of the compacted sphere_with_dead_slots() (not timed as above).
void BM_SortSpatially(benchmark::State& state) {
    SurfaceMesh base = sphere_with_dead_slots(static_cast<int>(state.range(0)));
    base.compact();
    for (auto _ : state) {
        state.PauseTiming();
        SurfaceMesh mesh = base;
        state.ResumeTiming();
        mesh.sort_spatially();
        benchmark::DoNotOptimize(mesh);
        state.PauseTiming();
        { const SurfaceMesh gone = std::move(mesh); }
        state.ResumeTiming();
    }
    state.counters["triangles"] = base.count_live_triangles();
}

/// Outer sphere of radius RADIUS and, a quarter of an α-chord's sag inside it, a copy scaled
/// down with its orientation reversed; half the triangles each.
const SurfaceMesh& thin_shell(int triangles, double& xi) {
    static std::map<int, std::pair<SurfaceMesh, double>> cache;
    auto it = cache.find(triangles);
    if (it == cache.end()) {
        const SurfaceMesh outer = sphere_mesh(triangles / 2, RADIUS, Vec3::Zero());
        const double mean = meniscus::tracker::edge_length_stats(outer).mean;
        const double thickness = SHELL_SAG_FRACTION * (1.5 * mean) * (1.5 * mean) / (8.0 * RADIUS);
        const double scale = (RADIUS - thickness) / RADIUS;
        std::vector<Vec3> positions = outer.positions();
        std::vector<Triangle> tris;
        const int n = outer.num_vertices();
        for (int vi = 0; vi < n; ++vi)
            positions.push_back(scale * outer.position(vi));
        for (int ti = 0; ti < outer.num_triangles(); ++ti)
            tris.push_back(outer.triangle(ti));
        for (int ti = 0; ti < outer.num_triangles(); ++ti) {
            const Triangle& t = outer.triangle(ti);
            tris.push_back({t[0] + n, t[2] + n, t[1] + n});
        }
        it = cache.emplace(triangles, std::make_pair(SurfaceMesh(positions, tris), mean)).first;
    }
    xi = it->second.second;
    return it->second.first;
}

void BM_ThinSheetSizing(benchmark::State& state) {
    double xi = 0.0;
    const SurfaceMesh& shell = thin_shell(static_cast<int>(state.range(0)), xi);
    meniscus::tracker::RemeshOptions options;
    options.split_on_fitted_surface = true;
    options.thin_sheet_sag_fraction = 1.5;
    double refined = 0.0;
    for (auto _ : state) {
        const meniscus::tracker::EdgeSizing sizing(shell, options, xi);
        refined = 0.0;
        for (int vi = 0; vi < shell.num_vertices(); ++vi)
            refined += sizing.scale(vi, vi) < 1.0;
        benchmark::DoNotOptimize(refined);
    }
    state.counters["triangles"] = shell.count_live_triangles();
    state.counters["refined_vertices"] = refined;
}

BENCHMARK(BM_ImproveMesh)->Arg(10000)->Arg(50000)->Arg(200000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ImproveMeshSteadyState)
    ->Arg(10000)
    ->Arg(50000)
    ->Arg(200000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ChangeTopology)->Arg(10000)->Arg(50000)->Arg(200000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ChangeTopologyQuiet)->Arg(10000)->Arg(50000)->Arg(200000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Compact)->Arg(10000)->Arg(50000)->Arg(200000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SortSpatially)->Arg(10000)->Arg(50000)->Arg(200000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ThinSheetSizing)->Arg(10000)->Arg(50000)->Arg(200000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
