/// Part B of `meniscus validate`: two-phase flow with surface tension (docs/validation.md B1–B5;
/// B6–B7 in validate_viscous.cpp); the plots are in validate_fluid_plots.cpp.
/// B1–B4 drive a coupling::Simulation step by step and measure the mesh after every step
/// (app/fluid_measures.h); B5 is in validate_merge.cpp.

#include "app/scene_setup.h"
#include "app/validate_fluid.h"

#include "app/fluid_measures.h"
#include "app/fluid_references.h"
#include "app/run.h"
#include "app/validate_fluid_common.h"
#include "app/validate_merge.h"
#include "app/validate_viscous.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace meniscus::app {

namespace {

using namespace validate_fluid;
using Eigen::Vector3d;

}  // namespace

bool is_fluid_case(const std::string& id) {
    return id == "B1" || id == "B2" || id == "B3" || id == "B4" || id == "B5" || id == "B6" ||
           id == "B7";
}

// ---- The cases ----------------------------------------------------------------------------------

namespace {

/// Water and air (the scenes' defaults), no gravity.
constexpr double SIGMA = 0.0728;   ///< N/m
constexpr double RHO_L = 1000.0;   ///< kg/m³
constexpr double RHO_G = 1.2;      ///< kg/m³
constexpr double MU_L = 1.0e-3;    ///< Pa·s
constexpr double DROP_R = 0.002;   ///< m, B1 and B2 drop radius
/// Lamb l = 2 drop: R(1 + ε P₂(cos θ)) ≈ ellipsoid with semi-axes R(1 + ε), R(1 − ε/2).
constexpr double LAMB_EPSILON = 0.05;
/// B3: column radius and the fastest-growing wavelength 2πR/0.697 (as scenes/jet_pinch.json).
constexpr double JET_R = 0.0006;
constexpr double JET_WAVELENGTH = 0.00541;
constexpr double JET_BOX = 0.003;  ///< cross-section edge, m
constexpr double JET_EPSILON = 0.01;
/// The linear regime of B3: amplitudes below this fraction of R enter the growth fit.
constexpr double LINEAR_AMPLITUDE_FRACTION = 0.1;
/// The closed slab and the perturbed column extend this many cells beyond the walls they cross,
/// where a box cuts them: the cut's sharp rim (and its curvature, spread by smoothing passes)
/// must stay well away from the grid faces next to the wall. (With 2 cells and 2 smoothing
/// passes the rim's curvature reached the wall faces: at R = 3 cells the 1 % perturbation of
/// B3 shrank and reversed sign instead of growing.)
constexpr double WALL_OVERLAP_CELLS = 6.0;
/// B4 (docs/validation.md): σ = 1, ρ₁ = ρ₂ = 1, λ = 1, amplitude 0.01λ, inviscid.
constexpr double WAVE_LAMBDA = 1.0;
constexpr double WAVE_AMPLITUDE = 0.01;
constexpr double WAVE_THICKNESS_CELLS = 4.0;
/// B1: pressure samples this many cells away from the interface.
constexpr double B1_WELL_CELLS = 3.0;
/// Δt of the semi-implicit runs in units of the capillary limit (issue: ≥ 3×).
constexpr double IMPLICIT_DT_FACTOR = 3.0;

struct Runner : CaseContext {
    /// Δt factors of a study's coarsest row (the solver's own Δt first); the other rows run at the
    /// solver's own Δt only. `quick_too`: cheap cases measure the order in Δt in quick mode too.
    std::vector<double> factors_of(size_t row, bool quick_too = false) const {
        if (row == 0 && (options.full || quick_too))
            return {1.0, 0.5, 0.25};
        return {1.0};
    }

    /// A run of a study: its Δt factor, whether the surface tension is semi-implicit, and
    /// whether it belongs to the implicit-tension comparison (trilinear vertex velocities, which
    /// /coupling/implicit_tension needs) instead of the study.
    struct Variant {
        double factor = 1.0;
        bool implicit = false;
        bool comparison = false;
    };
    /// factors_of(), and on the coarsest row the comparison pair: explicit at the solver's own Δt
    /// and semi-implicit (/coupling/implicit_tension 1) at IMPLICIT_DT_FACTOR × the capillary
    /// limit, both with trilinear vertex velocities (kept out of the study; in quick mode only
    /// where `compare_quick`).
    std::vector<Variant> variants_of(size_t row, bool quick_too = false,
                                     bool compare_quick = true) const {
        std::vector<Variant> variants;
        for (double factor : factors_of(row, quick_too))
            variants.push_back({factor, false, false});
        if (row == 0 && (options.full || compare_quick)) {
            variants.push_back({1.0, false, true});
            variants.push_back({IMPLICIT_DT_FACTOR, true, true});
        }
        return variants;
    }
    /// Sets the variant's time step, tension treatment and interpolation on a case's scene.
    static void apply_variant(Json& j, const Variant& v) {
        j["coupling"]["capillary_safety"] = v.factor;
        j["coupling"]["implicit_tension"] = v.implicit ? 1.0 : 0.0;
        if (v.comparison)
            j["coupling"]["velocity_interpolation"] = "trilinear";
        else
            j["coupling"].erase("velocity_interpolation");
    }
    static std::string variant_text(const Variant& v) {
        if (!v.comparison)
            return dt_factor_text(v.factor);
        return dt_factor_text(v.factor) + (v.implicit ? ", implicit" : ", explicit") +
               " tension, trilinear velocities";
    }

