#include "app/validate_run.h"

#include "app/progress.h"
#include "app/validate_parameters.h"
#include "tracker/implicit_mesher.h"
#include "tracker/mesh_intersections.h"
#include "tracker/mesh_measures.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace meniscus::app::flow_validation {

using tracker::SurfaceMesh;
using tracker::Vec3;
using Json = nlohmann::json;

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::vector<Vec3> as_velocities(const std::vector<Vec3>& displacements, double dt) {
    std::vector<Vec3> v(displacements.size());
    for (size_t i = 0; i < v.size(); ++i)
        v[i] = displacements[i] / dt;
    return v;
}

Json phase_json(const PhaseSeconds& s, long steps) {
    const double n = std::max<long>(steps, 1);
    return {{"improvement", s.improvement / n},
            {"topology", s.topology / n},
            {"set_velocity", s.set_velocity / n},
            {"collisions", s.collisions / n},
            {"verification", s.verification / n}};
}

}  // namespace

RunResult run_tracked(const RunSpec& spec, bool quiet) {
    const auto wall_start = Clock::now();
    RunResult r;
    r.spec = spec;
    tracker::ImplicitMeshOptions mesh_options;
    mesh_options.edge_length = spec.xi_requested;
    mesh_options.crease = spec.crease;
    tracker::ImplicitMeshReport mesh_report;
    SurfaceMesh initial = tracker::mesh_implicit_shape(*spec.shape, mesh_options, &mesh_report);
    tracker::TrackerOptions tracker_options = spec.tracker;
    if (tracker_options.characteristic_length == 0.0)
        tracker_options.characteristic_length = mesh_report.nominal_characteristic_length();
    tracker::SurfaceTracker tr(std::move(initial), tracker_options);
    const SurfaceMesh& mesh = tr.mesh();
    r.xi = tr.characteristic_length();
    r.initial_mesh = mesh;
    r.initial_volume = tracker::enclosed_volume(mesh);
    r.initial_intersecting_pairs =
        static_cast<int>(tracker::find_self_intersections(mesh).triangle_pairs.size());
    r.min_triangles = r.max_triangles = mesh.count_live_triangles();
    const auto record = [&](int pairs) {
        r.series_t.push_back(r.t);
        r.series_volume.push_back(tracker::enclosed_volume(mesh));
        r.series_triangles.push_back(mesh.count_live_triangles());
        r.series_pairs.push_back(pairs);
        r.series_components.push_back(tracker::triangle_components(mesh).count);
    };
    record(r.initial_intersecting_pairs);
    std::vector<double> stops = spec.breakpoints;
    stops.push_back(spec.t_end);
    std::sort(stops.begin(), stops.end());
    int stalled = 0;
    // Long runs (A4 at full length takes hours) show how far they have got.
    Progress progress(stderr, quiet, "percent", PROGRESS_LINE_SECONDS);
    int percent_done = 0;
    while (r.t < spec.t_end) {
        if (r.steps >= MAX_STEPS) {
            r.stop_reason = "step limit";
            break;
        }
        const double next_stop = *std::upper_bound(stops.begin(), stops.end(), r.t);
        const double offered = std::min(spec.max_dt, next_stop - r.t);
        const double volume_before = tracker::enclosed_volume(mesh);
        auto start = Clock::now();
        tr.improve();
        r.seconds.improvement += seconds_since(start);
        start = Clock::now();
        tr.change_topology();  // compacts
        r.seconds.topology += seconds_since(start);
        const double volume_remeshed = tracker::enclosed_volume(mesh);
        r.volume_budget.remeshing += volume_remeshed - volume_before;
        start = Clock::now();
        const tracker::FlowStep step = spec.stepper->step(mesh, r.t, offered);
        const std::vector<Vec3> velocities = as_velocities(step.displacements, step.dt);
        r.seconds.set_velocity += seconds_since(start);
        const std::vector<Vec3> x0 = mesh.positions();
        start = Clock::now();
        const tracker::IntegrateResult integrated = tr.integrate(velocities, step.dt);
        r.seconds.collisions += seconds_since(start);
        std::vector<Vec3> requested = x0;
        for (size_t i = 0; i < requested.size(); ++i)
            requested[i] += integrated.collisions.motion_fraction * step.displacements[i];
        const double volume_requested = tracker::enclosed_volume(mesh, requested);
        r.volume_budget.motion += volume_requested - volume_remeshed;
        r.volume_budget.collisions += tracker::enclosed_volume(mesh) - volume_requested;
        start = Clock::now();
        const int pairs =
            static_cast<int>(tracker::find_self_intersections(mesh).triangle_pairs.size());
        r.seconds.verification += seconds_since(start);
        ++r.steps;
        r.t += integrated.time_advanced;
        if (next_stop - r.t <= TIME_SNAP_FRACTION * spec.max_dt)
            r.t = next_stop;
        r.max_intersecting_pairs = std::max(r.max_intersecting_pairs, pairs);
        r.steps_with_intersections += pairs > 0 ? 1 : 0;
        const int triangles = mesh.count_live_triangles();
        r.min_triangles = std::min(r.min_triangles, triangles);
        r.max_triangles = std::max(r.max_triangles, triangles);
        record(pairs);
        const int percent = static_cast<int>(std::floor(100.0 * r.t / spec.t_end));
        if (percent > percent_done) {
            percent_done = std::min(percent, 100);
            char detail[160];
            std::snprintf(detail, sizeof detail, "%s %s ξ=%g: step %ld, %d triangles, %d pairs",
                          spec.case_id.c_str(), spec.label.c_str(), spec.xi_requested, r.steps,
                          triangles, pairs);
            progress.frame_done(percent_done, 100, r.t, detail);
        }
        if (triangles > MAX_TRIANGLES) {
            r.stop_reason = "triangle limit";
            break;
        }
        stalled = integrated.time_advanced < STALL_FRACTION * offered ? stalled + 1 : 0;
        if (stalled >= MAX_STALLED_STEPS) {
            r.stop_reason = "stalled (steps advanced no time)";
            break;
        }
    }
    progress.finish();
    r.completed = r.t >= spec.t_end;
    if (r.completed)
        r.stop_reason = "reached end";
    r.final_mesh = mesh;
    r.wall_seconds = seconds_since(wall_start);
    if (!quiet)
        std::fprintf(stderr,
                     "  %s %s ξ=%g: %ld steps to t=%g (%s), %d–%d triangles, max %d intersecting "
                     "pairs, %.1f s\n",
                     spec.case_id.c_str(), spec.label.c_str(), spec.xi_requested, r.steps, r.t,
                     r.stop_reason.c_str(), r.min_triangles, r.max_triangles,
                     r.max_intersecting_pairs, r.wall_seconds);
    return r;
}

