#pragma once
/// \file `meniscus validate`: runs the paper's geometric-flow validation cases
/// (docs/validation.md part A: A1 normal flow, A2 mean curvature, A3 Enright, A4 curl
/// noise, A5 per-phase cost; A6 Zalesak's notched sphere turned once, app/validate_zalesak.h)
/// through the collision-safe SurfaceTracker and writes, into one
/// folder, `report.md` (our numbers beside the paper's, observed orders, per-phase seconds per
/// step), `results.json` (every number and time series) and PNG plots made by
/// `plot_validation.py` (written beside them; needs /usr/bin/python3 with matplotlib).

#include <string>
#include <vector>

namespace meniscus::app {

/// Options of run_validation().
struct ValidateOptions {
    /// false: the quick variants (coarsest resolution, shortened times; a few minutes, part of
    /// the test suite). true: the paper's resolutions and end times (long).
    bool full = false;
    std::string out_dir = "validation";  ///< folder for report.md, results.json and plots
    bool quiet = false;                  ///< no progress lines on stderr
    /// Cases to run ("A1", "A2", "A3", "A4", "A6"; A5 is timed on the A1 runs; "B1" … "B5": part B,
    /// two-phase flow, app/validate_fluid.h); empty: all.
    std::vector<std::string> cases;
    /// Resolutions ξ (m) of part A to run, each one of the selected cases' own (e.g. 0.01 with
    /// --full for the finest row only); empty: all. A value no selected case runs is an
    /// std::invalid_argument before anything runs. Part B has no ξ and ignores this.
    std::vector<double> xis;
    /// Curvature operators A2's mean-curvature runs use ("cotangent", Meyer's, the paper's;
    /// "quartic_fit", tracker::CurvatureOperator); empty: both, with the quartic dumbbell rows
    /// in full mode only (A2_QUARTIC_FIT_DUMBBELL_IN_QUICK). Naming "quartic_fit" runs its
    /// dumbbell rows in quick mode too. The sphere rows are the cotangent operator's. An unknown
    /// name is an std::invalid_argument before anything runs.
    std::vector<std::string> curvature_operators;
};

/// Throws std::invalid_argument, naming the option, if `options` asks for an unknown case, a
/// ξ that no selected case runs or an unknown curvature operator. run_validation() calls it
/// before running anything.
void check_validate_options(const ValidateOptions& options);

/// Runs the validation cases and writes the report. Returns a process exit code: 0 when every
/// run finished and every collision-safe run stayed intersection-free at every step, 1
/// otherwise (the report says which run failed). Throws std::runtime_error if the output folder
/// cannot be written.
int run_validation(const ValidateOptions& options);

}  // namespace meniscus::app