    // ---- B1 ----
    void b1(std::ostringstream& md) {
        const std::vector<int> resolutions =
            options.full ? std::vector<int>{10, 16, 25} : std::vector<int>{10, 16};
        // Full: 10 ms, a third of the capillary time sqrt(ρD³/σ) ≈ 30 ms (one viscous time
        // D²ρ/μ = 16 s would be 10⁵ steps). Quick: 2 ms.
        const double diameter = 2.0 * DROP_R;
        const double capillary_time = std::sqrt(RHO_L * std::pow(diameter, 3) / SIGMA);
        const double end = options.full ? 0.010 : 0.002;
        const double laplace = 2.0 * SIGMA / DROP_R;
        Json runs = Json::array(), implicit_runs = Json::array();
        Study study{"pressure jump Δp", "Pa", {}};
        for (size_t row = 0; row < resolutions.size(); ++row) {
            const int cpd = resolutions[row];
            const double box = 2.0 * diameter;
            const int cells = 2 * cpd;
            const double dx = box / cells;
            const Vector3d centre = Vector3d::Constant(box / 2);
            Json j = base_scene("B1 static drop");
            j["domain"] = {{"min", {0, 0, 0}}, {"size", {box, box, box}}, {"cells", cells}};
            j["coupling"]["curvature_smoothing"] = 2;  // as scenes/static_drop.json
            j["surface"] = {{"shape",
                             {{"type", "sphere"},
                              {"center", {centre.x(), centre.y(), centre.z()}},
                              {"radius", DROP_R}}}};
            for (const Variant& variant : variants_of(row, true)) {
                const double factor = variant.factor;
                apply_variant(j, variant);
                Scene scene = scene_from(j);
                scene.tracker.verify_intersection_free = true;
                coupling::Simulation sim = make_fluid_simulation(scene);
                std::vector<double> jump;
                const auto sample = [&](const coupling::Simulation& s) {
                    const fluid::Array3<double>& p = s.fluid().pressure();
                    const fluid::MacGrid& grid = s.fluid().grid();
                    double in = 0.0, outside = 0.0;
                    long long n_in = 0, n_out = 0;
                    for (int k = 0; k < grid.nz(); ++k)
                        for (int jj = 0; jj < grid.ny(); ++jj)
                            for (int i = 0; i < grid.nx(); ++i) {
                                const double r = (grid.cell_centre(i, jj, k) - centre).norm();
                                if (r < DROP_R - B1_WELL_CELLS * dx) {
                                    in += p(i, jj, k);
                                    ++n_in;
                                } else if (r > DROP_R + B1_WELL_CELLS * dx) {
                                    outside += p(i, jj, k);
                                    ++n_out;
                                }
                            }
                    jump.push_back(n_in > 0 && n_out > 0 ? in / n_in - outside / n_out : 0.0);
                };
                const FluidRunRecord r = run_sampled(sim, end, sample);
                const std::string what = "B1 " + std::to_string(cpd) + " cells per diameter, " +
                                         variant_text(variant);
                check(what, r);
                if (!variant.comparison)
                    study.add(cpd, dx,
                              {factor, r.first_dt, jump.back(), laplace, r.steps, r.wall_seconds});
                const double peak_speed = series_peak(r.max_speed);
                const double scale = std::sqrt(RHO_L * diameter / SIGMA);
                Json run = run_summary(r);
                run.update({{"cells_per_diameter", cpd},
                            {"dt_factor", factor},
                            {"dt", r.first_dt},
                            {"dx", dx},
                            {"t_end", sim.time()},
                            {"jump", jump.back()},
                            {"laplace", laplace},
                            {"jump_relative_error", jump.back() / laplace - 1.0},
                            {"final_max_speed", r.max_speed.back()},
                            {"peak_max_speed", peak_speed},
                            {"capillary_number_final", r.max_speed.back() * scale},
                            {"capillary_number_peak", peak_speed * scale},
                            {"volume_drift", max_relative_drift(r.enclosed_volume)},
                            {"series", series_json(r)}});
                run["series"]["jump"] = jump;
                log(what + ": Δp " + fmt(jump.back()) + " Pa (2σ/R " + fmt(laplace) +
                    "), max|u| " + fmt(r.max_speed.back()) + " m/s, " +
                    fmt(r.wall_seconds, "%.0f") + " s");
                run["implicit_tension"] = variant.implicit;
                (variant.comparison ? implicit_runs : runs).push_back(run);
            }
        }
        out.results["B1"] = {{"runs", runs},
                             {"implicit_runs", implicit_runs},
                             {"t_end", end},
                             {"velocity_scale", std::sqrt(SIGMA / (RHO_L * diameter))},
                             {"capillary_time", capillary_time},
                             {"viscous_time", diameter * diameter * RHO_L / MU_L},
                             {"jump", study_json(study)}};
        md << "## B1 — static drop (Laplace)\n\n"
           << "Water drop R = 2 mm in air (σ = 0.0728 N/m, ρ 1000/1.2, μ 1e-3/1.8e-5), no "
              "gravity, box 2D, 2 curvature smoothing passes (as scenes/static_drop.json). Δp = "
              "mean pressure of the cells more than 3 cells inside the sphere minus that more "
              "than 3 cells outside, at the end of the run. Spurious currents: max|u| over the "
              "grid faces, as max|u|·sqrt(ρD/σ). **Run length: "
           << fmt(1e3 * end, "%.3g")
           << " ms** (capillary time sqrt(ρD³/σ) = " << fmt(1e3 * capillary_time, "%.3g")
           << " ms), not one viscous time D²ρ/μ = 16 s (10⁵ steps at these resolutions).\n\n"
           << study_markdown(study, "cells per D", 0.02, 16) << "\n"
           << "| cells per D | Δt | steps | max|u| end (m/s) | max|u|·sqrt(ρD/σ) end | peak over "
              "run | volume drift | max intersecting pairs |\n|---|---|---|---|---|---|---|---|\n";
        for (const Json& r : runs)
            md << "| " << r["cells_per_diameter"] << " | "
               << dt_factor_text(r["dt_factor"].get<double>()) << " | " << r["steps"] << " | "
               << fmt(r["final_max_speed"].get<double>(), "%.3e") << " | "
               << fmt(r["capillary_number_final"].get<double>(), "%.3e") << " | "
               << fmt(r["capillary_number_peak"].get<double>(), "%.3e") << " | "
               << fmt(100.0 * r["volume_drift"].get<double>(), "%.3f %%") << " | "
               << r["max_intersecting_pairs"] << " |\n";
        md << "\nReference: Δp within 2 % of 2σ/R at ≥ 16 cells per diameter; balanced-force VOF "
              "codes reach max|u|·sqrt(ρD/σ) < 1e-6 at 25 cells per diameter with exact "
              "curvature. Plot: b1_spurious.png (spurious currents, and Δp's error against "
              "resolution).\n\n";
        md << implicit_markdown(
            implicit_runs, "cells_per_diameter",
            {{"Δp (Pa)", "jump", "%.5g"},
             {"peak max|u|·sqrt(ρD/σ)", "capillary_number_peak", "%.3e"}});
    }

