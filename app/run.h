#pragma once
/// \file Running a scene: time stepping, per-frame output, checkpoints and resuming (the set-up
/// before the first step is scene_setup.h).

#include "app/errors.h"
#include "app/resource_estimate.h"
#include "app/scene.h"
#include "fluid/rank_communicator.h"
#include "tracker/mesh.h"

#include <atomic>
#include <stdexcept>
#include <string>

namespace meniscus::app {

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
    /// The ranks of a run under mpirun (issue 40): a fluid scene's grid is split over them, rank 0
    /// writes the frames and the stats; this process alone by default.
    fluid::RankCommunicator ranks = fluid::RankCommunicator::self();
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
