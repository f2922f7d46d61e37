#pragma once
/// \file Running a scene: initial surface, time stepping, per-frame output.

#include "app/resource_estimate.h"
#include "app/scene.h"
#include "tracker/mesh.h"

#include <atomic>
#include <stdexcept>
#include <string>

namespace meniscus::app {

/// Bad user input outside the scene JSON itself (e.g. a broken mesh file): exit code 2.
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A fault inside Meniscus (not the input's): exit code 1. The message says where it happened
/// (the step and frame) and what failed.
class InternalFailure : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Command-line choices of `meniscus run`.
struct RunOptions {
    std::string out_dir = "out";
    int frames = 0;           ///< > 0 overrides /time/frames, keeping the time per frame
    long long max_steps = 0;  ///< > 0 stops after this many steps (smoke tests)
    bool quiet = false;
    ResourceLimits limits;  ///< estimated memory and steps per frame allowed before starting
    /// Continue the run in out_dir from its checkpoint (app/checkpoint.h) instead of starting:
    /// the scene must be the one the checkpoint holds (scene_for_resume()).
    bool resume = false;
};

/// The scene of `meniscus run --resume DIR [SCENE]`: SCENE, or the scene file the checkpoint in
/// DIR names. Throws InputError when the file's JSON differs from the text the checkpoint holds
/// (naming the JSON paths that changed) unless `allow_change`; when the file no longer exists
/// (and no SCENE is given) the checkpoint's copy is used and `note` says so.
Scene scene_for_resume(const std::string& dir, const std::string& scene_path, bool allow_change,
                       std::string* note);

/// How a run ended.
struct RunResult {
    int frames_written = 0;  ///< including frame 0
    bool interrupted = false;
    bool reached_max_steps = false;  ///< stopped by RunOptions::max_steps
    /// A geometric flow stopped because its steps advanced no time (a stalled inversion limit
    /// or collision resolution); the last frame written is the stalled state.
    bool stalled = false;
    /// Worst exact self-intersection count over all steps (−1 unless
    /// /tracker/verify_intersection_free is on).
    int max_intersecting_pairs = -1;
    double simulated_time = 0.0;
    long long steps = 0;
};

/// Builds the initial surface of a scene (meshing its shape or loading and validating its mesh
/// file). Throws InputError naming the file and the failed check for a bad mesh file.
/// `nominal_xi` gets the tracker's ξ when the mesh was refined around creases (its mean edge
/// length before that refinement), else 0: measure it from the mesh.
tracker::SurfaceMesh build_initial_surface(const Scene& scene, std::string* report = nullptr,
                                           double* nominal_xi = nullptr);
/// The scene's tracker options with ξ set to `nominal_xi` unless the scene fixes it (or
/// `nominal_xi` is 0).
tracker::TrackerOptions tracker_options(const Scene& scene, double nominal_xi);

/// The coupled simulation of a fluid scene as `meniscus run` sets it up: the grid from /domain
/// (cubic cells, /domain/cells along x), the initial surface from /surface (build_initial_surface(),
/// whose `report` it passes on), the fluid at rest except for the /initial_velocity regions.
/// Throws what build_initial_surface() and the fluid solver throw.
coupling::Simulation make_fluid_simulation(const Scene& scene, std::string* report = nullptr);

/// Runs the scene, writing frames into options.out_dir. Before anything large is allocated it
/// checks the output folder (InputError), the scene's scale and the estimated memory and steps
/// per frame against options.limits (InputError naming the keys and the option to raise), and
/// the initial surface (InputError). Once `stop` becomes true it stops at the next safe point —
/// between steps, or inside a step's long loops (solver iterations, remeshing, collision
/// rounds), discarding that frame — with RunResult::interrupted; every frame written is
/// complete (its stats.jsonl line is written last). If `stop` comes before frame 0 is written,
/// meniscus::Cancelled propagates. A failed write throws meniscus::WriteError; any other
/// failure during the run InternalFailure saying where.
RunResult run_scene(const Scene& scene, const RunOptions& options, const std::atomic<bool>& stop);

}  // namespace meniscus::app
