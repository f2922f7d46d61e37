#include "app/run.h"

#include "app/checkpoint.h"
#include "app/frame_output.h"
#include "app/frame_stats.h"
#include "app/frame_writer.h"
#include "app/geometric_flow.h"
#include "app/output_dir.h"
#include "app/progress.h"
#include "app/resource_estimate.h"
#include "app/scene_setup.h"
#include "common/atomic_file.h"
#include "common/cancellation.h"
#include "common/phase_clock.h"
#include "coupling/simulation.h"
#include "coupling/vdb_output.h"
#include "tracker/flows/flow_runner.h"
#include "tracker/mesh_measures.h"
#include "tracker/surface_tracker.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

namespace meniscus::app {

namespace {

using tracker::SurfaceMesh;
using tracker::Vec3;
using Clock = std::chrono::steady_clock;

/// Geometric flows: a step that ends this close (fraction of /time/dt) to a stop lands on it.
constexpr double TIME_SNAP_FRACTION = 1e-9;
/// Geometric flows: the run stops (RunResult::stalled) after this many consecutive steps that
/// advance less than STALL_FRACTION of the offered step.
constexpr int MAX_STALLED_STEPS = 50;
constexpr double STALL_FRACTION = 1e-6;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

/// Turns an exception escaping a run's computation into what `meniscus run` reports: a stop
/// request, a write error and bad input pass through; anything else is an internal failure at
/// `where`.
[[noreturn]] static void rethrow_with_context(const std::string& where) {
    try {
        throw;
    } catch (const Cancelled&) {
        throw;
    } catch (const WriteError&) {
        throw;
    } catch (const InputError&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw InternalFailure("out of memory " + where);
    } catch (const std::exception& e) {
        throw InternalFailure(where + ": " + e.what());
    }
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

/// Writes the run's checkpoint (app/checkpoint.h) with every /output/checkpoint_every-th frame
/// and the last, before the frame's stats line, which then records its size and seconds.
class Checkpointer {
public:
    Checkpointer(const Scene& scene, const RunOptions& options, int frames, double nominal_xi)
        : m_dir(options.out_dir), m_every(scene.output.checkpoint_every), m_frames(frames) {
        std::error_code ec;
        const std::filesystem::path absolute = std::filesystem::absolute(scene.source_path, ec);
        m_header.scene_path = ec ? scene.source_path : absolute.lexically_normal().string();
        m_header.scene_text = scene.source_text;
        m_header.flow_type = scene.flow.type;
        m_header.frames = frames;
        m_header.nominal_xi = nominal_xi;
    }

    /// Is a checkpoint due after frame `frame`?
    bool due(int frame) const { return m_every > 0 && (frame % m_every == 0 || frame == m_frames); }

    /// If frame `frame` is due, writes the checkpoint with `save` as its state and the run's
    /// counters, then adds "checkpoint": {"bytes", "seconds"} to `line` (the frame's stats).
    /// A checkpoint that cannot be written discards the frame's files from `writer` (the frame
    /// then has no stats line) and throws WriteError.
    template <class SaveState>
    void write(int frame, double t, const RunResult& result, double last_dt, int stalled_steps,
               nlohmann::json& line, FrameWriter& writer, const SaveState& save) {
        if (!due(frame))
            return;
        const auto start = Clock::now();
        CheckpointHeader h = m_header;
        h.frame = frame;
        h.time = t;
        h.last_dt = last_dt;
        h.steps = result.steps;
        h.stalled_steps = stalled_steps;
        h.max_intersecting_pairs = result.max_intersecting_pairs;
        // Without its wall-clock timings: they are not the run's state, and with them the
        // checkpoint's size (reported in stats.jsonl) would vary from run to run.
        nlohmann::json stored = line;
        stored.erase("seconds");
        h.stats_line = stored.dump();
        BinaryWriter state;
        save(state);
        std::uint64_t bytes = 0;
        try {
            bytes = write_checkpoint(m_dir, h, state.bytes());
        } catch (const WriteError&) {
            writer.discard_pending();
            throw;
        }
        line["checkpoint"] = {{"bytes", bytes}, {"seconds", seconds_since(start)}};
    }

private:
    std::string m_dir;
    int m_every = 1;
    int m_frames = 0;
    CheckpointHeader m_header;
};

/// A resumed run's checkpoint, checked against the run about to continue it.
struct Resume {
    Checkpoint checkpoint;
    std::uint64_t bytes = 0;  ///< the checkpoint file's size
    int frames = 0;           ///< frames after frame 0 the resumed run ends at
};

std::optional<Resume> read_resume(const Scene& scene, const RunOptions& options) {
    if (!options.resume)
        return std::nullopt;
    Resume r;
    r.checkpoint = read_checkpoint(options.out_dir);
    const CheckpointHeader& h = r.checkpoint.header;
    const std::string path = (std::filesystem::path(options.out_dir) / CHECKPOINT_NAME).string();
    std::error_code ec;
    r.bytes = std::filesystem::file_size(path, ec);
    if (h.flow_type != scene.flow.type)
        throw InputError(path + ": written by a /flow/type \"" + h.flow_type +
                         "\" run, the scene's is \"" + scene.flow.type + "\"");
    r.frames = options.frames > 0 ? options.frames : h.frames;
    if (r.frames < h.frame)
        throw InputError("--frames " + std::to_string(options.frames) +
                         ": the checkpoint in " + options.out_dir + " is already at frame " +
                         std::to_string(h.frame));
    return r;
}

/// Restores a solver from a checkpoint's state block; a state that does not fit (a scene
/// changed under --allow-scene-change, a damaged file) is bad input naming the file.
template <class Restore>
void restore_state(const Resume& resume, const RunOptions& options, const Restore& restore) {
    try {
        BinaryReader in(resume.checkpoint.state.data(), resume.checkpoint.state.size());
        restore(in);
        if (!in.at_end())
            throw FormatError("bytes left after the state");
    } catch (const FormatError& e) {
        throw InputError((std::filesystem::path(options.out_dir) / CHECKPOINT_NAME).string() +
                         ": its state does not fit this scene: " + e.what());
    }
}

/// A stand-in surface for solvers that a checkpoint's state then replaces (a resumed run does
/// not mesh its initial shape again). With `periods` (a periodic scene) it is a small tetrahedron
/// in the box that wraps as the scene's surface does: its state keeps the periods it is loaded
/// into (SurfaceMesh::load_state), and the simulation checks them against the box.
SurfaceMesh placeholder_surface(const tracker::MeshPeriods& periods = {}) {
    const std::vector<tracker::Triangle> faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    if (!periods.any())
        return SurfaceMesh({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}, faces);
    double size = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a)
        if (periods.wraps(a))
            size = std::min(size,
                            periods.length[a] / (4.0 * tracker::MeshPeriods::PERIOD_TO_EDGE_RATIO));
    const Vec3 o = periods.origin;
    SurfaceMesh mesh({o, o + Vec3(size, 0, 0), o + Vec3(0, size, 0), o + Vec3(0, 0, size)}, faces);
    mesh.set_periods(periods);
    return mesh;
}

/// Runs a fluid scene, keeping `result` current frame by frame (a caller that catches an
/// exception still knows what was written).
static void run_fluid_scene(const Scene& scene, const RunOptions& options,
                            const std::atomic<bool>& stop, RunResult& result) {
    // On several MPI ranks (issue 40) every rank steps its part of the simulation and rank 0
    // alone writes: the frames (the VDB's grids gathered from every rank), the stats and the
    // progress. Every call below that reads the grid is collective.
    const fluid::RankCommunicator& ranks = options.ranks;
    const bool distributed = ranks.size() > 1;
    const bool root = ranks.rank() == 0;
    const std::optional<Resume> resume = read_resume(scene, options);
    std::string report;
    double nominal_xi = 0.0;
    std::optional<coupling::Simulation> simulation;
    if (resume) {
        // A checkpoint holds the whole grid's state (Simulation::save_state): it resumes on any
        // number of ranks, whatever number wrote it; every rank reads it.
        if (root)
            prepare_output_dir(options.out_dir);
        nominal_xi = resume->checkpoint.header.nominal_xi;
        simulation.emplace(make_fluid_simulation(scene, placeholder_surface(scene_periods(scene)),
                                                 nominal_xi, ranks));
        restore_state(*resume, options, [&](BinaryReader& in) { simulation->load_state(in); });
        report = "resumed at frame " + std::to_string(resume->checkpoint.header.frame) +
                 " from " + options.out_dir + "/" + CHECKPOINT_NAME;
    } else {
        if (root)
            prepare_output_dir(options.out_dir);
        SurfaceMesh initial = checked_initial_surface(scene, options.limits, &report, &nominal_xi);
        simulation.emplace(make_fluid_simulation(scene, std::move(initial), nominal_xi, ranks));
    }
    coupling::Simulation& sim = *simulation;
    const double dx = sim.fluid().grid().dx();
    const std::array<int, 3> cells = sim.fluid().box_cells();
    if (!options.quiet)
        std::fprintf(stderr, "%s: %s; fluid grid %d x %d x %d, dx = %g m%s\n", scene.name.c_str(),
                     report.c_str(), cells[0], cells[1], cells[2], dx,
                     distributed ? (", split over " + std::to_string(ranks.size()) +
                                    " MPI ranks in slabs of z-layers")
                                       .c_str()
                                 : "");

    const int frames =
        resume ? resume->frames : options.frames > 0 ? options.frames : scene.time.frames;
    const double frame_dt = scene.time.end / scene.time.frames;
    const double end_time = frame_dt * frames;
    std::optional<FrameWriter> frame_writer;
    if (resume && root)
        frame_writer.emplace(scene, options.out_dir, options.quiet, frames,
                             resume->checkpoint.header, resume->bytes);
    else if (root)
        frame_writer.emplace(scene, options.out_dir, options.quiet, frames);
    Checkpointer checkpointer(scene, options, frames, nominal_xi);
    // On several ranks saving the state is collective (the grid's fields are gathered on rank
    // 0), so every rank saves when a checkpoint is due and rank 0 writes what it gathered.
    std::optional<BinaryWriter> gathered;
    const auto gather_state = [&](int frame) {
        gathered.reset();
        if (distributed && checkpointer.due(frame)) {
            gathered.emplace();
            sim.save_state(*gathered);
        }
    };
    const auto save = [&](BinaryWriter& out) {
        if (gathered)
            out = std::move(*gathered);
        else
            sim.save_state(out);
    };
    Progress progress(stderr, options.quiet);
    // The whole grid's velocities and pressure on rank 0 (gathered from every rank's slab) when
    // the VDB files need them.
    std::optional<fluid::MacGrid> whole_grid;
    fluid::Array3<double> whole_pressure;
    const auto fields = [&]() {
        if (!distributed)
            return coupling::FluidFields{&sim.fluid().grid(), &sim.fluid().pressure()};
        if (!scene.output.vdb)
            return coupling::FluidFields{};
        const fluid::SlabDecomposition& d = sim.fluid().blocks().decomposition();
        if (!whole_grid) {
            whole_grid.emplace(root ? cells[0] : 1, root ? cells[1] : 1, root ? cells[2] : 1, dx,
                               sim.fluid().box_min());
            whole_grid->set_periodic(
                {sim.fluid().grid().periodic()[0], sim.fluid().grid().periodic()[1], d.periodic()});
        }
        fluid::gather_velocities(sim.fluid().grid(), d, ranks, *whole_grid, 0);
        whole_pressure =
            fluid::gather_field(sim.fluid().pressure(), d, ranks, fluid::LayerKind::cells, 0);
        return coupling::FluidFields{&*whole_grid, &whole_pressure};
    };
    // A stop (Ctrl-C, SIGTERM: mpirun passes them to every rank) counts once any rank has seen
    // it, so that every rank leaves at the same step.
    std::atomic<bool> agreed_stop{false};
    const auto stop_flag = [&]() -> const std::atomic<bool>& {
        if (!distributed)
            return stop;
        agreed_stop.store(ranks.max(stop.load() ? 1.0 : 0.0) > 0.0);
        return agreed_stop;
    };

    coupling::SimulationStepReport last;
    double t = 0.0;
    int first_frame = 1;
    if (resume) {
        const CheckpointHeader& h = resume->checkpoint.header;
        t = h.time;
        first_frame = h.frame + 1;
        result.steps = h.steps;
        result.max_intersecting_pairs = h.max_intersecting_pairs;
        result.simulated_time = t;
        result.frames_written = h.frame + 1;
    } else {
        FluidFrameTimes times;
        PhaseClock output_clock;
        const coupling::FluidFields grids = fields();
        if (root)
            frame_writer->write(0, sim.tracker().mesh(), sim.vertex_velocities(), grids);
        output_clock.lap_into(times.output);
        nlohmann::json line =
            fluid_frame_stats(0, 0.0, 0, sim, last, times.json(), nlohmann::json::object());
        gather_state(0);
        if (root) {
            checkpointer.write(0, 0.0, result, 0.0, 0, line, *frame_writer, save);
            frame_writer->stats(line);
        }
        gathered.reset();  // the other ranks' copy is not a state
        result.frames_written = 1;
    }
    for (int frame = first_frame; frame <= frames; ++frame) {
        const double t_frame = frame == frames ? end_time : frame * frame_dt;
        long long steps = 0;
        FluidFrameTimes times;
        long long intersecting = -1, merges = 0, splits = 0, shortenings = 0;
        std::map<std::string, long long> limits;  // steps per limit that set their Δt
        FrameSolves solves;
        FrameOpenBoundaries open_faces;
        while (t < t_frame) {
            if (should_stop(options, stop_flag(), t, progress, result))
                return;
            last = sim.step(t_frame - t, scene.time.dt);
            solves.add(last.fluid);
            open_faces.add(last.open_boundaries);
            times.add(last);
            intersecting = std::max<long long>(intersecting, last.integrate.intersecting_pairs);
            result.max_intersecting_pairs =
                std::max(result.max_intersecting_pairs, last.integrate.intersecting_pairs);
            merges += last.volume.merges;
            splits += last.volume.splits;
            shortenings += last.integrate.collisions.step_shortenings;
            ++limits[coupling::to_string(last.limit)];
            t = (t_frame - (t + last.dt) <= 1e-12 * t_frame) ? t_frame : t + last.dt;
            ++steps;
            ++result.steps;
        }
        PhaseClock output_clock;
        const coupling::FluidFields grids = fields();
        if (root)
            frame_writer->write(frame, sim.tracker().mesh(), sim.vertex_velocities(), grids);
        output_clock.lap_into(times.output);
        nlohmann::json work = {{"intersecting_pairs", intersecting},
                               {"merges", merges},
                               {"splits", splits},
                               {"step_shortenings", shortenings},
                               {"dt_limits", limits},
                               {"solves", solves.json(steps)}};
        const fluid::BoundaryOptions& boundaries = sim.fluid().options().boundaries;
        if (boundaries.open() || boundaries.inflow())
            work["open_boundaries"] = open_faces.json(
                sim.boundary_volumes(),
                coupling::inflow_attachments(sim.tracker().mesh(), sim.fluid().grid(), boundaries));
        nlohmann::json line = fluid_frame_stats(frame, t, steps, sim, last, times.json(), work);
        const std::string deferred = open_faces.warning(frame);
        if (!deferred.empty() && !options.quiet) {
            progress.finish();
            std::fprintf(stderr, "%s\n", deferred.c_str());
        }
        gather_state(frame);
        if (root) {
            checkpointer.write(frame, t, result, 0.0, 0, line, *frame_writer, save);
            frame_writer->stats(line);
        }
        gathered.reset();  // the other ranks' copy is not a state
        const std::string warning = solves.warning(frame, steps);
        if (!warning.empty() && !options.quiet) {
            progress.finish();
            std::fprintf(stderr, "%s\n", warning.c_str());
        }
        result.frames_written = frame + 1;
        result.simulated_time = t;
        char detail[128];
        std::snprintf(detail, sizeof detail, "%d triangles, %d components, %lld steps",
                      sim.tracker().mesh().count_live_triangles(),
                      tracker::triangle_components(sim.tracker().mesh()).count, steps);
        progress.frame_done(frame, frames, t, detail);
    }
    progress.finish();
}

/// Runs a geometric-flow scene; see run_fluid_scene().
static void run_geometric_scene(const Scene& scene, const RunOptions& options,
                                const std::atomic<bool>& stop, RunResult& result) {
    const std::optional<Resume> resume = read_resume(scene, options);
    const int frames =
        resume ? resume->frames : options.frames > 0 ? options.frames : scene.time.frames;
    // --frames keeps the time per frame of the scene.
    const double frame_dt = scene.time.end / scene.time.frames;
    const double end_time = frame_dt * frames;
    ExactSolution exact(scene, end_time);
    if (exact.enabled())
        exact.check_end(end_time);

    std::string report;
    double nominal_xi = 0.0;
    std::optional<tracker::SurfaceTracker> surface_tracker;
    if (resume) {
        prepare_output_dir(options.out_dir);
        nominal_xi = resume->checkpoint.header.nominal_xi;
        surface_tracker.emplace(placeholder_surface(), tracker_options(scene, nominal_xi));
        restore_state(*resume, options, [&](BinaryReader& in) {
            surface_tracker->load_state(in);
            exact.load_state(in);
        });
        report = "resumed at frame " + std::to_string(resume->checkpoint.header.frame) +
                 " from " + options.out_dir + "/" + CHECKPOINT_NAME;
    } else {
        prepare_output_dir(options.out_dir);
        SurfaceMesh initial = checked_initial_surface(scene, options.limits, &report, &nominal_xi);
        surface_tracker.emplace(std::move(initial), tracker_options(scene, nominal_xi));
    }
    tracker::SurfaceTracker& tracker = *surface_tracker;
    const SurfaceMesh& mesh = tracker.mesh();
    if (!options.quiet)
        std::fprintf(stderr, "%s: %s\n", scene.name.c_str(), report.c_str());
    if (exact.enabled() && !resume)
        exact.check_initial(mesh, tracker.characteristic_length());
    for (const std::string& warning : plausibility_warnings(scene, tracker.characteristic_length()))
        std::fprintf(stderr, "meniscus: warning: %s\n", warning.c_str());
    const GeometricFlow flow = make_flow(scene.flow, scene.cancel);

    std::optional<FrameWriter> frame_writer;
    if (resume)
        frame_writer.emplace(scene, options.out_dir, options.quiet, frames,
                             resume->checkpoint.header, resume->bytes);
    else
        frame_writer.emplace(scene, options.out_dir, options.quiet, frames);
    FrameWriter& writer = *frame_writer;
    Checkpointer checkpointer(scene, options, frames, nominal_xi);
    Progress progress(stderr, options.quiet);
    std::vector<Vec3> velocities(static_cast<size_t>(mesh.num_vertices()), Vec3::Zero());
    double t = 0.0, dt = 0.0;
    int stalled = 0;
    const auto write_stats = [&](int frame, double time, double step_dt, long long steps,
                                 const FrameWork& work) {
        nlohmann::json line = frame_stats(frame, time, step_dt, steps, mesh, work);
        if (exact.enabled())
            line["exact_error"] = exact.stats(mesh, time);
        checkpointer.write(frame, time, result, step_dt, stalled, line, writer,
                           [&](BinaryWriter& out) {
            tracker.save_state(out);
            exact.save_state(out);
        });
        writer.stats(line);
    };

    FrameWork work;
    int first_frame = 1;
    if (resume) {
        const CheckpointHeader& h = resume->checkpoint.header;
        t = h.time;
        dt = h.last_dt;
        stalled = h.stalled_steps;
        first_frame = h.frame + 1;
        result.steps = h.steps;
        result.max_intersecting_pairs = h.max_intersecting_pairs;
        result.simulated_time = t;
        result.frames_written = h.frame + 1;
    } else {
        work.output = writer.write(0, mesh, velocities);
        write_stats(0, 0.0, 0.0, 0, work);
        result.frames_written = 1;
    }
    for (int frame = first_frame; frame <= frames; ++frame) {
        const double t_frame = frame == frames ? end_time : frame * frame_dt;
        long long steps = 0;
        work = FrameWork{};
        while (t < t_frame) {
            if (should_stop(options, stop, t, progress, result))
                return;
            // Steps end exactly on frame times (unless /time/land_on_frames is off: then on the
            // end time only) and on the flow's breakpoints (A1's reversal).
            double next_stop = scene.time.land_on_frames ? t_frame : end_time;
            for (double b : flow.breakpoints)
                if (b > t && b < next_stop)
                    next_stop = b;
            const double offered = std::min(scene.time.dt, next_stop - t);
            const double volume_before = tracker::enclosed_volume(mesh);
            auto start = Clock::now();
            tracker.improve();
            work.improvement += seconds_since(start);
            start = Clock::now();
            tracker.change_topology();  // compacts: vertex indices may change
            work.topology += seconds_since(start);
            const double volume_remeshed = tracker::enclosed_volume(mesh);
            work.volume_remeshing += volume_remeshed - volume_before;
            velocities.assign(static_cast<size_t>(mesh.num_vertices()), Vec3::Zero());
            start = Clock::now();
            dt = offered;
            if (flow.stepper) {
                const tracker::FlowStep step = flow_step(*flow.stepper, mesh, t, offered, scene);
                dt = step.dt;
                work.flow_shortenings += step.shortened ? 1 : 0;
                for (size_t vi = 0; vi < step.displacements.size(); ++vi)
                    velocities[vi] = step.displacements[vi] / dt;
            }
            work.set_velocity += seconds_since(start);
            std::vector<Vec3> requested = mesh.positions();
            start = Clock::now();
            const tracker::IntegrateResult r = tracker.integrate(velocities, dt);
            work.collisions += seconds_since(start);
            for (size_t vi = 0; vi < requested.size(); ++vi)
                requested[vi] += r.time_advanced * velocities[vi];
            const double volume_requested = tracker::enclosed_volume(mesh, requested);
            work.volume_motion += volume_requested - volume_remeshed;
            work.volume_collisions += tracker::enclosed_volume(mesh) - volume_requested;
            work.collisions_found += r.collisions.collisions_first_sweep;
            work.impact_zone_iterations += r.collisions.impact_zone_iterations;
            work.step_shortenings += r.collisions.step_shortenings;
            work.intersecting_pairs = std::max(work.intersecting_pairs, r.intersecting_pairs);
            result.max_intersecting_pairs =
                std::max(result.max_intersecting_pairs, r.intersecting_pairs);
            // Advance by the motion actually applied; land exactly on the stop despite
            // round-off in the sum of steps.
            t += r.time_advanced;
            if (next_stop - t <= TIME_SNAP_FRACTION * scene.time.dt)
                t = next_stop;
            ++steps;
            ++result.steps;
            stalled = r.time_advanced < STALL_FRACTION * offered ? stalled + 1 : 0;
            if (stalled >= MAX_STALLED_STEPS) {
                progress.finish();
                result.stalled = true;
                result.simulated_time = t;
                work.output = writer.write(frame, mesh, velocities);
                write_stats(frame, t, dt, steps, work);
                result.frames_written = frame + 1;
                return;
            }
        }
        work.output = writer.write(frame, mesh, velocities);
        write_stats(frame, t, dt, steps, work);
        result.frames_written = frame + 1;
        result.simulated_time = t;
        char detail[96];
        std::snprintf(detail, sizeof detail, "%d triangles", mesh.count_live_triangles());
        progress.frame_done(frame, frames, t, detail);
    }
    progress.finish();
}

RunResult run_scene(const Scene& scene, const RunOptions& options, const std::atomic<bool>& stop) {
    Scene stoppable = scene;
    // On several MPI ranks nothing is cancelled half-way (a rank that left a step alone would
    // leave the others waiting in their next collective call): the ranks agree to stop between
    // steps instead (run_fluid_scene()).
    if (options.ranks.size() <= 1)
        stoppable.cancel = CancellationToken(&stop);
    RunResult result;
    try {
        if (scene.flow.type == "fluid")
            run_fluid_scene(stoppable, options, stop, result);
        else
            run_geometric_scene(stoppable, options, stop, result);
    } catch (const Cancelled&) {
        // Stopped inside a step: the frame in progress is discarded, every frame written is
        // complete. Before frame 0 there is nothing to report: the caller handles it.
        if (result.frames_written == 0)
            throw;
        result.interrupted = true;
    } catch (...) {
        rethrow_with_context(result.frames_written == 0
                                 ? std::string("while preparing the run")
                                 : "in step " + std::to_string(result.steps + 1) + " (frame " +
                                       std::to_string(result.frames_written) + ")");
    }
    return result;
}

Scene scene_for_resume(const std::string& dir, const std::string& scene_path, bool allow_change,
                       std::string* note) {
    const Checkpoint checkpoint = read_checkpoint(dir);
    const CheckpointHeader& h = checkpoint.header;
    const std::string path = scene_path.empty() ? h.scene_path : scene_path;
    std::error_code ec;
    if (scene_path.empty() && !std::filesystem::exists(path, ec)) {
        if (note)
            *note = path + " no longer exists: resuming with the scene text saved in the checkpoint";
        const std::filesystem::path p(path);
        return parse_scene(h.scene_text, path, p.has_parent_path() ? p.parent_path().string() : ".");
    }
    Scene scene = load_scene(path);
    const std::vector<std::string> changed = scene_differences(h.scene_text, scene.source_text);
    if (changed.empty())
        return scene;
    std::string list;
    for (const std::string& c : changed)
        list += (list.empty() ? "" : ", ") + c;
    if (!allow_change)
        throw InputError(path + ": changed since the checkpoint in " + dir + " was written (" +
                         list + "); resume with the scene as it was, or pass --allow-scene-change "
                         "to continue with the changed scene (the frames then differ from an "
                         "uninterrupted run)");
    if (note)
        *note = path + " changed since the checkpoint (" + list +
                "); continuing with the changed scene (--allow-scene-change)";
    return scene;
}

}  // namespace meniscus::app
