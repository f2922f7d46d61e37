// Physics of the shipped fluid scenes at coarse resolution (docs/validation.md part B, quick):
// the oscillating drop's l = 2 frequency against Lamb's, the jet's Rayleigh–Plateau pinch-off,
// and the volume of each phase, the component counts and intersection-freedom of the merge
// scenes. Each test loads the shipped scene file and coarsens or shortens it (said where).
// The merge and pinch runs also check that every surface written (or, for the jet, every step's
// output surface) is closed, edge-manifold and consistently oriented.
// Longer and finer runs: `meniscus validate --full` (app/validate_fluid.cpp).

#include "app/frame_output.h"
#include "app/run.h"
#include "app/scene.h"
#include "app/fluid_measures.h"
#include "app/fluid_references.h"
#include "app/scene_setup.h"
#include "tests/one_worker_thread.h"
#include "tracker/mesh_io.h"
#include "tracker/mesh_measures.h"
#include "tracker/topology/separate.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace meniscus::app {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// This program's scene runs (here and in test_periodic_scenes.cpp) on one worker thread.
::testing::Environment* const ONE_WORKER_THREAD =
    ::testing::AddGlobalTestEnvironment(new meniscus::testing::OneWorkerThread);

/// docs/validation.md B5: volume of each phase within 0.5 % over a run with volume correction on.
constexpr double PHASE_VOLUME_TOLERANCE = 0.005;

std::string scene_path(const std::string& name) {
    return std::string(MENISCUS_SOURCE_DIR) + "/scenes/" + name + ".json";
}

Json scene_json(const std::string& name) {
    std::ifstream f(scene_path(name));
    return Json::parse(f);
}

Scene scene_from(const Json& j, const std::string& name) {
    return parse_scene(j.dump(), name + " (test variant)", std::string(MENISCUS_SOURCE_DIR) + "/scenes");
}

double max_relative_drift(const std::vector<double>& v) {
    double drift = 0.0;
    for (double x : v)
        drift = std::max(drift, std::abs(x / v.front() - 1.0));
    return drift;
}

/// Directed edges of live triangles not paired exactly once with their reverse: 0 for a closed,
/// edge-manifold, consistently oriented surface (each edge in exactly two triangles, one in each
/// direction). Checked on the triangle list alone.
int unpaired_directed_edges(const std::vector<tracker::Triangle>& triangles) {
    std::map<std::pair<int, int>, int> directed;
    for (const tracker::Triangle& t : triangles)
        for (int k = 0; k < 3; ++k)
            ++directed[{t[k], t[(k + 1) % 3]}];
    int unpaired = 0;
    for (const auto& [edge, count] : directed) {
        const auto reverse = directed.find({edge.second, edge.first});
        unpaired += count != 1 || reverse == directed.end() || reverse->second != 1 ? 1 : 0;
    }
    return unpaired;
}

std::vector<tracker::Triangle> live_triangles(const tracker::SurfaceMesh& mesh) {
    std::vector<tracker::Triangle> triangles;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        if (mesh.triangle_alive(ti))
            triangles.push_back(mesh.triangle(ti));
    return triangles;
}

