#pragma once
/// \file One tracked run of `meniscus validate` part A: a SurfaceTracker driven step by step
/// exactly as app/run.cpp does (improve → change_topology → velocities → integrate), with the
/// four phases of the paper's Table 4.4 timed, the enclosed volume's change split by phase, and
/// the intersecting triangle pairs counted after every step with the exact static test; and its
/// numbers as JSON for results.json.

#include "tracker/flows/flow_errors.h"
#include "tracker/flows/flow_runner.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/surface_tracker.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

namespace meniscus::app::flow_validation {

/// Per-phase wall time (s), summed over steps.
struct PhaseSeconds {
    double improvement = 0.0, topology = 0.0, set_velocity = 0.0, collisions = 0.0;
    double verification = 0.0;  ///< the exact static intersection test (not a paper phase)
};

/// Where the enclosed volume changed (m³, summed over steps): mesh improvement and topology
/// changes; the flow's motion as requested (shortened by the fraction collision handling
/// applied); and what collision handling changed of that motion.
struct VolumeBudget {
    double remeshing = 0.0, motion = 0.0, collisions = 0.0;
};

struct RunSpec {
    std::string case_id;  ///< "A1", …
    std::string label;    ///< e.g. "face offsetting"
    double xi_requested = 0.0;
    tracker::ShapePtr shape;
    tracker::TrackerOptions tracker;
    std::shared_ptr<const tracker::FlowStepper> stepper;
    double t_end = 0.0;
    double max_dt = 0.0;
    std::vector<double> breakpoints;  ///< steps end exactly on these times
    /// Refinement of the initial mesh around the shape's creases (off by default); the
    /// tracker then keeps the unrefined ξ unless `tracker.characteristic_length` is set.
    tracker::CreaseRefinementOptions crease;
};

struct RunResult {
    RunSpec spec;
    double xi = 0.0;  ///< measured ξ of the initial mesh
    double t = 0.0;
    long steps = 0;
    bool completed = false;
    std::string stop_reason;
    double initial_volume = 0.0;
    PhaseSeconds seconds;
    VolumeBudget volume_budget;
    int min_triangles = 0, max_triangles = 0;
    int max_intersecting_pairs = 0;
    int steps_with_intersections = 0;
    int initial_intersecting_pairs = 0;
    std::vector<double> series_t, series_volume;
    std::vector<int> series_triangles, series_pairs, series_components;
    tracker::SurfaceMesh initial_mesh;  ///< as the tracker started (after meshing the shape)
    tracker::SurfaceMesh final_mesh;
    double wall_seconds = 0.0;
};

/// Meshes spec.shape at spec.xi_requested and runs it to spec.t_end (or a stop: step limit,
/// triangle limit, stalled steps; RunResult::stop_reason says which). Progress lines and a
/// summary go to stderr unless `quiet`.
RunResult run_tracked(const RunSpec& spec, bool quiet);

/// TrackerOptions with the paper's α, β and γ (docs/validation.md part A).
tracker::TrackerOptions paper_tracker_options();

/// Every number of a run (spec, counts, seconds per step by phase, volume budget, time series).
nlohmann::json run_json(const RunResult& r);

/// A SurfaceError as JSON (the keys results.json and the report read).
nlohmann::json error_json(const tracker::SurfaceError& e);

}  // namespace meniscus::app::flow_validation
