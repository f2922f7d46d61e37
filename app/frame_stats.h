#pragma once
/// \file The per-frame lines of stats.jsonl (README, "Running scenes"): what a frame's steps did,
/// summed over them, for a geometric flow (FrameWork, frame_stats) and for a fluid scene
/// (FluidFrameTimes, FrameSolves, FrameOpenBoundaries, fluid_frame_stats), and the run-log
/// warnings of the fluid's solves.

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "common/phase_clock.h"
#include "coupling/open_boundaries.h"
#include "coupling/simulation.h"
#include "fluid/fluid_solver.h"
#include "tracker/mesh.h"

namespace meniscus::app {

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
    long long flow_shortenings = 0;  ///< steps the flow's own limit shortened (inversion, CFL)
    int intersecting_pairs = -1;     ///< worst exact check result of the frame, −1 = not checked
    /// Change of the enclosed volume over the frame's steps (m³): by mesh improvement and
    /// topology changes, by the flow's motion as requested (shortened by the fraction collision
    /// handling applied), and by what collision handling changed of that motion.
    double volume_remeshing = 0.0, volume_motion = 0.0, volume_collisions = 0.0;
};

/// A geometric flow's stats.jsonl line for frame `frame`: the mesh's counts, volumes, edge
/// lengths and angles, and the frame's work.
nlohmann::json frame_stats(int frame, double time, double dt, long long steps,
                           const tracker::SurfaceMesh& mesh, const FrameWork& work);

/// Wall and process-CPU seconds of a frame's fluid steps per phase, summed over its steps, and
/// of writing its files. stats.jsonl "seconds": the wall seconds by phase, the fluid step's own
/// phases under "fluid_phases", and the same figures in CPU seconds under "cpu".
struct FluidFrameTimes {
    coupling::SimulationTimings coupled;
    fluid::StepTimings fluid;
    PhaseSeconds output;

    void add(const coupling::SimulationStepReport& step);

    nlohmann::json json() const;
};

/// The linear solves of a frame's fluid steps.
struct FrameSolves {
    long long pressure_iterations = 0, viscosity_iterations = 0, passes = 0;
    double pressure_residual = 0.0, viscosity_residual = 0.0, pass_change = 0.0;
    int pressure_failures = 0, viscosity_failures = 0, pass_failures = 0;  ///< steps not converged
    /// The cells the coupled scheme's passes ran on, summed over the steps that made passes.
    double pass_cells = 0.0;
    long long steps_with_passes = 0;

    void add(const fluid::StepResult& r);

    nlohmann::json json(long long steps) const;

    /// The run-log warning for unconverged solves ("" when every solve converged).
    std::string warning(int frame, long long steps) const;
};

/// What a frame's steps did at the open faces of the box (inflow and outflow).
struct FrameOpenBoundaries {
    coupling::BoundaryVolumes volumes;
    int clips = 0, components_removed = 0, deferred_clips = 0, unfed_inflows = 0;
    std::string deferred;

    void add(const coupling::OpenBoundaryReport& r);

    /// stats.jsonl "open_boundaries": this frame's volumes in and out by phase (m³), the run's
    /// totals, the clips, the components that left whole, and per inflow face how far the part of
    /// the mesh it feeds reaches into the box (a jet's intact length, m).
    nlohmann::json json(const coupling::BoundaryVolumes& total,
                        const std::vector<coupling::InflowAttachment>& inflows) const;

    /// The run-log warning when cuts at outflow faces had to wait ("" otherwise).
    std::string warning(int frame) const;
};

/// A fluid scene's stats.jsonl line for frame `frame`: the mesh's counts and volumes, the flow's
/// kinetic energy and largest face speed (collective on several ranks), the last step's Δt and
/// pressure solve, `seconds` (FluidFrameTimes::json()) and the members of `work`.
nlohmann::json fluid_frame_stats(int frame, double time, long long steps,
                                 const coupling::Simulation& sim,
                                 const coupling::SimulationStepReport& last,
                                 const nlohmann::json& seconds, const nlohmann::json& work);

}  // namespace meniscus::app
