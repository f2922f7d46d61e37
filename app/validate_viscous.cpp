/// Part B of `meniscus validate`, the viscosity-dominated cases (docs/validation.md):
/// B6 — the damped l = 2 oscillation of a free viscous drop against the exact normal mode;
/// B7 — the creeping rise of a bubble in a very viscous liquid in a free-slip box against
/// Hadamard–Rybczynski with the walls' exact image correction. Each at several resolutions at the
/// solver's own Δt, the coarsest also at Δt/2 (and Δt/4 in full mode), as B1–B4.

#include "app/scene_setup.h"
#include "app/validate_viscous.h"

#include "app/fluid_references.h"
#include "app/run.h"

#include <cmath>
#include <map>
#include <string>
#include <utility>

namespace meniscus::app::validate_fluid {

namespace {

using Eigen::Vector3d;

// ---- B6 ----
constexpr double B6_RADIUS = 0.002;  ///< m
constexpr double B6_SIGMA = 0.0728;  ///< N/m
constexpr double B6_RHO = 1000.0;    ///< kg/m³
/// ω₀R²/ν: the drop's inviscid frequency over its viscous rate. 20 gives a damping of about a
/// fifth of the frequency (the amplitude falls to 0.28 per period), where the exact mode is
/// 4.2 % slower and 22 % less damped than Lamb's ω₀ and 5ν/R².
constexpr double B6_OMEGA0_TILDE = 20.0;
constexpr double B6_EPSILON = 0.05;    ///< initial P₂ amplitude
constexpr double B6_PERIODS = 1.5;     ///< run length
constexpr double B6_TARGET = 0.05;     ///< frequency and damping, from 16 cells per diameter

// ---- B7 ----
constexpr double B7_RADIUS = 0.001;     ///< m
constexpr double B7_RHO_LIQUID = 1000.0;
constexpr double B7_RHO_GAS = 1.0;      ///< density ratio 1000
constexpr double B7_MU_LIQUID = 2.0;    ///< Pa·s
constexpr double B7_MU_GAS = 2.0e-3;    ///< κ = 1e-3; the gas's ν equals the liquid's
constexpr double B7_SIGMA = 0.01;       ///< N/m (Bond number ρga²/σ ≈ 1)
constexpr double B7_GRAVITY = 9.81;
constexpr double B7_BOX_RADII = 10.0;   ///< box edge in radii (full mode)
/// Box edge in radii in quick mode: the walls' correction is larger (U/U∞ ≈ 0.6) but the run is
/// ~10× cheaper (a (6/10)³ grid run for (6/10)² of the time).
constexpr double B7_QUICK_BOX_RADII = 6.0;
/// Run length in units of the box's viscous time L²/ν: its slowest Stokes mode decays as
/// e^{−2π²νt/L²}, to 0.3 % by then.
constexpr double B7_END_VISCOUS_TIMES = 0.3;
/// The rise speed is averaged over the last quarter of the run.
constexpr double B7_AVERAGE_FRACTION = 0.25;
constexpr double B7_TARGET = 0.05;

/// Runs a scene with `dt_factor` on the capillary limit, calling `sample` after every step.
FluidRunRecord run_case(Json j, double dt_factor, double end,
                        const std::function<void(const coupling::Simulation&)>& sample) {
    j["coupling"]["capillary_safety"] = dt_factor;
    Scene scene = scene_from(j);
    scene.tracker.verify_intersection_free = true;
    coupling::Simulation sim = make_fluid_simulation(scene);
    return run_sampled(sim, end, sample);
}

}  // namespace

void viscous_drop_case(CaseContext& context, std::ostringstream& md) {
    const FluidValidationOptions& options = context.options;
    const std::vector<int> resolutions =
        options.full ? std::vector<int>{12, 16, 25} : std::vector<int>{12};
    const std::vector<double> factors =
        options.full ? std::vector<double>{1.0, 0.5, 0.25} : std::vector<double>{1.0, 0.5};
    const double omega0 = lamb_omega(2, B6_SIGMA, B6_RADIUS, B6_RHO, 0.0);
    const double nu = omega0 * B6_RADIUS * B6_RADIUS / B6_OMEGA0_TILDE;
    const DropMode mode = viscous_drop_mode(2, B6_SIGMA, B6_RADIUS, B6_RHO, nu);
    const double lamb_decay = 5.0 * nu / (B6_RADIUS * B6_RADIUS);
    const double period = 2.0 * M_PI / mode.omega;
    const double end = B6_PERIODS * period;
    Study frequency{"frequency ω", "1/s", {}}, damping{"damping rate γ", "1/s", {}};
    Json runs = Json::array();
    for (int cpd : resolutions) {
        const double box = 4.0 * B6_RADIUS;
        const int cells = 2 * cpd;
        const double dx = box / cells;
        Json j = base_scene("B6 viscous drop");
        j["fluid"]["mode"] = "free_surface";
        j["fluid"]["phases"] = {{"rho_liquid", B6_RHO}, {"mu_liquid", nu * B6_RHO},
                                {"sigma", B6_SIGMA}};
        j["domain"] = {{"min", {0, 0, 0}}, {"size", {box, box, box}}, {"cells", cells}};
        j["coupling"]["curvature_smoothing"] = 1;  // as B2
        const double a = B6_RADIUS * (1.0 + B6_EPSILON), b = B6_RADIUS * (1.0 - 0.5 * B6_EPSILON);
        j["surface"] = {{"shape",
                         {{"type", "ellipsoid"},
                          {"center", {box / 2, box / 2, box / 2}},
                          {"radii", {a, b, b}}}}};
        for (double factor : factors) {
            if (factor != 1.0 && cpd != resolutions.front())
                continue;  // the smaller Δt at the coarsest resolution only
            std::vector<double> deformation;
            const auto sample = [&](const coupling::Simulation& s) {
                const VolumeMoments m = volume_moments(s.tracker().mesh());
                deformation.push_back(m.semi_axes.x() - 0.5 * (m.semi_axes.y() + m.semi_axes.z()));
            };
            const FluidRunRecord r = run_case(j, factor, end, sample);
            const std::string what =
                "B6 " + std::to_string(cpd) + " cells per diameter, Δt factor " + fmt(factor);
            context.check(what, r);
            const OscillationFit fit =
                fit_damped_oscillation(r.t, deformation, 0.5 * mode.omega, 1.5 * mode.omega);
            frequency.add(cpd, dx, {factor, r.first_dt, fit.omega, mode.omega, r.steps,
                                    r.wall_seconds});
            damping.add(cpd, dx, {factor, r.first_dt, fit.decay_rate, mode.decay_rate, r.steps,
                                  r.wall_seconds});
            Json run = run_summary(r);
            run.update({{"cells_per_diameter", cpd},
                        {"dt_factor", factor},
                        {"dt", r.first_dt},
                        {"volume_drift", max_relative_drift(r.enclosed_volume)},
                        {"series", series_json(r)}});
            run.update(oscillation_fit_json(fit, mode.omega));
            run["series"]["deformation"] = deformation;
            runs.push_back(run);
            context.log(what + ": ω " + fmt(fit.omega) + " (exact " + fmt(mode.omega) + "), γ " +
                        fmt(fit.decay_rate) + " (exact " + fmt(mode.decay_rate) + "), " +
                        fmt(r.wall_seconds, "%.0f") + " s");
        }
    }
    context.out.results["B6"] = {{"runs", runs},
                                 {"omega_exact", mode.omega},
                                 {"decay_rate_exact", mode.decay_rate},
                                 {"omega_inviscid", omega0},
                                 {"decay_rate_lamb", lamb_decay},
                                 {"nu", nu},
                                 {"omega0_tilde", B6_OMEGA0_TILDE},
                                 {"t_end", end},
                                 {"frequency", study_json(frequency)},
                                 {"damping", study_json(damping)}};
    md << "## B6 — viscous drop oscillation (exact normal mode)\n\n"
       << "A free drop (free_surface mode: void outside), R = 2 mm, ρ = 1000 kg/m³, σ = 0.0728 "
          "N/m, ν = "
       << fmt(nu, "%.4g") << " m²/s (ω₀R²/ν = " << fmt(B6_OMEGA0_TILDE, "%.3g")
       << ", Ohnesorge number μ/sqrt(ρσR) = " << fmt(nu * std::sqrt(B6_RHO / (B6_SIGMA * B6_RADIUS)), "%.3g")
       << "), no gravity, initial ellipsoid R(1+ε), R(1−ε/2), R(1−ε/2), ε = 0.05, box 4R. The "
          "deformation a_x − (a_y + a_z)/2 from the mesh's volume moments, fitted over "
       << fmt(B6_PERIODS, "%.2g")
       << " periods to d₀ + e^{−γt}(A cos ωt + B sin ωt). Reference: the least damped l = 2 "
          "root of the exact characteristic equation of a free viscous drop (Reid 1960, "
          "Chandrasekhar 1961 §98; derived in docs/validation.md): ω = "
       << fmt(mode.omega, "%.5g") << " 1/s, γ = " << fmt(mode.decay_rate, "%.5g")
       << " 1/s. For comparison Lamb's inviscid ω₀ = " << fmt(omega0, "%.5g")
       << " 1/s and weak-damping γ = 5ν/R² = " << fmt(lamb_decay, "%.5g")
       << " 1/s differ from it by " << percent(omega0, mode.omega) << " and "
       << percent(lamb_decay, mode.decay_rate) << ".\n\n"
       << study_markdown(frequency, "cells per D", B6_TARGET, 16) << "\n"
       << study_markdown(damping, "cells per D", B6_TARGET, 16) << "\n"
       << "Plot: b6_viscous_drop.png.\n\n";
}

void creeping_bubble_case(CaseContext& context, std::ostringstream& md) {
    const FluidValidationOptions& options = context.options;
    const std::vector<int> resolutions =  // cells per radius
        options.full ? std::vector<int>{4, 6, 8} : std::vector<int>{4};
    const std::vector<double> factors =
        options.full ? std::vector<double>{1.0, 0.5, 0.25} : std::vector<double>{1.0, 0.5};
    const double box_radii = options.full ? B7_BOX_RADII : B7_QUICK_BOX_RADII;
    const double a = B7_RADIUS, box = box_radii * a;
    const double nu = B7_MU_LIQUID / B7_RHO_LIQUID;
    const double end = B7_END_VISCOUS_TIMES * box * box / nu;
    // The pointwise weights (the default) at every resolution, the coarsest also at the smaller
    // Δt; for comparison the sharp ones at every resolution and the volume-fraction ones (3× the
    // wall time) at the coarsest, each at the solver's own Δt.
    const std::vector<std::string> weightings = {"pointwise", "sharp", "volume_fraction"};
    std::map<std::string, Study> speed;
    for (const std::string& w : weightings)
        speed.emplace(w, Study{"rise speed U", "m/s", {}});
    Json runs = Json::array();
    CreepingRiseSetup setup;
    setup.radius = a;
    setup.rho_liquid = B7_RHO_LIQUID;
    setup.rho_inside = B7_RHO_GAS;
    setup.mu_liquid = B7_MU_LIQUID;
    setup.mu_inside = B7_MU_GAS;
    setup.gravity = B7_GRAVITY;
    setup.box_size = Vector3d::Constant(box);
    for (int cpr : resolutions) {
        const int cells = static_cast<int>(std::lround(box_radii * cpr));
        const double dx = box / cells;
        Json j = base_scene("B7 creeping bubble");
        j["fluid"]["gravity"] = {0, 0, -B7_GRAVITY};
        j["fluid"]["phases"] = {{"rho_liquid", B7_RHO_LIQUID}, {"rho_gas", B7_RHO_GAS},
                                {"mu_liquid", B7_MU_LIQUID},   {"mu_gas", B7_MU_GAS},
                                {"sigma", B7_SIGMA}};
        j["domain"] = {{"min", {0, 0, 0}}, {"size", {box, box, box}}, {"cells", cells}};
        j["surface"] = {{"inside", "gas"},
                        {"shape",
                         {{"type", "sphere"},
                          {"center", {box / 2, box / 2, box / 2}},
                          {"radius", a}}}};
        std::vector<std::pair<std::string, double>> variants;  // (weights, Δt factor)
        for (double factor : factors) {
            variants.emplace_back(weightings.front(), factor);
            if (cpr != resolutions.front())
                break;
        }
        variants.emplace_back("sharp", 1.0);
        if (cpr == resolutions.front())
            variants.emplace_back("volume_fraction", 1.0);
        for (const auto& variant : variants) {
            const std::string& weights = variant.first;
            const double factor = variant.second;
            j["fluid"]["viscosity_weights"] = weights;
            std::vector<double> t, u, z;
            const auto sample = [&](const coupling::Simulation& s) {
                if (s.time() == 0.0)
                    return;  // no velocities before the first step
                t.push_back(s.time());
                u.push_back(centroid_velocity(s.tracker().mesh(), s.vertex_velocities()).z());
                z.push_back(volume_moments(s.tracker().mesh()).centroid.z());
            };
            const FluidRunRecord r = run_case(j, factor, end, sample);
            const std::string what = "B7 " + std::to_string(2 * cpr) +
                                     " cells per diameter, " + weights + " weights, Δt factor " +
                                     fmt(factor);
            context.check(what, r);
            // Time averages over the last quarter, and over the quarter before (steadiness).
            double late = 0.0, earlier = 0.0, late_z = 0.0;
            int n_late = 0, n_earlier = 0;
            for (size_t i = 0; i < t.size(); ++i) {
                if (t[i] >= (1.0 - B7_AVERAGE_FRACTION) * end) {
                    late += u[i];
                    late_z += z[i];
                    ++n_late;
                } else if (t[i] >= (1.0 - 2.0 * B7_AVERAGE_FRACTION) * end) {
                    earlier += u[i];
                    ++n_earlier;
                }
            }
            late /= std::max(n_late, 1);
            earlier /= std::max(n_earlier, 1);
            setup.centre = Vector3d(box / 2, box / 2, late_z / std::max(n_late, 1));
            const CreepingRise reference = creeping_rise(setup);
            speed.at(weights).add(2 * cpr, dx, {factor, r.first_dt, late, reference.speed,
                                                r.steps, r.wall_seconds});
            Json run = run_summary(r);
            run.update({{"cells_per_diameter", 2 * cpr},
                        {"weights", weights},
                        {"dt_factor", factor},
                        {"dt", r.first_dt},
                        {"diffusion_number", nu * r.first_dt / (dx * dx)},
                        {"rise_speed", late},
                        {"rise_speed_previous_quarter", earlier},
                        {"reference_speed", reference.speed},
                        {"unbounded_speed", reference.unbounded},
                        {"wall_correction", reference.wall_correction},
                        {"volume_drift", max_relative_drift(r.enclosed_volume)},
                        {"series", series_json(r)}});
            run["series"]["speed_t"] = t;
            run["series"]["speed"] = u;
            runs.push_back(run);
            context.log(what + ": U " + fmt(late) + " m/s (reference " + fmt(reference.speed) +
                        ", " + percent(late, reference.speed) + "), " +
                        fmt(r.wall_seconds, "%.0f") + " s");
        }
    }
    setup.centre = Vector3d::Constant(box / 2);
    const CreepingRise centre = creeping_rise(setup);
    context.out.results["B7"] = {{"runs", runs},
                                 {"unbounded_speed", centre.unbounded},
                                 {"reference_speed_at_centre", centre.speed},
                                 {"wall_coefficient", centre.wall_coefficient},
                                 {"t_end", end},
                                 {"box_radii", box_radii},
                                 {"speed", study_json(speed.at("pointwise"))},
                                 {"speed_sharp", study_json(speed.at("sharp"))},
                                 {"speed_volume_fraction", study_json(speed.at("volume_fraction"))}};
    const double reynolds = 2.0 * a * centre.speed * B7_RHO_LIQUID / B7_MU_LIQUID;
    md << "## B7 — creeping bubble rise\n\n"
       << "A gas bubble a = 1 mm (ρ 1 kg/m³, μ 2e-3 Pa·s) rising under gravity through a very "
          "viscous liquid (ρ 1000 kg/m³, μ 2 Pa·s; density ratio 1000, viscosity ratio κ = "
          "1e-3), σ = 0.01 N/m, in a closed box of "
       << fmt(box_radii, "%.3g")
       << " radii (" << fmt(B7_BOX_RADII, "%.3g") << " in full mode) with free-slip walls, from rest at its centre. Reynolds number 2aUρ/μ = "
       << fmt(reynolds, "%.2g") << ", Bond number ρga²/σ = "
       << fmt(B7_RHO_LIQUID * B7_GRAVITY * a * a / B7_SIGMA, "%.2g")
       << " (in the creeping limit the sphere is an exact solution at any Bond number). Run "
       << fmt(1e3 * end, "%.3g") << " ms = " << fmt(B7_END_VISCOUS_TIMES, "%.2g")
       << " L²/ν; the rise speed is the mean over the last quarter of the instantaneous "
          "velocity of the enclosed volume's centroid, (1/V)∮(z − z_c)(u·n)dA with the "
          "interpolated vertex velocities. Reference: Hadamard–Rybczynski U∞ = "
          "(2/3)(Δρga²/μ)(1+κ)/(2+3κ) = "
       << fmt(centre.unbounded, "%.5g")
       << " m/s plus the walls' correction: the z-velocity at the bubble's centre of the Stokes "
          "flow of the images of its point force Δρg(4/3)πa³ across the free-slip walls (mirror "
          "planes, so the images form a periodic array: an Ewald-free Fourier sum with "
          "Gaussian-smoothed forces, the smoothed self-flow removed, extrapolated to zero width; "
          "derived in docs/validation.md), "
       << fmt(centre.wall_correction, "%.4g") << " m/s at the box centre (" 
       << percent(centre.speed, centre.unbounded)
       << "), evaluated at the run's mean height. Neglected: the walls' reflection of the "
          "bubble's dipole (O(κ(a/ℓ)³)) and stresslet (O((a/ℓ)⁴)), and inertia (O(Re)).\n\n"
       << "With the default `/fluid/viscosity_weights` `pointwise` (each cell centre's and "
          "each edge midpoint's μ by the phase there, φ at an edge the mean of its cells):\n\n"
       << study_markdown(speed.at("pointwise"), "cells per D", B7_TARGET, 16) << "\n"
       << "With `sharp` (each cell's μ by its phase, the edges' harmonic mean), at the solver's "
          "own Δt:\n\n"
       << study_markdown(speed.at("sharp"), "cells per D", B7_TARGET, 16) << "\n"
       << "With `volume_fraction` (μ blended by the liquid fraction of each control volume, "
          "Batty & Bridson 2008), at the solver's own Δt:\n\n"
       << study_markdown(speed.at("volume_fraction"), "cells per D", B7_TARGET, 16) << "\n"
       << "The harmonic mean of `sharp` gives every edge next to a gas cell the gas's μ, so the "
          "gas's low viscosity reaches half a cell into the liquid all round and the bubble "
          "rises too fast; the blended weights give the liquid's viscosity to part of the gas, "
          "so it rises too slowly. The pointwise weights put the jump where φ changes sign, to "
          "within half a cell either way, without a bias to either phase.\n\n"
       << "Plot: b7_creeping_bubble.png.\n\n";
}

}  // namespace meniscus::app::validate_fluid