/// A scene run through `meniscus run`'s loop (with /initial_velocity) and the exact
/// self-intersection test after every step; its stats.jsonl lines. Every frame's PLY must be a
/// closed edge-manifold surface enclosing the volume stats.jsonl records.
std::vector<Json> run_frames(Scene scene, const std::string& tag, int frames) {
    scene.tracker.verify_intersection_free = true;
    scene.output.ply = true;
    scene.output.ply_velocity = false;
    scene.output.vdb = false;
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() /
                       ("meniscus_physics_" + tag + "_" + std::to_string(::getpid())))
                          .string();
    options.frames = frames;
    options.quiet = true;
    const std::atomic<bool> stop{false};
    const RunResult r = run_scene(scene, options, stop);
    EXPECT_EQ(r.frames_written, frames + 1);
    EXPECT_EQ(r.max_intersecting_pairs, 0) << "intersecting triangle pairs after some step";
    std::ifstream stats(fs::path(options.out_dir) / "stats.jsonl");
    std::vector<Json> lines;
    for (std::string line; std::getline(stats, line);)
        lines.push_back(Json::parse(line));
    const double cube = std::pow(1.0 / metres_per_unit(scene.output.length_unit), 3);
    for (const Json& l : lines) {
        const int frame = l["frame"];
        const tracker::SurfaceMesh mesh = tracker::to_surface_mesh(
            tracker::read_ply(frame_path(options.out_dir, "surface", frame, "ply")), tag);
        EXPECT_EQ(unpaired_directed_edges(live_triangles(mesh)), 0) << tag << " frame " << frame;
        const double volume = l["volume"].get<double>() * cube;
        EXPECT_NEAR(tracker::enclosed_volume(mesh), volume, 1e-9 * volume)
            << tag << " frame " << frame;
    }
    fs::remove_all(options.out_dir);
    return lines;
}

/// Checks the volume of the enclosed phase and of the other (box minus it) on every frame.
void expect_phase_volumes_kept(const std::vector<Json>& lines, double box_volume) {
    std::vector<double> inside, other;
    for (const Json& l : lines) {
        inside.push_back(l["volume"].get<double>());
        other.push_back(box_volume - l["volume"].get<double>());
        EXPECT_LE(l.value("intersecting_pairs", -1), 0) << "frame " << l["frame"];
    }
    std::printf("[ measured ] largest volume drift over %zu frames: enclosed phase %.4f %%, other "
                "phase %.5f %%\n",
                lines.size(), 100.0 * max_relative_drift(inside), 100.0 * max_relative_drift(other));
    EXPECT_LT(max_relative_drift(inside), PHASE_VOLUME_TOLERANCE);
    EXPECT_LT(max_relative_drift(other), PHASE_VOLUME_TOLERANCE);
}

/// scenes/oscillating_drop.json (two-phase as shipped, or with the air as void) against Lamb.
void expect_lamb_frequency(bool free_surface) {
    // scenes/oscillating_drop.json as shipped (16 cells per diameter) for 1.3 Lamb periods.
    // The deformation d = a_x − (a_y + a_z)/2 comes from the exact volume moments of the mesh
    // after every step (a_d = sqrt(5⟨(x_d − c_d)²⟩), exact for an ellipsoid); ω is the
    // least-squares fit of d₀ + e^{−γt}(A cos ωt + B sin ωt) over the whole run (more than one
    // full period). Lamb's two-phase l = 2 frequency uses the volume-equivalent radius of the
    // initial mesh. Measured period errors (same fit): +8.3 %, +5.9 %, +4.5 %, +3.3 % at 10,
    // 12, 14, 16 cells per diameter — first order, hence not a coarser grid here.
    constexpr double PERIODS = 1.3;
    constexpr double FREQUENCY_TOLERANCE = 0.05;
    Scene scene = load_scene(scene_path("oscillating_drop"));
    scene.tracker.verify_intersection_free = true;
    if (free_surface)
        scene.fluid.mode = fluid::FluidMode::free_surface;
    coupling::Simulation sim = make_fluid_simulation(scene);
    const VolumeMoments m0 = volume_moments(sim.tracker().mesh());
    const double radius = std::cbrt(3.0 * m0.volume / (4.0 * M_PI));
    const fluid::PhaseOptions& phases = scene.fluid.phases;
    const double omega =
        lamb_omega(2, phases.sigma, radius, phases.rho_liquid, free_surface ? 0.0 : phases.rho_gas);
    std::vector<double> deformation;
    const FluidRunRecord r =
        run_sampled(sim, PERIODS * 2.0 * M_PI / omega, [&](const coupling::Simulation& s) {
            const VolumeMoments m = volume_moments(s.tracker().mesh());
            deformation.push_back(m.semi_axes.x() - 0.5 * (m.semi_axes.y() + m.semi_axes.z()));
        });
    ASSERT_TRUE(r.completed);
    EXPECT_TRUE(r.pressure_converged);
    EXPECT_EQ(r.max_intersecting_pairs, 0);
    const OscillationFit fit = fit_damped_oscillation(r.t, deformation, 0.5 * omega, 1.5 * omega);
    std::printf("[ measured ] oscillating drop (%s), %d cells per diameter, %lld steps: period "
                "%.3f ms, Lamb %.3f ms (%+.2f %%); amplitude %.4f mm (initial deformation %.4f mm), "
                "decay rate %.3g 1/s, fit rms %.2e mm\n",
                free_surface ? "free surface" : "two-phase", scene.domain.cells / 2, r.steps,
                2e3 * M_PI / fit.omega, 2e3 * M_PI / omega,
                100.0 * (fit.omega / omega - 1.0), 1e3 * fit.amplitude,
                1e3 * (deformation.front() - fit.offset), fit.decay_rate, 1e3 * fit.rms_residual);
    EXPECT_NEAR(fit.omega, omega, FREQUENCY_TOLERANCE * omega);
    // The fit describes the run: the residual is small against the oscillation, and the
    // fitted amplitude is the initial deformation (no spurious growth or loss within a period).
    EXPECT_LT(fit.rms_residual, 0.05 * fit.amplitude);
    EXPECT_NEAR(fit.amplitude, deformation.front() - fit.offset,
                0.2 * (deformation.front() - fit.offset));
    EXPECT_LT(max_relative_drift(r.enclosed_volume), PHASE_VOLUME_TOLERANCE);
}

