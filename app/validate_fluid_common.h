#pragma once
/// \file What the part-B validation cases share (app/validate_fluid.cpp: B1–B5,
/// app/validate_viscous.cpp: B6–B7): scene building, run summaries, formatting, and convergence
/// studies — a case measured at several resolutions (observed order in Δx against the reference)
/// and at Δt, Δt/2, Δt/4 (observed order in Δt from successive differences).

#include "app/fluid_measures.h"
#include "app/scene.h"
#include "app/validate_fluid.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace meniscus::app::validate_fluid {

using Json = nlohmann::json;

/// printf-style formatting of one number.
std::string fmt(double v, const char* f = "%.4g");
/// 100 (measured/reference − 1) as "+1.23 %".
std::string percent(double measured, double reference);
/// A time-step factor as the report names it: "Δt" for 1, "Δt/2" for ½, …
std::string dt_factor_text(double factor);

/// A fluid scene JSON with the validation defaults: two_phase, no gravity, one cell per edge,
/// volume correction on, no PLY/VDB output.
Json base_scene(const std::string& name);
/// The Scene of a JSON built by base_scene() and its callers.
Scene scene_from(const Json& j);

/// The series every run records (t, components, enclosed volume, max speed).
Json series_json(const FluidRunRecord& r);
/// Steps, completion, convergence, intersections and wall time of a run.
Json run_summary(const FluidRunRecord& r);
/// Largest |v/v₀ − 1| over a series.
double max_relative_drift(const std::vector<double>& v);
/// Largest value of a series (0 when empty).
double series_peak(const std::vector<double>& v);
/// The fields of a damped-oscillation fit (ω, γ, the coefficients, the rms residual) for a
/// run's JSON, with the frequency's relative error against `omega_reference`.
Json oscillation_fit_json(const OscillationFit& fit, double omega_reference);

/// Shared state of the cases: options, the output, and what failed.
struct CaseContext {
    const FluidValidationOptions& options;
    FluidValidation& out;

    /// A progress line on stderr unless quiet.
    void log(const std::string& line) const;
    /// Records a failure for a run that did not finish, intersected itself or whose pressure
    /// (or viscosity) solve did not converge.
    void check(const std::string& what, const FluidRunRecord& r);
};

/// One run of a convergence study.
struct StudyRun {
    double dt_factor = 1.0;   ///< Δt over the solver's own (coupling/capillary_safety)
    double dt = 0.0;          ///< the first step's Δt, s
    double measured = 0.0;    ///< the measured quantity
    double reference = 0.0;   ///< its reference value
    long long steps = 0;
    double wall_seconds = 0.0;
    double relative_error() const { return measured / reference - 1.0; }
};

/// The runs of one resolution, at Δt factors 1, ½, ¼ … (the first is the solver's own Δt).
struct StudyRow {
    int resolution = 0;  ///< cells per diameter (or wavelength): the table's label
    double dx = 0.0;     ///< m
    std::vector<StudyRun> runs;
};

/// A quantity of a case at several resolutions, each at several time steps.
struct Study {
    std::string quantity;  ///< e.g. "rise speed"
    std::string unit;      ///< e.g. "m/s"
    std::vector<StudyRow> rows;  ///< ascending resolution

    /// The run of `row` at `dt_factor`, appended (rows in ascending resolution, factors in
    /// descending order, 1 first).
    void add(int resolution, double dx, const StudyRun& run);
};

/// Observed order in Δx between rows i−1 and i, from the errors against the reference at the
/// solver's own Δt (NaN where undefined; none for row 0).
double space_order(const Study& study, size_t row);
/// Observed order in Δt of a row with three or more Δt factors, from successive differences of
/// the measured values (independent of the spatial error): log(|v₁ − v₂| / |v₂ − v₃|) / log r,
/// r the factor ratio. NaN where undefined.
double time_order(const StudyRow& row);

/// results.json entry of a study (rows, runs, orders).
Json study_json(const Study& study);
/// Markdown table of a study: a row per resolution with the error at each Δt factor and the
/// observed orders in Δx and in Δt. `target_relative` applies from `target_resolution` on.
std::string study_markdown(const Study& study, const std::string& resolution_label,
                           double target_relative, int target_resolution);

}  // namespace meniscus::app::validate_fluid
