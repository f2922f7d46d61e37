#include "app/run.h"

#include "app/progress.h"
#include "coupling/simulation.h"
#include "coupling/vdb_output.h"
#include "tracker/flows/velocity_field.h"
#include "tracker/implicit_mesher.h"
#include "tracker/mesh_intersections.h"
#include "tracker/mesh_io.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"
#include "tracker/surface_tracker.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

namespace meniscus::app {

namespace {

using tracker::SurfaceMesh;
using tracker::Vec3;
using Clock = std::chrono::steady_clock;

/// Violations listed in an error message before "and N more".
constexpr size_t MAX_LISTED_VIOLATIONS = 5;
/// Frames are numbered with this many digits.
constexpr int FRAME_DIGITS = 4;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string frame_path(const std::string& dir, const char* stem, int frame, const char* ext) {
    char name[64];
    std::snprintf(name, sizeof name, "%s_%0*d.%s", stem, FRAME_DIGITS, frame, ext);
    return (std::filesystem::path(dir) / name).string();
}

std::unique_ptr<tracker::VelocityField> make_field(const FlowOptions& flow) {
    // "fluid" scenes never get here (run_fluid_scene).
    if (flow.type == "enright")
        return std::make_unique<tracker::EnrightField>(flow.period);
    return nullptr;  // "none": the surface stays where it is
}

/// Per-frame timings (seconds) and collision work, summed over the frame's steps.
struct FrameWork {
    double improvement = 0.0;   ///< paper Table 4.4 "improvement"
    double topology = 0.0;      ///< paper Table 4.4 "topology"
    double set_velocity = 0.0;  ///< evaluating the flow (paper Table 4.4 "set velocity")
    double collisions = 0.0;    ///< collision-safe integration (Table 4.4 "collisions")
    double output = 0.0;
    long long collisions_found = 0;
    long long impact_zone_iterations = 0;
    long long step_shortenings = 0;
    int intersecting_pairs = -1;  ///< worst exact check result of the frame, −1 = not checked
};

class FrameWriter {
public:
    FrameWriter(const Scene& scene, const std::string& dir) : m_scene(scene), m_dir(dir) {
        std::filesystem::create_directories(dir);
        m_stats.open((std::filesystem::path(dir) / "stats.jsonl").string(), std::ios::trunc);
        if (!m_stats)
            throw std::runtime_error(dir + "/stats.jsonl: cannot open for writing");
        m_vdb.voxel_size = scene.output.voxel_size > 0.0 ? scene.output.voxel_size
                                                         : 0.5 * scene.surface.edge_length;
        m_vdb.half_width_voxels = scene.output.half_width_voxels;
    }

    /// Writes the frame's files; returns seconds spent.
    double write(int frame, const SurfaceMesh& mesh, const std::vector<Vec3>& velocities,
                 const coupling::FluidFields& fluid = {}) {
        const auto start = Clock::now();
        const OutputOptions& o = m_scene.output;
        if (o.ply)
            tracker::write_ply(frame_path(m_dir, "surface", frame, "ply"), mesh,
                               o.ply_velocity ? &velocities : nullptr);
        if (o.obj)
            tracker::write_obj(frame_path(m_dir, "surface", frame, "obj"), mesh);
        if (o.vdb)
            coupling::write_surface_vdb(frame_path(m_dir, "fields", frame, "vdb"), mesh, m_vdb);
        return seconds_since(start);
    }