TEST(ScenePhysics, OscillatingDropHasLambsFrequency) { expect_lamb_frequency(false); }

TEST(ScenePhysics, FreeSurfaceOscillatingDropHasLambsFrequencyInAVoid) {
    // Issue #7 item 6: the same drop with the air as void (free-surface mode, no gas solve);
    // Lamb's l = 2 frequency with no outer fluid, ω² = 8σ/(ρR³).
    expect_lamb_frequency(true);
}

TEST(ScenePhysics, JetPinchQuickPinchesIntoDrops) {
    // scenes/jet_pinch.json shortened: one wavelength in the periodic box instead of two, 27
    // cells per wavelength (R = 3 cells instead of 4) and a 15 % perturbation instead of 1 %, so
    // that it pinches after ~12 ms instead of ~27 ms. Rayleigh–Plateau: still the fastest-growing
    // wavelength (kR = 0.697), the pinch comes from capillary instability, not from the
    // perturbation (which only shortens the linear phase: ln(1/ε)/s ≈ 9.5 ms at s = 199 1/s).
    // The column is a closed tube across the periodic ends (issue 39); it used to run through
    // free-slip end walls, cut by a box outside the domain.
    constexpr int CELLS = 27;
    constexpr double AMPLITUDE = 0.15;
    constexpr double END = 0.015;  // s
    Json j = scene_json("jet_pinch");
    ASSERT_EQ(j["fluid"]["boundaries"]["x_min"], "periodic");
    Json& column = j["surface"]["shape"];
    ASSERT_EQ(column["type"], "perturbed_cylinder");
    const double wavelength = column["wavelength"], radius = column["radius"];
    const std::vector<double> size = j["domain"]["size"];
    j["domain"]["size"] = {wavelength, size[1], size[2]};
    j["domain"]["cells"] = CELLS;
    column["center"] = {wavelength, size[1] / 2, size[2] / 2};
    column["height"] = 3.0 * wavelength;
    column["amplitude"] = AMPLITUDE;
    Scene scene = scene_from(j, "jet_pinch");
    scene.tracker.verify_intersection_free = true;
    coupling::Simulation sim = make_fluid_simulation(scene);
    const double k = 2.0 * M_PI / wavelength;
    const double rate = rayleigh_plateau_rate(scene.fluid.phases.sigma,
                                              scene.fluid.phases.rho_liquid, radius, k);
    // Every step's surface as a frame file would hold it is edge-manifold (mid-pinch too): the
    // periodic mesh made edge-manifold is closed, each directed edge paired with its reverse once;
    // the file holds its images reaching into the box (open where they leave it), no edge with
    // more than two triangles.
    int steps_checked = 0, steps_not_manifold = 0, nonmanifold_edges_resolved = 0;
    const FluidRunRecord r = run_sampled(sim, END, [&](const coupling::Simulation& s) {
        tracker::SurfaceMesh closed = s.tracker().mesh();
        tracker::make_edge_manifold(closed);
        const OutputSurface out = output_surface(s.tracker().mesh(), {}, 1.0);
        ++steps_checked;
        int crowded_edges = 0;
        for (int e = 0; e < out.mesh.num_edges(); ++e)
            crowded_edges += out.mesh.edge_alive(e) && out.mesh.edge_triangles(e).size() > 2;
        steps_not_manifold +=
            unpaired_directed_edges(live_triangles(closed)) != 0 || crowded_edges != 0 ? 1 : 0;
        nonmanifold_edges_resolved += out.nonmanifold_edges;
    });
    std::printf("[ measured ] jet pinch quick: %d steps' output surfaces edge-manifold-checked, "
                "%d non-manifold edges of the tracker's mesh split for output\n",
                steps_checked, nonmanifold_edges_resolved);
    EXPECT_EQ(steps_not_manifold, 0);
    ASSERT_TRUE(r.completed);
    EXPECT_EQ(r.max_intersecting_pairs, 0);
    double pinch_time = -1.0;
    for (size_t i = 0; i < r.t.size(); ++i)
        if (pinch_time < 0.0 && r.components[i] > 1)
            pinch_time = r.t[i];
    std::printf("[ measured ] jet pinch quick, %lld steps: pinch-off at %.2f ms (linear estimate "
                "ln(1/eps)/s = %.2f ms), %d components at %.1f ms, %d splits, volume drift "
                "%.3f %%\n",
                r.steps, 1e3 * pinch_time, 1e3 * std::log(1.0 / AMPLITUDE) / rate,
                r.components.back(), 1e3 * END, r.splits,
                100.0 * max_relative_drift(r.enclosed_volume));
    EXPECT_EQ(r.components.front(), 1);
    EXPECT_GT(r.components.back(), 1);
    EXPECT_GE(r.splits, 1);
    // Not before the linear phase is over.
    EXPECT_GT(pinch_time, std::log(1.0 / AMPLITUDE) / rate);
    // The liquid's volume, within docs/validation.md's 0.5 %. Regression: the volume correction used to close only the previous
    // step's gap, while the parts of the mesh outside the domain (moving with the clamped wall
    // velocity) changed the volume by a whole step's worth every step: 3.8 % drift. It now
    // also cancels the motion's own volume rate: measured 0.005 %.
    EXPECT_LT(max_relative_drift(r.enclosed_volume), PHASE_VOLUME_TOLERANCE);
}

