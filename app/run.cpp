#include "app/run.h"

#include "app/progress.h"
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
    double write(int frame, const SurfaceMesh& mesh, const std::vector<Vec3>& velocities) {
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

SurfaceMesh build_initial_surface(const Scene& scene, std::string* report) {
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

RunResult run_scene(const Scene& scene, const RunOptions& options, const std::atomic<bool>& stop) {
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
            if (stop.load()) {
                progress.finish();
                result.interrupted = true;
                result.simulated_time = t;
                return result;
            }
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