    // ---- B2 ----
    void b2(std::ostringstream& md) {
        const std::vector<int> resolutions =
            options.full ? std::vector<int>{12, 16, 25} : std::vector<int>{12};
        const double omega = lamb_omega(2, SIGMA, DROP_R, RHO_L, RHO_G);
        const double period = 2.0 * M_PI / omega;
        const double tau = DROP_R * DROP_R / (1.0 * 5.0 * (MU_L / RHO_L));
        // Quick: 1.3 periods (the fit needs one full period); full: 1.5.
        const double end = (options.full ? 1.5 : 1.3) * period;
        Json runs = Json::array(), implicit_runs = Json::array();
        Study study{"frequency ω", "1/s", {}};
        for (size_t row = 0; row < resolutions.size(); ++row) {
            const int cpd = resolutions[row];
            const double box = 4.0 * DROP_R;
            const int cells = 2 * cpd;
            Json j = base_scene("B2 oscillating drop");
            j["domain"] = {{"min", {0, 0, 0}}, {"size", {box, box, box}}, {"cells", cells}};
            j["coupling"]["curvature_smoothing"] = 1;  // as scenes/oscillating_drop.json
            const double a = DROP_R * (1.0 + LAMB_EPSILON), b = DROP_R * (1.0 - 0.5 * LAMB_EPSILON);
            j["surface"] = {{"shape",
                             {{"type", "ellipsoid"},
                              {"center", {box / 2, box / 2, box / 2}},
                              {"radii", {a, b, b}}}}};
            // The comparison runs in quick mode too: with the surface term in the viscous CG's
            // preconditioner the semi-implicit run costs what the explicit one does (it took 62 s
            // against 19 with the plain diagonal).
            for (const Variant& variant : variants_of(row, false, true)) {
                const double factor = variant.factor;
                apply_variant(j, variant);
                Scene scene = scene_from(j);
                scene.tracker.verify_intersection_free = true;
                coupling::Simulation sim = make_fluid_simulation(scene);
                std::vector<double> deformation;
                const auto sample = [&](const coupling::Simulation& s) {
                    const VolumeMoments m = volume_moments(s.tracker().mesh());
                    deformation.push_back(m.semi_axes.x() -
                                          0.5 * (m.semi_axes.y() + m.semi_axes.z()));
                };
                const FluidRunRecord r = run_sampled(sim, end, sample);
                const std::string what = "B2 " + std::to_string(cpd) + " cells per diameter, " +
                                         variant_text(variant);
                check(what, r);
                const OscillationFit fit =
                    fit_damped_oscillation(r.t, deformation, 0.5 * omega, 1.5 * omega);
                if (!variant.comparison)
                    study.add(cpd, box / cells,
                              {factor, r.first_dt, fit.omega, omega, r.steps, r.wall_seconds});
                Json run = run_summary(r);
                run.update({{"cells_per_diameter", cpd},
                            {"dt_factor", factor},
                            {"dt", r.first_dt},
                            {"dx", box / cells},
                            {"period", 2.0 * M_PI / fit.omega},
                            {"volume_drift", max_relative_drift(r.enclosed_volume)},
                            {"series", series_json(r)}});
                run.update(oscillation_fit_json(fit, omega));
                run["series"]["deformation"] = deformation;
                log(what + ": period " + fmt(1e3 * 2.0 * M_PI / fit.omega) + " ms (Lamb " +
                    fmt(1e3 * period) + "), " + fmt(r.wall_seconds, "%.0f") + " s");
                run["implicit_tension"] = variant.implicit;
                (variant.comparison ? implicit_runs : runs).push_back(run);
            }
        }
        out.results["B2"] = {{"runs", runs},
                             {"implicit_runs", implicit_runs},
                             {"lamb_omega", omega},
                             {"lamb_period", period},
                             {"viscous_decay_time", tau},
                             {"t_end", end},
                             {"frequency", study_json(study)}};
        md << "## B2 — oscillating drop (Lamb, l = 2)\n\n"
           << "Water drop R = 2 mm in air, no gravity, initial ellipsoid with semi-axes R(1+ε), "
              "R(1−ε/2), R(1−ε/2), ε = 0.05 (R(1 + ε P₂) to first order); 1 curvature smoothing "
              "pass (as scenes/oscillating_drop.json). Measured every step: the deformation "
              "d = a_x − (a_y + a_z)/2 from the exact volume moments of the mesh (a_d = "
              "sqrt(5⟨(x_d − c_d)²⟩), exact for an ellipsoid). Fitted over the whole run ("
           << fmt(end / period, "%.2g")
           << " periods) by least squares to d₀ + e^{−γt}(A cos ωt + B sin ωt). Lamb with both "
              "phases: ω² = 24σ/(R³(3ρ_l + 2ρ_g)), period "
           << fmt(1e3 * period, "%.4g") << " ms; viscous decay time τ = R²/(5ν) = "
           << fmt(tau, "%.3g") << " s (γ = 1/τ = " << fmt(1.0 / tau, "%.3g") << " 1/s).\n\n"
           << study_markdown(study, "cells per D", 0.02, 25) << "\n"
           << "| cells per D | Δt | steps | fitted period (ms) | Lamb (ms) | fitted γ (1/s) | 1/τ "
              "(1/s) | fit rms / amplitude | volume drift | max intersecting pairs "
              "|\n|---|---|---|---|---|---|---|---|---|---|\n";
        for (const Json& r : runs)
            md << "| " << r["cells_per_diameter"] << " | "
               << dt_factor_text(r["dt_factor"].get<double>()) << " | " << r["steps"] << " | "
               << fmt(1e3 * r["period"].get<double>(), "%.4g") << " | "
               << fmt(1e3 * period, "%.4g") << " | "
               << fmt(r["decay_rate"].get<double>(), "%.3g") << " | " << fmt(1.0 / tau, "%.3g")
               << " | "
               << fmt(r["rms_residual"].get<double>() / r["amplitude"].get<double>(), "%.3f")
               << " | " << fmt(100.0 * r["volume_drift"].get<double>(), "%.3f %%") << " | "
               << r["max_intersecting_pairs"] << " |\n";
        md << "\nTarget: the frequency within 2 % at 25 cells per diameter. Reference (Basilisk, "
              "2D analogue): +1.4 %, −0.5 %, 0.1 %, 0.1 % frequency error at 6.4, 12.8, 25.6, "
              "51.2 cells per diameter. Plot: b2_oscillation.png.\n\n";
        md << implicit_markdown(implicit_runs, "cells_per_diameter",
                                {{"ω (1/s)", "omega", "%.5g"}, {"γ (1/s)", "decay_rate", "%.3g"}});
    }