TEST(ScenePhysics, DropMergeEndsAsOneDropKeepingBothPhaseVolumes) {
    // scenes/drop_merge.json for its first 10 of 30 frames (the drops touch at ~6 ms and have
    // merged by 9 ms).
    constexpr int FRAMES = 10;
    const Scene scene = load_scene(scene_path("drop_merge"));
    const std::vector<Json> lines = run_frames(scene, "drop_merge", FRAMES);
    ASSERT_EQ(lines.size(), static_cast<size_t>(FRAMES + 1));
    EXPECT_EQ(lines.front()["components"].get<int>(), 2);
    EXPECT_EQ(lines.back()["components"].get<int>(), 1);
    expect_phase_volumes_kept(lines, scene.domain.size.prod());
}

TEST(ScenePhysics, BubbleMergeEndsAsOneBubbleKeepingBothPhaseVolumes) {
    // scenes/bubble_merge.json for its first 8 of 20 frames (16 ms; measured: the bubbles merge
    // at about 13 ms). Regression: with the paper's merge distance 0.1ξ the sub-cell water film
    // between the bubbles never drained and they drifted apart again.
    constexpr int FRAMES = 8;
    const Scene scene = load_scene(scene_path("bubble_merge"));
    const std::vector<Json> lines = run_frames(scene, "bubble_merge", FRAMES);
    ASSERT_EQ(lines.size(), static_cast<size_t>(FRAMES + 1));
    EXPECT_EQ(lines.front()["components"].get<int>(), 2);
    EXPECT_EQ(lines.back()["components"].get<int>(), 1);
    expect_phase_volumes_kept(lines, scene.domain.size.prod());
}

