// Per-phase cost of the A1 normal-flow run (docs/validation.md A1/A5: two spheres of radius 0.2
// grow at 0.2 m/s by face offsetting, merge at t = 0.25, reverse at t = 1) for profiling, without
// the validation suite around it. Usage:
//
//   profile_a1 [XI=0.02] [STEPS=400] [THREADS=0 (TBB default)]
//
// Prints, per step, the wall seconds of improve / topology / set velocity / collisions (the
// paper's Table 4.4 phases, as `meniscus validate` measures them) and of improve's parts, the
// process CPU seconds, the triangle counts, the topology phase's share of the steps in which it
// changed nothing (issue #36's target: at most 10 %), and a hash of the final positions and
// triangles (equal hashes for different thread counts show the run is deterministic).
#include "tracker/flows/flow_errors.h"
#include "tracker/flows/flow_runner.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_intersections.h"
#include "tracker/surface_tracker.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <time.h>
#include <memory>
#include <vector>

namespace {

using namespace meniscus::tracker;
using Clock = std::chrono::steady_clock;

/// validate.cpp's A1 settings (paper §4.1 and Table 4.1).
constexpr double A1_DT = 0.005;
constexpr double A1_REVERSAL = 1.0;
constexpr double MAX_EDGE_FRACTION = 1.5;
constexpr double MIN_EDGE_FRACTION = 0.5;
constexpr double VOLUME_CHANGE_FRACTION = 0.1;
constexpr double MAX_NORMAL_CHANGE_DEGREES = 20.0;

double since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Process CPU seconds (all threads).
double cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Wall and CPU seconds of one phase, summed over steps.
struct PhaseTimer {
    double wall = 0.0, cpu = 0.0;
    Clock::time_point wall_start;
    double cpu_start = 0.0;
    void start() {
        wall_start = Clock::now();
        cpu_start = cpu_seconds();
    }
    void stop() {
        wall += since(wall_start);
        cpu += cpu_seconds() - cpu_start;
    }
};

std::uint64_t fnv1a(std::uint64_t h, const void* data, size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < bytes; ++i) {
        h ^= p[i];
        h *= 1099511628211ULL;
    }
    return h;
}

std::uint64_t mesh_hash(const SurfaceMesh& mesh) {
    std::uint64_t h = 1469598103934665603ULL;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            h = fnv1a(h, mesh.position(vi).data(), 3 * sizeof(double));
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        if (mesh.triangle_alive(ti))
            h = fnv1a(h, mesh.triangle(ti).data(), 3 * sizeof(int));
    return h;
}

}  // namespace