    void stats(const nlohmann::json& line) {
        m_stats << line.dump() << '\n';
        m_stats.flush();
    }

private:
    const Scene& m_scene;
    std::string m_dir;
    std::ofstream m_stats;
    coupling::VdbOutputOptions m_vdb;
};

nlohmann::json frame_stats(int frame, double time, double dt, long long steps,
                           const SurfaceMesh& mesh, const FrameWork& work) {
    const auto components = tracker::triangle_components(mesh);
    const auto volumes = tracker::component_volumes(mesh, components);
    double total = 0.0;
    for (double v : volumes)
        total += v;
    const auto edges = tracker::edge_length_stats(mesh);
    const auto angles = tracker::angle_stats(mesh);
    return {{"frame", frame},
            {"time", time},
            {"dt", dt},
            {"steps", steps},
            {"vertices", mesh.count_live_vertices()},
            {"triangles", mesh.count_live_triangles()},
            {"components", components.count},
            {"volume", total},
            {"component_volumes", volumes},
            {"mean_edge_length", edges.mean},
            {"min_angle_degrees", angles.min_degrees},
            {"max_angle_degrees", angles.max_degrees},
            {"collisions_found", work.collisions_found},
            {"impact_zone_iterations", work.impact_zone_iterations},
            {"step_shortenings", work.step_shortenings},
            {"intersecting_pairs", work.intersecting_pairs},
            {"seconds",
             {{"improvement", work.improvement},
              {"topology", work.topology},
              {"set_velocity", work.set_velocity},
              {"collisions", work.collisions},
              {"output", work.output}}}};
}

/// Throws InputError listing the first intersecting triangle pairs, if any.
void check_intersection_free(const SurfaceMesh& mesh, const std::string& what) {
    const tracker::IntersectionReport r = tracker::find_self_intersections(mesh);
    if (r.intersection_free())
        return;
    std::ostringstream s;
    s << what << ": the surface intersects itself (" << r.triangle_pairs.size()
      << " triangle pairs), e.g.";
    for (size_t i = 0; i < r.triangle_pairs.size() && i < MAX_LISTED_VIOLATIONS; ++i)
        s << " (" << r.triangle_pairs[i].ti << ", " << r.triangle_pairs[i].tj << ")";
    throw InputError(s.str());
}

}  // namespace

/// The initial surface's geometry and connectivity (labels still the default: liquid inside).
static SurfaceMesh build_initial_surface_geometry(const Scene& scene, std::string* report) {
    if (scene.shape) {
        tracker::ImplicitMeshOptions options;
        options.edge_length = scene.surface.edge_length;
        options.remesh_iterations = scene.surface.remesh_iterations;
        tracker::ImplicitMeshReport r;
        SurfaceMesh mesh;
        try {
            mesh = tracker::mesh_implicit_shape(*scene.shape, options, &r);
        } catch (const std::exception& e) {
            throw InputError(scene.source_path + ": /surface: " + e.what());
        }
        check_intersection_free(mesh, scene.source_path +
                                          ": /surface/shape meshed at edge_length " +
                                          std::to_string(scene.surface.edge_length));
        if (report) {
            std::ostringstream s;
            s << "meshed shape: " << r.vertices << " vertices, " << r.triangles
              << " triangles, mean edge " << r.mean_edge_length << " m (requested "
              << scene.surface.edge_length << "), angles " << r.min_angle_degrees << "°–"
              << r.max_angle_degrees << "°";
            *report = s.str();
        }
        return mesh;
    }
    const std::string& file = scene.surface.mesh_file;
    SurfaceMesh mesh;
    try {
        mesh = tracker::to_surface_mesh(tracker::read_mesh_file(file), file);
    } catch (const std::runtime_error& e) {
        throw InputError(e.what());
    }
    const auto violations = tracker::validate_mesh(mesh);
    if (!violations.empty()) {
        std::ostringstream s;
        s << file << ": not a valid closed surface (" << violations.size() << " problems):";
        for (size_t i = 0; i < violations.size() && i < MAX_LISTED_VIOLATIONS; ++i)
            s << "\n  " << tracker::to_string(violations[i].kind) << ": " << violations[i].message;
        if (violations.size() > MAX_LISTED_VIOLATIONS)
            s << "\n  ... and " << violations.size() - MAX_LISTED_VIOLATIONS << " more";
        throw InputError(s.str());
    }
    check_intersection_free(mesh, file);
    if (report) {
        std::ostringstream s;
        s << "loaded " << file << ": " << mesh.count_live_vertices() << " vertices, "
          << mesh.count_live_triangles() << " triangles";
        *report = s.str();
    }
    return mesh;
}

SurfaceMesh build_initial_surface(const Scene& scene, std::string* report) {
    SurfaceMesh mesh = build_initial_surface_geometry(scene, report);
    // /surface/inside: which phase the surface encloses.
    const tracker::LabelPair labels =
        scene.surface.inside == "gas" ? tracker::LabelPair{0, 1} : tracker::LabelPair{1, 0};
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        if (mesh.triangle_alive(ti))
            mesh.set_labels(ti, labels);
    return mesh;
}

/// True (with `result` filled in) when the run must stop before the next step: Ctrl-C or
/// RunOptions::max_steps reached.
bool should_stop(const RunOptions& options, const std::atomic<bool>& stop, double t,
                 Progress& progress, RunResult& result) {
    const bool interrupted = stop.load();
    if (!interrupted && !(options.max_steps > 0 && result.steps >= options.max_steps))
        return false;
    progress.finish();
    result.interrupted = interrupted;
    result.reached_max_steps = !interrupted;
    result.simulated_time = t;
    return true;
}

/// Sets every face whose centre lies inside a region's shape to that region's velocity.
void apply_initial_velocity(const std::vector<VelocityRegion>& regions, fluid::MacGrid& grid) {
    for (int axis = 0; axis < 3; ++axis) {
        fluid::Array3<double>& u = grid.velocity(axis);
        for (int k = 0; k < u.nk(); ++k)
            for (int j = 0; j < u.nj(); ++j)
                for (int i = 0; i < u.ni(); ++i) {
                    const Vec3 x = grid.face_centre(axis, i, j, k);
                    for (const VelocityRegion& r : regions)
                        if (r.shape->value(x) < 0.0)
                            u(i, j, k) = r.velocity[axis];
                }
    }
}

nlohmann::json fluid_frame_stats(int frame, double time, long long steps,
                                 const coupling::Simulation& sim,
                                 const coupling::SimulationStepReport& last,
                                 const nlohmann::json& seconds, const nlohmann::json& work) {
    const SurfaceMesh& mesh = sim.tracker().mesh();
    const auto components = tracker::triangle_components(mesh);
    const auto volumes = tracker::component_volumes(mesh, components);
    double total = 0.0, max_speed = 0.0;
    for (double v : volumes)
        total += v;
    const fluid::MacGrid& grid = sim.fluid().grid();
    for (int axis = 0; axis < 3; ++axis) {
        const fluid::Array3<double>& u = grid.velocity(axis);
        for (int k = 0; k < u.nk(); ++k)
            for (int j = 0; j < u.nj(); ++j)
                for (int i = 0; i < u.ni(); ++i)
                    max_speed = std::max(max_speed, std::abs(u(i, j, k)));
    }
    nlohmann::json line = {{"frame", frame},
                           {"time", time},
                           {"dt", last.dt},
                           {"dt_limit", coupling::to_string(last.limit)},
                           {"steps", steps},
                           {"vertices", mesh.count_live_vertices()},
                           {"triangles", mesh.count_live_triangles()},
                           {"components", components.count},
                           {"volume", total},
                           {"component_volumes", volumes},
                           {"volume_targets", last.volume.targets},
                           {"kinetic_energy", sim.kinetic_energy()},
                           {"max_speed", max_speed},
                           {"pressure_iterations", last.fluid.pressure.iterations},
                           {"pressure_converged", last.fluid.pressure.converged},
                           {"seconds", seconds}};
    line.update(work);
    return line;
}

RunResult run_fluid_scene(const Scene& scene, const RunOptions& options,
                          const std::atomic<bool>& stop) {
    std::string report;
    SurfaceMesh initial = build_initial_surface(scene, &report);
    const double dx = scene.domain.size.x() / scene.domain.cells;
    const auto cells_along = [&](double size) {
        return std::max(1, static_cast<int>(std::lround(size / dx)));
    };
    fluid::FluidSolver solver(scene.domain.cells, cells_along(scene.domain.size.y()),
                              cells_along(scene.domain.size.z()), dx, scene.domain.min,
                              scene.fluid);
    apply_initial_velocity(scene.initial_velocity, solver.grid());
    coupling::Simulation sim(tracker::SurfaceTracker(std::move(initial), scene.tracker),
                             std::move(solver), scene.coupling.simulation);
    if (!options.quiet)
        std::fprintf(stderr, "%s: %s; fluid grid %d x %d x %d, dx = %g m\n", scene.name.c_str(),
                     report.c_str(), sim.fluid().grid().nx(), sim.fluid().grid().ny(),
                     sim.fluid().grid().nz(), dx);

    const int frames = options.frames > 0 ? options.frames : scene.time.frames;
    const double frame_dt = scene.time.end / scene.time.frames;
    const double end_time = frame_dt * frames;
    FrameWriter writer(scene, options.out_dir);
    Progress progress(stderr, options.quiet);
    const auto fields = [&]() {
        return coupling::FluidFields{&sim.fluid().grid(), &sim.fluid().pressure()};
    };

    RunResult result;
    coupling::SimulationStepReport last;
    double output_seconds =
        writer.write(0, sim.tracker().mesh(), sim.vertex_velocities(), fields());
    writer.stats(fluid_frame_stats(0, 0.0, 0, sim, last, {{"output", output_seconds}},
                                   nlohmann::json::object()));
    result.frames_written = 1;
    double t = 0.0;
    for (int frame = 1; frame <= frames; ++frame) {
        const double t_frame = frame == frames ? end_time : frame * frame_dt;
        long long steps = 0;
        double rasterize = 0.0, fluid_s = 0.0, interpolate = 0.0, tracker_s = 0.0;
        long long intersecting = -1, merges = 0, splits = 0, shortenings = 0;
        while (t < t_frame) {
            if (should_stop(options, stop, t, progress, result))
                return result;
            last = sim.step(t_frame - t);
            rasterize += last.rasterize_seconds;
            fluid_s += last.fluid_seconds;
            interpolate += last.interpolate_seconds;
            tracker_s += last.tracker_seconds;
            intersecting = std::max<long long>(intersecting, last.integrate.intersecting_pairs);
            result.max_intersecting_pairs =
                std::max(result.max_intersecting_pairs, last.integrate.intersecting_pairs);
            merges += last.volume.merges;
            splits += last.volume.splits;
            shortenings += last.integrate.collisions.step_shortenings;
            t = (t_frame - (t + last.dt) <= 1e-12 * t_frame) ? t_frame : t + last.dt;
            ++steps;
            ++result.steps;
        }
        output_seconds =
            writer.write(frame, sim.tracker().mesh(), sim.vertex_velocities(), fields());
        writer.stats(fluid_frame_stats(frame, t, steps, sim, last,
                                       {{"rasterize", rasterize},
                                        {"fluid", fluid_s},
                                        {"interpolate", interpolate},
                                        {"tracker", tracker_s},
                                        {"output", output_seconds}},
                                       {{"intersecting_pairs", intersecting},
                                        {"merges", merges},
                                        {"splits", splits},
                                        {"step_shortenings", shortenings}}));
        result.frames_written = frame + 1;
        result.simulated_time = t;
        char detail[128];
        std::snprintf(detail, sizeof detail, "%d triangles, %d components, %lld steps",
                      sim.tracker().mesh().count_live_triangles(),
                      tracker::triangle_components(sim.tracker().mesh()).count, steps);
        progress.frame_done(frame, frames, t, detail);
    }
    progress.finish();
    return result;
}

RunResult run_scene(const Scene& scene, const RunOptions& options, const std::atomic<bool>& stop) {
    if (scene.flow.type == "fluid")
        return run_fluid_scene(scene, options, stop);
    std::string report;
    tracker::SurfaceTracker tracker(build_initial_surface(scene, &report), scene.tracker);
    const SurfaceMesh& mesh = tracker.mesh();
    if (!options.quiet)
        std::fprintf(stderr, "%s: %s\n", scene.name.c_str(), report.c_str());

    const int frames = options.frames > 0 ? options.frames : scene.time.frames;
    // --frames keeps the time per frame of the scene.
    const double frame_dt = scene.time.end / scene.time.frames;
    const double end_time = frame_dt * frames;
    const auto field = make_field(scene.flow);

    FrameWriter writer(scene, options.out_dir);
    Progress progress(stderr, options.quiet);
    std::vector<Vec3> velocities(static_cast<size_t>(mesh.num_vertices()), Vec3::Zero());

    RunResult result;
    FrameWork work;
    work.output = writer.write(0, mesh, velocities);
    writer.stats(frame_stats(0, 0.0, 0.0, 0, mesh, work));
    result.frames_written = 1;

    double t = 0.0, dt = 0.0;
    for (int frame = 1; frame <= frames; ++frame) {
        const double t_frame = frame == frames ? end_time : frame * frame_dt;
        long long steps = 0;
        work = FrameWork{};
        while (t < t_frame) {
            if (should_stop(options, stop, t, progress, result))
                return result;
            dt = std::min(scene.time.dt, t_frame - t);
            auto start = Clock::now();
            tracker.improve();
            work.improvement += seconds_since(start);
            start = Clock::now();
            tracker.change_topology();  // compacts: vertex indices may change
            work.topology += seconds_since(start);
            velocities.assign(static_cast<size_t>(mesh.num_vertices()), Vec3::Zero());
            start = Clock::now();
            if (field) {
                const std::vector<Vec3> d = tracker::rk4_displacements(mesh, *field, t, dt);
                for (size_t vi = 0; vi < d.size(); ++vi)
                    velocities[vi] = d[vi] / dt;
            }
            work.set_velocity += seconds_since(start);
            start = Clock::now();
            const tracker::IntegrateResult r = tracker.integrate(velocities, dt);
            work.collisions += seconds_since(start);
            work.collisions_found += r.collisions.collisions_first_sweep;
            work.impact_zone_iterations += r.collisions.impact_zone_iterations;
            work.step_shortenings += r.collisions.step_shortenings;
            work.intersecting_pairs = std::max(work.intersecting_pairs, r.intersecting_pairs);
            result.max_intersecting_pairs =
                std::max(result.max_intersecting_pairs, r.intersecting_pairs);
            // Land exactly on the frame time despite round-off in the sum of steps.
            t = (t_frame - (t + dt) <= 1e-12 * t_frame) ? t_frame : t + dt;
            ++steps;
            ++result.steps;
        }
        work.output = writer.write(frame, mesh, velocities);
        writer.stats(frame_stats(frame, t, dt, steps, mesh, work));
        result.frames_written = frame + 1;
        result.simulated_time = t;
        char detail[96];
        std::snprintf(detail, sizeof detail, "%d triangles", mesh.count_live_triangles());
        progress.frame_done(frame, frames, t, detail);
    }
    progress.finish();
    return result;
}

}  // namespace meniscus::app