TEST(ScenePhysics, RisingBubbleShortKeepsBothPhaseVolumes) {
    // scenes/rising_bubble.json for 2 of 25 frames (4 ms: the bubble accelerates from rest).
    constexpr int FRAMES = 2;
    const Scene scene = load_scene(scene_path("rising_bubble"));
    const std::vector<Json> lines = run_frames(scene, "rising_bubble", FRAMES);
    ASSERT_EQ(lines.size(), static_cast<size_t>(FRAMES + 1));
    EXPECT_EQ(lines.back()["components"].get<int>(), 1);
    EXPECT_GT(lines.back()["kinetic_energy"].get<double>(), 0.0);  // buoyancy moves it
    expect_phase_volumes_kept(lines, scene.domain.size.prod());
}

/// What a jet's breakup looked like over a run (jet_breakup()).
struct JetBreakup {
    double speed = 0.0;         ///< m/s
    double first_drop = -1.0;   ///< s, first frame with a drop apart from the jet
    double intact_length = 0.0;  ///< m, mean reach of the attached jet once the start has gone
    double shortest = 0.0, longest = 0.0;  ///< m, its range over those frames
    int frames_averaged = 0;
    double volume_balance = 0.0;  ///< |liquid now − start − in + out| / in, worst frame
};

/// scenes/jet_nozzle.json at `speed` (m/s), coarsened for the suite: 3 cells per radius instead
/// of 4 in a box 20 mm long instead of 30 (18 × 18 × 120 cells), a 3 % pulse instead of 2 % (a
/// shorter linear phase), the pulse's frequency scaled with the speed so that the forced
/// wavelength stays the fastest-growing one (kR = 0.697). The intact length is averaged over the
/// frames after the start's column (the liquid in the box at t = 0) has left the box.
JetBreakup jet_breakup(double speed, double end) {
    constexpr double WIDTH = 0.003, LENGTH = 0.02, PULSE = 0.03;
    constexpr int CELLS_ACROSS = 18;
    constexpr double FRAME = 1e-3;  // s
    Json j = scene_json("jet_nozzle");
    Json& inflow = j["fluid"]["boundaries"]["z_max"]["inflow"];
    const double radius = inflow["radius"];
    const double scene_speed = inflow["speed"];
    inflow["speed"] = speed;
    inflow["pulse"] = PULSE;
    inflow["pulse_frequency"] = inflow["pulse_frequency"].get<double>() * speed / scene_speed;
    inflow["centre"] = {WIDTH / 2, WIDTH / 2, LENGTH};
    j["domain"]["size"] = {WIDTH, WIDTH, LENGTH};
    j["domain"]["cells"] = CELLS_ACROSS;
    Json column = j["surface"]["shape"];
    column["center"] = {WIDTH / 2, WIDTH / 2, LENGTH / 2};
    column["height"] = LENGTH + 4.0 * radius / 3.0;  // 2 cells past either end, as shipped
    j["surface"]["shape"] = column;
    j["initial_velocity"][0]["shape"] = column;
    j["initial_velocity"][0]["velocity"] = {0.0, 0.0, -speed};
    j["time"]["end"] = end;
    j["time"]["frames"] = static_cast<int>(std::lround(end / FRAME));
    const Scene scene = scene_from(j, "jet_nozzle");
    const std::vector<Json> lines = run_frames(scene, "jet_nozzle", scene.time.frames);
    JetBreakup b;
    b.speed = speed;
    b.shortest = LENGTH;
    const double start = lines.front()["volume"].get<double>();  // m³, as open_boundaries'
    double sum = 0.0;
    for (const Json& l : lines) {
        const double t = l["time"];
        const Json& open = l.value("open_boundaries", Json::object());
        if (open.empty())
            continue;
        if (b.first_drop < 0.0 && l["components"].get<int>() > 1)
            b.first_drop = t;
        const Json& total = open["total"];
        const double in = total["liquid_in"].get<double>(), out = total["liquid_out"].get<double>();
        const double now = l["volume"].get<double>();
        b.volume_balance = std::max(b.volume_balance, std::abs(now - start - in + out) / in);
        if (t < LENGTH / speed)
            continue;  // the start's column is still in the box
        const double reach = open["inflows"][0]["attached_reach"];
        sum += reach;
        b.shortest = std::min(b.shortest, reach);
        b.longest = std::max(b.longest, reach);
        ++b.frames_averaged;
    }
    b.intact_length = b.frames_averaged > 0 ? sum / b.frames_averaged : 0.0;
    return b;
}