int main(int argc, char** argv) {
    const double xi = argc > 1 ? std::atof(argv[1]) : 0.02;
    const long max_steps = argc > 2 ? std::atol(argv[2]) : 400;
    const int threads = argc > 3 ? std::atoi(argv[3]) : 0;
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0)
        limit = std::make_unique<tbb::global_control>(
            tbb::global_control::max_allowed_parallelism, static_cast<size_t>(threads));

    TwoSphereNormalFlow flow;
    flow.reversal_time = A1_REVERSAL;
    const auto shape = make_union(
        {make_sphere(flow.center0, flow.initial_radius), make_sphere(flow.center1, flow.initial_radius)});
    const FaceOffsettingStepper stepper([flow](double t) { return flow.normal_speed(t); });
    TrackerOptions options;
    options.remesh.max_edge_fraction = MAX_EDGE_FRACTION;
    options.remesh.min_edge_fraction = MIN_EDGE_FRACTION;
    options.remesh.max_volume_change_fraction = VOLUME_CHANGE_FRACTION;
    options.remesh.max_normal_change_degrees = MAX_NORMAL_CHANGE_DEGREES;
    options.remesh.split_on_fitted_surface = true;  // as validate's A1
    options.remesh.smoothing_onto_fitted_surface = true;
    ImplicitMeshOptions mesh_options;
    mesh_options.edge_length = xi;
    SurfaceTracker tracker(mesh_implicit_shape(*shape, mesh_options), options);
    const SurfaceMesh& mesh = tracker.mesh();

    PhaseTimer improve, topology, velocity, collisions;
    double smooth = 0, split = 0, flip = 0, collapse = 0;
    double merge = 0, separate = 0, compact = 0, quiet_topology = 0;
    long quiet_steps = 0;  // steps whose topology phase changed nothing
    double quiet_step_wall = 0;  // the whole of those steps (the four phases)
    long candidate_steps = 0, candidates = 0;  // steps with merge candidates, and how many
    int min_tris = mesh.count_live_triangles(), max_tris = min_tris;
    double t = 0.0;
    long steps = 0;
    const double cpu_start = cpu_seconds();
    const auto wall_start = Clock::now();
    for (; steps < max_steps && t < 2.0 * A1_REVERSAL; ++steps) {
        const double offered = t < A1_REVERSAL ? std::min(A1_DT, A1_REVERSAL - t) : A1_DT;
        const double wall_before = improve.wall + topology.wall + velocity.wall + collisions.wall;
        bool quiet = false;
        improve.start();
        const ImproveReport ir = tracker.improve();
        improve.stop();
        smooth += ir.smooth.seconds;
        split += ir.split.seconds;
        flip += ir.flip.seconds;
        collapse += ir.collapse.seconds;
        topology.start();
        const double topology_wall = topology.wall;
        const TopologyReport tr = tracker.change_topology();
        topology.stop();
        merge += tr.merge.seconds;
        candidates += tr.merge.candidates;
        candidate_steps += tr.merge.candidates > 0 ? 1 : 0;
        separate += tr.separation.seconds;
        compact += (topology.wall - topology_wall) - tr.seconds;
        if (tr.merge.merges == 0 && tr.separation.singular_vertices_split == 0 &&
            tr.separation.degenerate_tetrahedra_removed == 0) {
            quiet_topology += topology.wall - topology_wall;
            ++quiet_steps;
            quiet = true;
        }
        velocity.start();
        const FlowStep step = stepper.step(mesh, t, offered);
        std::vector<Vec3> v(step.displacements.size());
        for (size_t i = 0; i < v.size(); ++i)
            v[i] = step.displacements[i] / step.dt;
        velocity.stop();
        collisions.start();
        const IntegrateResult r = tracker.integrate(v, step.dt);
        collisions.stop();
        t += r.time_advanced;
        if (quiet)
            quiet_step_wall +=
                improve.wall + topology.wall + velocity.wall + collisions.wall - wall_before;
        if (std::abs(t - A1_REVERSAL) < 1e-9 * A1_DT)
            t = A1_REVERSAL;
        const int tris = mesh.count_live_triangles();
        min_tris = std::min(min_tris, tris);
        max_tris = std::max(max_tris, tris);
    }
    const double wall = since(wall_start);
    const double cpu = cpu_seconds() - cpu_start;
    const double n = static_cast<double>(std::max(steps, 1L));
    std::printf("A1 face offsetting xi=%g: %ld steps to t=%g, %d-%d triangles\n", xi, steps, t,
                min_tris, max_tris);
    std::printf("wall per step (s): improve %.4f  topology %.4f  set_velocity %.4f  collisions "
                "%.4f  total %.4f\n",
                improve.wall / n, topology.wall / n, velocity.wall / n, collisions.wall / n,
                (improve.wall + topology.wall + velocity.wall + collisions.wall) / n);
    std::printf("CPU per step (s):  improve %.4f  topology %.4f  set_velocity %.4f  collisions "
                "%.4f  total %.4f\n",
                improve.cpu / n, topology.cpu / n, velocity.cpu / n, collisions.cpu / n,
                (improve.cpu + topology.cpu + velocity.cpu + collisions.cpu) / n);
    std::printf("improve parts, wall per step (s): smooth %.4f  split %.4f  flip %.4f  collapse %.4f\n",
                smooth / n, split / n, flip / n, collapse / n);
    std::printf("topology parts, wall per step (s): merge %.4f  separate %.4f  compact "
                "%.4f; on the %ld steps without a change %.4f\n",
                merge / n, separate / n, compact / n, quiet_steps, quiet_topology / std::max(quiet_steps, 1L));
    std::printf("merge candidates: %ld on %ld steps\n", candidates, candidate_steps);
    std::printf("topology share of the steps without a change (wall): %.1f %% (%.4f of %.4f s per "
                "step)\n",
                100.0 * quiet_topology / std::max(quiet_step_wall, 1e-300),
                quiet_topology / std::max(quiet_steps, 1L),
                quiet_step_wall / std::max(quiet_steps, 1L));
    std::printf("wall %.2f s, process CPU %.2f s (%.2f s/step)\n", wall, cpu, cpu / n);
    std::printf("intersecting pairs at end: %zu\n", find_self_intersections(mesh).triangle_pairs.size());
    std::printf("final mesh hash: %016llx\n", static_cast<unsigned long long>(mesh_hash(mesh)));
    return 0;
}