    // ---- B3 ----
    void b3(std::ostringstream& md) {
        // One wavelength, wall to wall, bulges at both walls and the neck in the middle (free-
        // slip walls are mirror planes); the column crosses the end walls by
        // WALL_OVERLAP_CELLS and is cut there by a box (outside the domain).
        // R = 3, 4 (as jet_pinch) and 5.3 cells; quick: R = 3 cells.
        const std::vector<int> resolutions =
            options.full ? std::vector<int>{27, 36, 48} : std::vector<int>{27};
        const int primary = options.full ? 36 : 27;  // runs on to pinch-off (full)
        const double k = 2.0 * M_PI / JET_WAVELENGTH;
        const double rate = rayleigh_plateau_rate(SIGMA, RHO_L, JET_R, k);
        const double capillary_time = std::sqrt(RHO_L * std::pow(JET_R, 3) / SIGMA);
        // The linear regime (ε grows ≈ 2.5×) is all the growth fit needs; the primary run of
        // the full variant goes on to pinch-off.
        const double linear_end = 0.008;
        const double pinch_end = options.full ? 0.030 : linear_end;
        Json runs = Json::array();
        Study study{"growth rate s", "1/s", {}};
        for (size_t row = 0; row < resolutions.size(); ++row) {
            const int cells = resolutions[row];
            const double dx = JET_WAVELENGTH / cells;
            const double m = WALL_OVERLAP_CELLS * dx;
            Json j = base_scene("B3 Rayleigh–Plateau");
            j["domain"] = {{"min", {0, 0, 0}},
                           {"size", {JET_WAVELENGTH, JET_BOX, JET_BOX}},
                           {"cells", cells}};
            j["coupling"]["curvature_smoothing"] = 2;  // as scenes/jet_pinch.json
            j["surface"] = {
                {"shape",
                 {{"type", "intersection"},
                  {"shapes",
                   {{{"type", "perturbed_cylinder"},
                     {"center", {JET_WAVELENGTH, JET_BOX / 2, JET_BOX / 2}},
                     {"axis", {1, 0, 0}},
                     {"radius", JET_R},
                     {"height", 2.0 * JET_WAVELENGTH + 4.0 * m},
                     {"amplitude", JET_EPSILON},
                     {"wavelength", JET_WAVELENGTH}},
                    {{"type", "box"},
                     {"min", {-m, -m, -m}},
                     {"max", {JET_WAVELENGTH + m, JET_BOX + m, JET_BOX + m}}}}}}}};
            for (double factor : factors_of(row)) {
                j["coupling"]["capillary_safety"] = factor;
                const double end = cells == primary && factor == 1.0 ? pinch_end : linear_end;
                Scene scene = scene_from(j);
                scene.tracker.verify_intersection_free = true;
                coupling::Simulation sim = make_fluid_simulation(scene);
                std::vector<double> amplitude, mean_radius;
                const auto sample = [&](const coupling::Simulation& s) {
                    const ModeFit f = column_radius_mode(
                        s.tracker().mesh(), Eigen::Vector2d(JET_BOX / 2, JET_BOX / 2), 0.0,
                        JET_WAVELENGTH, 0.0, JET_WAVELENGTH);
                    amplitude.push_back(f.cos_amplitude);
                    mean_radius.push_back(f.mean);
                };
                const FluidRunRecord r = run_sampled(sim, end, sample);
                const std::string what = "B3 " + std::to_string(cells) + " cells per wavelength, " +
                                         dt_factor_text(factor);
                check(what, r);
                // The linear regime: from the start while the amplitude stays below 0.1 R, one
                // component, and the same window for every run (the one that goes on to
                // pinch-off too), so that the rows compare.
                std::vector<double> t_lin, a_lin;
                for (size_t i = 0; i < r.t.size(); ++i) {
                    if (amplitude[i] > LINEAR_AMPLITUDE_FRACTION * JET_R || r.components[i] != 1 ||
                        r.t[i] > linear_end * (1.0 + 1e-9))
                        break;
                    t_lin.push_back(r.t[i]);
                    a_lin.push_back(amplitude[i]);
                }
                GrowthFit fit;
                if (t_lin.size() >= 4)
                    fit = fit_growth_from_rest(t_lin, a_lin, 0.2 * rate, 3.0 * rate);
                study.add(cells, dx, {factor, r.first_dt, fit.rate, rate, r.steps, r.wall_seconds});
                double pinch_time = -1.0;
                for (size_t i = 0; i < r.t.size(); ++i)
                    if (r.components[i] > 1) {
                        pinch_time = r.t[i];
                        break;
                    }
                Json run = run_summary(r);
                run.update({{"cells_per_wavelength", cells},
                            {"dt_factor", factor},
                            {"dt", r.first_dt},
                            {"t_end", end},
                            {"radius_cells", JET_R / dx},
                            {"rate", fit.rate},
                            {"rate_relative_error", fit.rate / rate - 1.0},
                            {"fit_samples", t_lin.size()},
                            {"fit_t_end", t_lin.empty() ? 0.0 : t_lin.back()},
                            {"fit_a_plus", fit.a_plus},
                            {"fit_a_minus", fit.a_minus},
                            {"fit_rms_relative", fit.rms_relative_residual},
                            {"pinch_time", pinch_time},
                            {"final_components", r.components.back()},
                            {"volume_drift", max_relative_drift(r.enclosed_volume)},
                            {"series", series_json(r)}});
                run["series"]["amplitude"] = amplitude;
                run["series"]["mean_radius"] = mean_radius;
                log(what + ": growth " + fmt(fit.rate) + " 1/s (theory " + fmt(rate) + "), " +
                    (pinch_time >= 0.0 ? "pinch at " + fmt(1e3 * pinch_time) + " ms"
                                       : "no pinch-off") +
                    ", " + fmt(r.wall_seconds, "%.0f") + " s");
                runs.push_back(run);
            }
        }
        out.results["B3"] = {{"runs", runs},
                             {"theory_rate", rate},
                             {"kR", k * JET_R},
                             {"radius", JET_R},
                             {"capillary_time", capillary_time},
                             {"t_end", pinch_end},
                             {"growth", study_json(study)}};
        md << "## B3 — Rayleigh–Plateau\n\n"
           << "Water column R = 0.6 mm in air, no gravity, 1 % cosine perturbation at kR = "
           << fmt(k * JET_R, "%.3f")
           << " (λ = 5.41 mm), one wavelength between free-slip end walls (mirror planes: "
              "bulges at the walls, the neck in the middle). Amplitude a(t): least-squares "
              "cos(kx) mode of the vertices' distance to the axis. Fitted, while a < 0.1R and "
              "the column is whole, to A e^{st} + B e^{−st} (the linear solution from rest; "
              "relative least squares) up to " << fmt(1e3 * linear_end, "%.3g")
           << " ms in every run. Inviscid theory: s² = σ/(ρR³)·x(1−x²)I₁(x)/I₀(x), s = "
           << fmt(rate, "%.4g") << " 1/s. Runs end at " << fmt(1e3 * linear_end, "%.3g")
           << " ms (the linear regime)"
           << (options.full ? ", the 36-cell run at the solver's Δt at 30 ms (pinch-off)" : "")
           << ".\n\n"
           << study_markdown(study, "cells per λ", 0.05, 27) << "\n"
           << "| cells per λ | R (cells) | Δt | fit window (ms) | fit rms (relative) | pinch-off "
              "at (ms) | components at end | volume drift | max intersecting pairs "
              "|\n|---|---|---|---|---|---|---|---|---|\n";
        for (const Json& r : runs) {
            const double pinch = r["pinch_time"].get<double>();
            md << "| " << r["cells_per_wavelength"] << " | "
               << fmt(r["radius_cells"].get<double>(), "%.2g") << " | "
               << dt_factor_text(r["dt_factor"].get<double>()) << " | 0–"
               << fmt(1e3 * r["fit_t_end"].get<double>(), "%.3g") << " | "
               << fmt(r["fit_rms_relative"].get<double>(), "%.3f") << " | "
               << (pinch > 0.0 ? fmt(1e3 * pinch, "%.3g") : std::string("—")) << " | "
               << r["final_components"] << " | "
               << fmt(100.0 * r["volume_drift"].get<double>(), "%.3f %%") << " | "
               << r["max_intersecting_pairs"] << " |\n";
        }
        md << "\nPlot: b3_growth.png (log amplitude with the fit and the theory, and the growth "
              "rate's error against resolution).\n\n";
    }