TEST(ScenePhysics, JetBreakupLengthAtTwoInflowSpeeds) {
    // Issue 39: the forced jet of scenes/jet_nozzle.json (coarsened, see jet_breakup()) at 0.8
    // and 1.2 m/s, each run until the start's column has gone and two drops' periods more.
    // Linear theory: a disturbance grows as e^{ωt} with ω = 0.3433 sqrt(σ/(ρR³)) = 262 1/s
    // whatever the speed, so the jet breaks after about the same time t_b = ln(R/δ₀)/ω and its
    // intact length L = U t_b grows with the speed. Measured: 10.9 and 15.7 mm, t_b = 13.6 and
    // 13.1 ms (ω t_b = 3.6 and 3.4: the pulse's disturbance grows about 33-fold before the
    // neck closes); about 8 minutes of CPU for both runs.
    const JetBreakup slow = jet_breakup(0.8, 0.034);
    const JetBreakup fast = jet_breakup(1.2, 0.026);
    const double omega = rayleigh_plateau_rate(0.0728, 1000.0, 5e-4, 0.697 / 5e-4);
    for (const JetBreakup& b : {slow, fast})
        std::printf("[ measured ] jet at %.1f m/s: first drop at %.1f ms; intact length %.2f mm "
                    "(%.2f to %.2f over %d frames), breakup time L/U = %.2f ms = %.2f / omega; "
                    "liquid volume balance %.1e of the inflow\n",
                    b.speed, 1e3 * b.first_drop, 1e3 * b.intact_length, 1e3 * b.shortest,
                    1e3 * b.longest, b.frames_averaged, 1e3 * b.intact_length / b.speed,
                    omega * b.intact_length / b.speed, b.volume_balance);
    for (const JetBreakup& b : {slow, fast}) {
        EXPECT_GT(b.first_drop, 0.0) << "no drop at " << b.speed << " m/s";
        EXPECT_GE(b.frames_averaged, 6);
        EXPECT_GT(b.shortest, 0.0);         // the jet stays attached to its nozzle
        EXPECT_LT(b.longest, 0.02);         // and breaks inside the box
        EXPECT_LT(b.volume_balance, 0.01);  // what came in is there or went out
        const double growth = omega * b.intact_length / b.speed;  // ln(R/δ₀)
        EXPECT_GT(growth, 2.0);
        EXPECT_LT(growth, 6.0);
    }
    EXPECT_GT(fast.intact_length, 1.2 * slow.intact_length);
    const double ratio = (fast.intact_length / fast.speed) / (slow.intact_length / slow.speed);
    EXPECT_GT(ratio, 0.75);
    EXPECT_LT(ratio, 1.15);
}

}  // namespace
}  // namespace meniscus::app
