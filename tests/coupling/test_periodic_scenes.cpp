// Liquid columns in a box periodic along them (issue 39): the surface mesh wraps around the box
// with the fluid, so a column is a closed tube with no ends. A column shorter than its
// circumference is stable (every mode has kR > 1) and must stay at rest; one a Rayleigh–Plateau
// wavelength long must grow at the inviscid rate. Scenes are built from scenes/jet_pinch.json.

#include "app/fluid_measures.h"
#include "app/fluid_references.h"
#include "app/scene.h"
#include "app/scene_setup.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace meniscus::app {
namespace {

using Json = nlohmann::json;

Json jet_pinch_json() {
    std::ifstream f(std::string(MENISCUS_SOURCE_DIR) + "/scenes/jet_pinch.json");
    return Json::parse(f);
}

Scene scene_from(const Json& j) {
    return parse_scene(j.dump(), "jet_pinch (periodic test variant)",
                       std::string(MENISCUS_SOURCE_DIR) + "/scenes");
}

/// jet_pinch's water column (R = 0.6 mm in air), `cells` cells along a periodic box `length`
/// long (the cross-section as the scene's), radius perturbed by `amplitude` at wavelength
/// `length` (a crest at x = 0).
Json periodic_column(double length, int cells, double amplitude) {
    Json j = jet_pinch_json();
    EXPECT_EQ(j["fluid"]["boundaries"]["x_min"], "periodic");
    const std::vector<double> size = j["domain"]["size"];
    j["domain"]["size"] = {length, size[1], size[2]};
    j["domain"]["cells"] = cells;
    Json& column = j["surface"]["shape"];
    column["center"] = {length, size[1] / 2, size[2] / 2};
    column["height"] = 3.0 * length;
    column["amplitude"] = amplitude;
    column["wavelength"] = length;
    return j;
}

double max_relative_drift(const std::vector<double>& v) {
    double drift = 0.0;
    for (double x : v)
        drift = std::max(drift, std::abs(x / v.front() - 1.0));
    return drift;
}

TEST(PeriodicScenes, ColumnShorterThanItsCircumferenceStaysAtRest) {
    // L = 3 mm < 2πR = 3.77 mm: no unstable mode fits. 20 cells along (R = 4 cells), 4 ms
    // (about 2.5 capillary times sqrt(ρR³/σ)).
    const Json j = periodic_column(0.003, 20, 0.0);
    const Scene scene = scene_from(j);
    coupling::Simulation sim = make_fluid_simulation(scene);
    ASSERT_TRUE(sim.tracker().mesh().periodic());
    const double radius = j["surface"]["shape"]["radius"];
    const std::vector<double> size = j["domain"]["size"];
    std::vector<double> mean_radius, centre_y, centre_z;
    const auto sample = [&](const coupling::Simulation& s) {
        const tracker::SurfaceMesh& mesh = s.tracker().mesh();
        const ModeFit f = column_radius_mode(mesh, Eigen::Vector2d(size[1] / 2, size[2] / 2), 0.0,
                                             0.003, 0.0, 0.003);
        mean_radius.push_back(f.mean);
        double y = 0.0, z = 0.0;
        int n = 0;
        for (int v = 0; v < mesh.num_vertices(); ++v)
            if (mesh.vertex_alive(v)) {
                y += mesh.position(v).y();
                z += mesh.position(v).z();
                ++n;
            }
        centre_y.push_back(y / n);
        centre_z.push_back(z / n);
    };
    const double end = 0.004;
    const FluidRunRecord r = run_sampled(sim, end, sample);
    ASSERT_TRUE(r.completed);
    double max_speed = 0.0, drift = 0.0, radius_change = 0.0;
    for (size_t i = 0; i < r.t.size(); ++i) {
        max_speed = std::max(max_speed, r.max_speed[i]);
        drift = std::max(
            drift, std::hypot(centre_y[i] - centre_y.front(), centre_z[i] - centre_z.front()));
        radius_change = std::max(radius_change, std::abs(mean_radius[i] / mean_radius.front() - 1));
    }
    // The capillary velocity scale sqrt(σ/(ρR)).
    const double u_sigma =
        std::sqrt(scene.fluid.phases.sigma / (scene.fluid.phases.rho_liquid * radius));
    std::printf(
        "[ measured ] periodic column at rest, %lld steps: max |u| %.3g m/s (%.2g of "
        "sqrt(sigma/(rho R))), axis drift %.3g R, mean radius change %.3g %%, volume "
        "drift %.3g %%, components %d, intersecting pairs %d\n",
        r.steps, max_speed, max_speed / u_sigma, drift / radius, 100.0 * radius_change,
        100.0 * max_relative_drift(r.enclosed_volume), r.components.back(),
        r.max_intersecting_pairs);
    EXPECT_EQ(r.components.back(), 1);
    EXPECT_EQ(r.max_intersecting_pairs, 0);
    EXPECT_LT(max_speed, 0.05 * u_sigma);  // spurious currents only
    EXPECT_LT(drift, 0.01 * radius);
    EXPECT_LT(radius_change, 0.01);
    EXPECT_LT(max_relative_drift(r.enclosed_volume), 0.005);
}

TEST(PeriodicScenes, RayleighPlateauGrowsAtTheInviscidRate) {
    // One fastest-growing wavelength λ = 2πR/0.697 in a periodic box, 27 cells (R = 3 cells,
    // as validate's quick B3), 1 % cosine perturbation; the growth fitted while a < 0.1 R.
    const Json base = jet_pinch_json();
    const double wavelength = base["surface"]["shape"]["wavelength"];
    const Json j = periodic_column(wavelength, 27, 0.01);
    Scene scene = scene_from(j);
    scene.tracker.verify_intersection_free = true;
    coupling::Simulation sim = make_fluid_simulation(scene);
    const double radius = j["surface"]["shape"]["radius"];
    const std::vector<double> size = j["domain"]["size"];
    const double rate = rayleigh_plateau_rate(
        scene.fluid.phases.sigma, scene.fluid.phases.rho_liquid, radius, 2.0 * M_PI / wavelength);
    std::vector<double> amplitude;
    const FluidRunRecord r = run_sampled(sim, 0.008, [&](const coupling::Simulation& s) {
        amplitude.push_back(column_radius_mode(s.tracker().mesh(),
                                               Eigen::Vector2d(size[1] / 2, size[2] / 2), 0.0,
                                               wavelength, 0.0, wavelength)
                                .cos_amplitude);
    });
    ASSERT_TRUE(r.completed);
    std::vector<double> t, a;
    for (size_t i = 0; i < r.t.size() && amplitude[i] < 0.1 * radius && r.components[i] == 1; ++i) {
        t.push_back(r.t[i]);
        a.push_back(amplitude[i]);
    }
    ASSERT_GE(t.size(), 4u);
    const GrowthFit fit = fit_growth_from_rest(t, a, 0.2 * rate, 3.0 * rate);
    std::printf(
        "[ measured ] periodic Rayleigh-Plateau, 27 cells per wavelength (R = 3 cells), "
        "%lld steps: growth %.4g 1/s against %.4g (%+.2f %%), amplitude %.3g -> %.3g R, "
        "volume drift %.3g %%\n",
        r.steps, fit.rate, rate, 100.0 * (fit.rate / rate - 1.0), a.front() / radius,
        a.back() / radius, 100.0 * max_relative_drift(r.enclosed_volume));
    EXPECT_NEAR(fit.rate / rate, 1.0, 0.05);
    EXPECT_EQ(r.max_intersecting_pairs, 0);
    EXPECT_LT(max_relative_drift(r.enclosed_volume), 0.005);
}

}  // namespace
}  // namespace meniscus::app