    // ---- B4 ----
    void b4(std::ostringstream& md) {
        const std::vector<int> resolutions =
            options.full ? std::vector<int>{16, 24, 32} : std::vector<int>{16};
        const double depth = 0.5 * WAVE_LAMBDA, height = WAVE_LAMBDA;
        const double sigma = 1.0, rho = 1.0;
        const double k = 2.0 * M_PI / WAVE_LAMBDA;
        const double omega_deep = std::sqrt(sigma * k * k * k / (2.0 * rho));
        // Finite depth: each layer (depth λ/2 below, λ/2 above) adds ρ coth(kh) to the inertia.
        const double omega = std::sqrt(sigma * k * k * k /
                                       (rho / std::tanh(k * depth) + rho / std::tanh(k * (height - depth))));
        const double period = 2.0 * M_PI / omega;
        const double end = (options.full ? 3.0 : 1.5) * period;
        const double amplitude0 = WAVE_AMPLITUDE * WAVE_LAMBDA;
        Json runs = Json::array(), implicit_runs = Json::array();
        Study study{"frequency ω", "1/s", {}};
        for (size_t row = 0; row < resolutions.size(); ++row) {
            const int cells = resolutions[row];
            const double dx = WAVE_LAMBDA / cells;
            const double thickness = WAVE_THICKNESS_CELLS * dx;
            const double m = WALL_OVERLAP_CELLS * dx;
            Json j = base_scene("B4 capillary wave");
            j["domain"] = {{"min", {0, 0, 0}},
                           {"size", {WAVE_LAMBDA, thickness, height}},
                           {"cells", cells}};
            j["fluid"]["phases"] = {{"rho_liquid", rho}, {"rho_gas", rho}, {"mu_liquid", 0.0},
                                    {"mu_gas", 0.0},     {"sigma", sigma}};
            j["fluid"]["viscosity"] = false;
            j["coupling"]["curvature_smoothing"] = 0;
            j["surface"] = {
                {"shape",
                 {{"type", "intersection"},
                  {"shapes",
                   {{{"type", "wavy_half_space"},
                     {"origin", {0, 0, depth}},
                     {"up", {0, 0, 1}},
                     {"direction", {1, 0, 0}},
                     {"amplitude", amplitude0},
                     {"wavelength", WAVE_LAMBDA}},
                    {{"type", "box"},
                     {"min", {-m, -m, -m}},
                     {"max", {WAVE_LAMBDA + m, thickness + m, height - 0.25 * height}}}}}}}};
            for (const Variant& variant : variants_of(row)) {
                const double factor = variant.factor;
                apply_variant(j, variant);
                Scene scene = scene_from(j);
                scene.tracker.verify_intersection_free = true;
                coupling::Simulation sim = make_fluid_simulation(scene);
                std::vector<double> a;
                const auto sample = [&](const coupling::Simulation& s) {
                    a.push_back(surface_height_mode(s.tracker().mesh(), Vector3d::Zero(),
                                                    Vector3d(WAVE_LAMBDA, thickness, height),
                                                    0.5 * depth, 0.0, WAVE_LAMBDA)
                                    .cos_amplitude);
                };
                const FluidRunRecord r = run_sampled(sim, end, sample);
                const std::string what = "B4 " + std::to_string(cells) + " cells per wavelength, " +
                                         variant_text(variant);
                check(what, r);
                const OscillationFit fit = fit_damped_oscillation(r.t, a, 0.5 * omega, 1.5 * omega);
                if (!variant.comparison)
                    study.add(cells, dx,
                              {factor, r.first_dt, fit.omega, omega, r.steps, r.wall_seconds});
                Json run = run_summary(r);
                run.update({{"cells_per_wavelength", cells},
                            {"dt_factor", factor},
                            {"dt", r.first_dt},
                            {"volume_drift", max_relative_drift(r.enclosed_volume)},
                            {"series", series_json(r)}});
                run.update(oscillation_fit_json(fit, omega));
                run["series"]["amplitude"] = a;
                // The flow's own velocity scale is a₀ω₀; a max|u| far above it is a spurious flow.
                const double peak_speed = series_peak(r.max_speed);
                run["peak_speed_over_a0_omega0"] = peak_speed / (amplitude0 * omega);
                run["final_speed_over_a0_omega0"] = r.max_speed.back() / (amplitude0 * omega);
                log(what + ": ω " + fmt(fit.omega) + " (ω₀ " + fmt(omega) + "), " +
                    fmt(r.wall_seconds, "%.0f") + " s");
                run["implicit_tension"] = variant.implicit;
                (variant.comparison ? implicit_runs : runs).push_back(run);
            }
        }
        out.results["B4"] = {{"runs", runs},
                             {"implicit_runs", implicit_runs},
                             {"omega0", omega},
                             {"omega_deep", omega_deep},
                             {"initial_amplitude", amplitude0},
                             {"t_end", end},
                             {"frequency", study_json(study)}};
        md << "## B4 — capillary wave\n\n"
           << "σ = 1, ρ₁ = ρ₂ = 1, inviscid (viscosity off), λ = 1, amplitude 0.01λ, no gravity; "
              "domain x ∈ [0, λ] between free-slip walls (a cos(2πx/λ) mode is symmetric about "
              "both), " << WAVE_THICKNESS_CELLS
           << " cells thick in y, mean interface at depth λ/2 in a box of height λ. The liquid "
              "slab is the wavy half-space cut by a box reaching 6 cells beyond the side and "
              "bottom walls (a vertex outside the domain takes the flow mirrored across the free-slip "
              "wall, /coupling/outside_velocity mirror). "
              "Amplitude a(t): least-squares cos(kx) mode of the top surface's vertices in the "
              "domain, fitted over "
           << fmt(end / period, "%.2g")
           << " periods to a₀ + e^{−γt}(A cos ωt + B sin ωt). Reference: ω₀² = σk³/(ρ₁ "
              "coth(kh₁) + ρ₂ coth(kh₂)) with both layers λ/2 deep, ω₀ = "
           << fmt(omega, "%.5g") << " 1/s (" << percent(omega, omega_deep)
           << " from the deep-water σk³/(ρ₁+ρ₂)).\n\n"
           << study_markdown(study, "cells per λ", 0.02, 32) << "\n"
           << "| cells per λ | Δt | steps | fitted γ (1/s) | fit rms / amplitude | peak max|u| / "
              "(a₀ω₀) | volume drift | max intersecting pairs |\n|---|---|---|---|---|---|---|---|\n";
        for (const Json& r : runs)
            md << "| " << r["cells_per_wavelength"] << " | "
               << dt_factor_text(r["dt_factor"].get<double>()) << " | " << r["steps"] << " | "
               << fmt(r["decay_rate"].get<double>(), "%.3g") << " | "
               << fmt(r["rms_residual"].get<double>() / r["amplitude"].get<double>(), "%.3f")
               << " | " << fmt(r["peak_speed_over_a0_omega0"].get<double>(), "%.3g") << " | "
               << fmt(100.0 * r["volume_drift"].get<double>(), "%.3f %%") << " | "
               << r["max_intersecting_pairs"] << " |\n";
        md << "\nA peak max|u| far above a₀ω₀ (the linear wave's velocity scale) is a spurious "
              "flow. Two causes once slowed this wave at 32 cells per wavelength: the sub-grid "
              "tension's first-order high-pass I − S (−4.7 % over the first 1.65 periods, −1.1 % "
              "without the sub-grid tension; now (I − S)²) and the slab beyond the side walls "
              "moving with the clamped velocity instead of the mirrored one (it kinked at the "
              "walls: over 3 periods −4.1 % with the amplitude peaking at 1.32× the start; now "
              "−0.16 %, peaks 0.99–1.06×). Reference (Basilisk, viscous La = 3000 against Prosperetti): RMS "
              "error 0.139, 0.0243, 0.0069, 0.0024 at 8, 16, 32, 64 points per wavelength. Plot: "
              "b4_wave.png.\n\n";
        md << implicit_markdown(implicit_runs, "cells_per_wavelength",
                                {{"ω (1/s)", "omega", "%.5g"}, {"γ (1/s)", "decay_rate", "%.3g"}});
    }

