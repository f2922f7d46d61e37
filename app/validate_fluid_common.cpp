#include "app/validate_fluid_common.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace meniscus::app::validate_fluid {

std::string fmt(double v, const char* f) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

std::string percent(double measured, double reference) {
    return fmt(100.0 * (measured / reference - 1.0), "%+.2f %%");
}

std::string dt_factor_text(double factor) {
    if (factor == 1.0)
        return "Δt";
    return factor > 1.0 ? fmt(factor, "%.3g") + "Δt" : "Δt/" + fmt(1.0 / factor, "%.3g");
}

Json base_scene(const std::string& name) {
    return {{"name", name},
            {"flow", {{"type", "fluid"}}},
            {"fluid", {{"gravity", {0, 0, 0}}, {"mode", "two_phase"}}},
            {"coupling", {{"edge_length_cells", 1.0}, {"volume_correction", true}}},
            {"output", {{"ply", false}, {"vdb", false}}}};
}

Scene scene_from(const Json& j) { return parse_scene(j.dump(), j["name"].get<std::string>(), "."); }

Json series_json(const FluidRunRecord& r) {
    return {{"t", r.t},
            {"components", r.components},
            {"enclosed_volume", r.enclosed_volume},
            {"max_speed", r.max_speed}};
}

Json run_summary(const FluidRunRecord& r) {
    return {{"steps", r.steps},
            {"completed", r.completed},
            {"pressure_converged", r.pressure_converged},
            {"viscosity_converged", r.viscosity_converged},
            {"max_viscous_pressure_passes", r.max_passes},
            {"max_intersecting_pairs", r.max_intersecting_pairs},
            {"wall_seconds", r.wall_seconds}};
}

double max_relative_drift(const std::vector<double>& v) {
    double drift = 0.0;
    for (double x : v)
        drift = std::max(drift, std::abs(x / v.front() - 1.0));
    return drift;
}

double series_peak(const std::vector<double>& v) {
    double peak = 0.0;
    for (double x : v)
        peak = std::max(peak, x);
    return peak;
}

Json oscillation_fit_json(const OscillationFit& fit, double omega_reference) {
    return {{"omega", fit.omega},
            {"decay_rate", fit.decay_rate},
            {"amplitude", fit.amplitude},
            {"cos_coefficient", fit.cos_coefficient},
            {"sin_coefficient", fit.sin_coefficient},
            {"offset", fit.offset},
            {"rms_residual", fit.rms_residual},
            {"frequency_relative_error", fit.omega / omega_reference - 1.0}};
}

void CaseContext::log(const std::string& line) const {
    if (!options.quiet)
        std::fprintf(stderr, "  %s\n", line.c_str());
}

void CaseContext::check(const std::string& what, const FluidRunRecord& r) {
    std::string why;
    if (!r.completed)
        why = "did not reach its end time";
    else if (r.max_intersecting_pairs > 0)
        why = "intersecting triangle pairs";
    else if (!r.pressure_converged)
        why = "a pressure solve did not converge";
    else if (!r.viscosity_converged)
        why = "a viscosity solve did not converge";
    if (!why.empty()) {
        out.all_ok = false;
        out.failures.push_back(what + ": " + why);
    }
}

void Study::add(int resolution, double dx, const StudyRun& run) {
    if (rows.empty() || rows.back().resolution != resolution)
        rows.push_back({resolution, dx, {}});
    rows.back().runs.push_back(run);
}

double space_order(const Study& study, size_t row) {
    if (row == 0 || row >= study.rows.size() || study.rows[row].runs.empty() ||
        study.rows[row - 1].runs.empty())
        return std::numeric_limits<double>::quiet_NaN();
    const StudyRow& a = study.rows[row - 1];
    const StudyRow& b = study.rows[row];
    const double ea = std::abs(a.runs[0].relative_error()), eb = std::abs(b.runs[0].relative_error());
    return ea > 0.0 && eb > 0.0 ? std::log(ea / eb) / std::log(a.dx / b.dx)
                                : std::numeric_limits<double>::quiet_NaN();
}

double time_order(const StudyRow& row) {
    if (row.runs.size() < 3)
        return std::numeric_limits<double>::quiet_NaN();
    const double d1 = std::abs(row.runs[0].measured - row.runs[1].measured);
    const double d2 = std::abs(row.runs[1].measured - row.runs[2].measured);
    const double ratio = row.runs[0].dt_factor / row.runs[1].dt_factor;
    return d1 > 0.0 && d2 > 0.0 ? std::log(d1 / d2) / std::log(ratio)
                                : std::numeric_limits<double>::quiet_NaN();
}

namespace {

Json number_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

std::string order_text(double p) { return std::isfinite(p) ? fmt(p, "%.2f") : "—"; }

}  // namespace

Json study_json(const Study& study) {
    Json rows = Json::array();
    for (size_t i = 0; i < study.rows.size(); ++i) {
        const StudyRow& row = study.rows[i];
        Json runs = Json::array();
        for (const StudyRun& r : row.runs)
            runs.push_back({{"dt_factor", r.dt_factor},
                            {"dt", r.dt},
                            {"measured", r.measured},
                            {"reference", r.reference},
                            {"relative_error", r.relative_error()},
                            {"steps", r.steps},
                            {"wall_seconds", r.wall_seconds}});
        rows.push_back({{"resolution", row.resolution},
                        {"dx", row.dx},
                        {"runs", runs},
                        {"space_order", number_or_null(space_order(study, i))},
                        {"time_order", number_or_null(time_order(row))}});
    }
    return {{"quantity", study.quantity}, {"unit", study.unit}, {"rows", rows}};
}

std::string study_markdown(const Study& study, const std::string& resolution_label,
                           double target_relative, int target_resolution) {
    std::vector<double> factors;
    for (const StudyRow& row : study.rows)
        if (row.runs.size() > factors.size()) {
            factors.clear();
            for (const StudyRun& r : row.runs)
                factors.push_back(r.dt_factor);
        }
    std::ostringstream md;
    md << "| " << resolution_label << " | Δx (m) | Δt (s) | steps | " << study.quantity << " ("
       << study.unit << ") | reference |";
    for (double f : factors)
        md << " error at " << dt_factor_text(f) << " |";
    md << " order in Δx | order in Δt | target |\n|---|---|---|---|---|---|";
    for (size_t i = 0; i < factors.size(); ++i)
        md << "---|";
    md << "---|---|---|\n";
    for (size_t i = 0; i < study.rows.size(); ++i) {
        const StudyRow& row = study.rows[i];
        if (row.runs.empty())
            continue;
        const StudyRun& own = row.runs[0];
        md << "| " << row.resolution << " | " << fmt(row.dx, "%.3g") << " | "
           << fmt(own.dt, "%.3g") << " | " << own.steps << " | " << fmt(own.measured, "%.5g")
           << " | " << fmt(own.reference, "%.5g") << " |";
        for (size_t f = 0; f < factors.size(); ++f)
            md << " " << (f < row.runs.size() ? percent(row.runs[f].measured, row.runs[f].reference)
                                              : std::string("—"))
               << " |";
        md << " " << order_text(space_order(study, i)) << " | " << order_text(time_order(row))
           << " | "
           << (row.resolution >= target_resolution ? fmt(100.0 * target_relative, "%.3g %%")
                                                   : "—")
           << " |\n";
    }
    md << "\nOrder in Δx: between successive resolutions, from the errors at the solver's own Δt. "
          "Order in Δt: from the differences of the measured values at Δt, Δt/2, Δt/4 "
          "(independent of the spatial error).\n";
    return md.str();
}

}  // namespace meniscus::app::validate_fluid