tracker::TrackerOptions paper_tracker_options() {
    tracker::TrackerOptions o;
    o.remesh.max_edge_fraction = MAX_EDGE_FRACTION;
    o.remesh.min_edge_fraction = MIN_EDGE_FRACTION;
    o.remesh.max_volume_change_fraction = VOLUME_CHANGE_FRACTION;
    return o;
}

Json run_json(const RunResult& r) {
    return {{"case", r.spec.case_id},
            {"label", r.spec.label},
            {"xi_requested", r.spec.xi_requested},
            {"xi", r.xi},
            {"crease_refinement_levels", r.spec.crease.levels},
            {"t_end", r.spec.t_end},
            {"t_reached", r.t},
            {"completed", r.completed},
            {"stop_reason", r.stop_reason},
            {"steps", r.steps},
            {"collision_safety", r.spec.tracker.collision_safety},
            {"topology_changes", r.spec.tracker.allow_topology_changes},
            {"triangles_min", r.min_triangles},
            {"triangles_max", r.max_triangles},
            {"initial_intersecting_pairs", r.initial_intersecting_pairs},
            {"max_intersecting_pairs", r.max_intersecting_pairs},
            {"steps_with_intersections", r.steps_with_intersections},
            {"initial_volume", r.initial_volume},
            {"final_volume", r.series_volume.back()},
            {"volume_change_percent",
             100.0 * tracker::relative_volume_change(r.initial_volume, r.series_volume.back())},
            {"final_components", r.series_components.back()},
            {"seconds_per_step", phase_json(r.seconds, r.steps)},
            {"volume_change_percent_by_phase",
             {{"remeshing", 100.0 * r.volume_budget.remeshing / r.initial_volume},
              {"motion", 100.0 * r.volume_budget.motion / r.initial_volume},
              {"collisions", 100.0 * r.volume_budget.collisions / r.initial_volume}}},
            {"wall_seconds", r.wall_seconds},
            {"series",
             {{"t", r.series_t},
              {"volume", r.series_volume},
              {"triangles", r.series_triangles},
              {"intersecting_pairs", r.series_pairs},
              {"components", r.series_components}}}};
}

Json error_json(const tracker::SurfaceError& e) {
    return {{"linf", e.linf},
            {"l1", e.l1},
            {"vertex_linf", e.vertex_linf},
            {"vertex_l1", e.vertex_l1},
            {"vertex_max_signed", e.vertex_max_signed},
            {"vertex_min_signed", e.vertex_min_signed},
            {"vertex_mean_signed", e.vertex_mean_signed},
            {"vertex_linf_position",
             {e.vertex_linf_position.x(), e.vertex_linf_position.y(), e.vertex_linf_position.z()}}};
}

}  // namespace meniscus::app::flow_validation