    /// A column of implicit_markdown(): heading, results.json key, printf format.
    struct Column {
        const char* heading;
        const char* key;
        const char* format;
    };
    /// The comparison pair of a case (variants_of()): the explicit run at the solver's own Δt
    /// first, then the semi-implicit one, each quantity with its difference from the explicit.
    static std::string implicit_markdown(const Json& comparison, const char* resolution_key,
                                         const std::vector<Column>& columns) {
        std::ostringstream md;
        if (comparison.empty())
            return "";
        const Json& explicit_run = comparison[0];
        md << "Semi-implicit surface tension (`/coupling/implicit_tension` 1, Hysing 2006, in "
              "its normal form) at "
           << fmt(IMPLICIT_DT_FACTOR, "%.3g")
           << "× the capillary limit, beside the explicit run at the solver's own Δt, both with "
              "trilinear vertex velocities (`/coupling/velocity_interpolation` trilinear, which "
              "the implicit tension needs; target: the same frequencies within 2 %):\n\n"
              "| resolution | tension | Δt (s) | steps |";
        for (const Column& c : columns)
            md << " " << c.heading << " | vs explicit |";
        md << " wall (s) |\n|---|---|---|---|";
        for (size_t i = 0; i < columns.size(); ++i)
            md << "---|---|";
        md << "---|\n";
        const auto row = [&](const Json& r, const char* what) {
            md << "| " << r[resolution_key] << " | " << what << " "
               << dt_factor_text(r["dt_factor"].get<double>()) << " | "
               << fmt(r["dt"].get<double>(), "%.3g") << " | " << r["steps"] << " |";
            for (const Column& c : columns) {
                const double value = r[c.key].get<double>();
                md << " " << fmt(value, c.format) << " | "
                   << (&r == &explicit_run ? std::string("—")
                                           : percent(value, explicit_run[c.key].get<double>()))
                   << " |";
            }
            md << " " << fmt(r["wall_seconds"].get<double>(), "%.0f") << " |\n";
        };
        for (const Json& r : comparison)
            row(r, r["implicit_tension"].get<bool>() ? "implicit" : "explicit");
        md << "\n";
        return md.str();
    }

};

}  // namespace

FluidValidation run_fluid_validation(const FluidValidationOptions& options) {
    FluidValidation out;
    Runner runner{{options, out}};
    const auto wanted = [&](const char* id) {
        return options.cases.empty() ||
               std::find(options.cases.begin(), options.cases.end(), id) != options.cases.end();
    };
    std::ostringstream md;
    md << "# Part B — two-phase flow with surface tension (docs/validation.md B1–B7)\n\n"
       << (options.full ? "Full variants." : "Quick variants: coarse and short (test suite); "
                                             "`meniscus validate --full` runs the resolutions "
                                             "docs/validation.md asks for.")
       << " Every run has the exact self-intersection test after every step.\n\n";
    if (wanted("B1"))
        runner.b1(md);
    if (wanted("B2"))
        runner.b2(md);
    if (wanted("B3"))
        runner.b3(md);
    if (wanted("B4"))
        runner.b4(md);
    if (wanted("B5"))
        merge_scenes_case(runner, md);
    if (wanted("B6"))
        viscous_drop_case(runner, md);
    if (wanted("B7"))
        creeping_bubble_case(runner, md);
    out.report = md.str();
    return out;
}

}  // namespace meniscus::app
