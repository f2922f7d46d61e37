// Every shipped scene runs a few steps with the exact self-intersection check on; the
// drop_merge scene merges. (Full runs: `meniscus run`; validation: `meniscus validate`.)
#include "app/run.h"
#include "app/scene.h"
#include "tracker/flows/flow_errors.h"
#include "tracker/mesh_io.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>

namespace meniscus::app {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> shipped_scenes() {
    std::vector<fs::path> out;
    for (const auto& e :
         fs::recursive_directory_iterator(std::string(MENISCUS_SOURCE_DIR) + "/scenes"))
        if (e.path().extension() == ".json")
            out.push_back(e.path());
    std::sort(out.begin(), out.end());
    return out;
}

class SceneRuns : public testing::TestWithParam<fs::path> {};

/// Geometric-flow scenes run here at no finer than this edge length (their ξ = 0.01 variants
/// would spend seconds meshing); fluid scenes keep theirs (it follows the grid) up to
/// SMOKE_MAX_X_CELLS cells along x: the production-resolution scenes (scenes/production/) run
/// here on that coarser grid, with the mesh following it.
constexpr double SMOKE_EDGE_LENGTH = 0.04;
constexpr int SMOKE_MAX_X_CELLS = 40;

TEST_P(SceneRuns, FewStepsStayIntersectionFree) {
    Scene scene = load_scene(GetParam().string());
    if (scene.flow.type != "fluid")
        scene.surface.edge_length = std::max(scene.surface.edge_length, SMOKE_EDGE_LENGTH);
    if (scene.flow.type == "fluid" && scene.domain.cells > SMOKE_MAX_X_CELLS) {
        ASSERT_GT(scene.coupling.edge_length_cells, 0.0) << "the mesh must follow the grid";
        scene.domain.cells = SMOKE_MAX_X_CELLS;
        scene.surface.edge_length =
            scene.coupling.edge_length_cells * scene.domain.size.x() / scene.domain.cells;
    }
    scene.tracker.verify_intersection_free = true;
    scene.output.vdb = false;  // the VDB writer has its own test; keep the suite quick
    RunOptions options;
    options.out_dir =
        (fs::temp_directory_path() / ("meniscus_scene_" + GetParam().stem().string())).string();
    options.max_steps = 3;
    options.quiet = true;
    const std::atomic<bool> stop{false};
    const RunResult r = run_scene(scene, options, stop);
    EXPECT_TRUE(r.reached_max_steps);
    EXPECT_EQ(r.max_intersecting_pairs, 0);
    EXPECT_TRUE(fs::exists(fs::path(options.out_dir) / "surface_0000.ply"));
    fs::remove_all(options.out_dir);
}

INSTANTIATE_TEST_SUITE_P(Shipped, SceneRuns, testing::ValuesIn(shipped_scenes()),
                         [](const testing::TestParamInfo<fs::path>& param_info) {
                             std::string name = param_info.param.stem().string();
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c)))
                                     c = '_';
                             return name;
                         });

TEST(DropMerge, TwoDropsBecomeOneKeepingTheirVolume) {
    Scene scene = load_scene(std::string(MENISCUS_SOURCE_DIR) + "/scenes/drop_merge.json");
    scene.tracker.verify_intersection_free = true;
    scene.output.vdb = false;
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() / "meniscus_drop_merge").string();
    options.frames = 10;  // the drops touch after about 6 ms and merge by 9 ms
    options.quiet = true;
    const std::atomic<bool> stop{false};
    const RunResult r = run_scene(scene, options, stop);
    EXPECT_EQ(r.max_intersecting_pairs, 0);
    std::ifstream stats(fs::path(options.out_dir) / "stats.jsonl");
    std::vector<nlohmann::json> lines;
    for (std::string line; std::getline(stats, line);)
        lines.push_back(nlohmann::json::parse(line));
    ASSERT_EQ(lines.size(), 11u);
    EXPECT_EQ(lines.front()["components"], 2);
    // At 12 cells per diameter the fresh neck is 1–2 cells wide and may pinch again briefly
    // (the full 30-frame run ends as one drop); here: they did merge.
    int fewest = 2, merges = 0;
    for (const auto& l : lines) {
        fewest = std::min(fewest, l["components"].get<int>());
        merges += l.value("merges", 0);
    }
    EXPECT_EQ(fewest, 1);
    EXPECT_GE(merges, 1);
    const double v0 = lines.front()["volume"], v1 = lines.back()["volume"];
    EXPECT_NEAR(v1, v0, 0.005 * v0);
    fs::remove_all(options.out_dir);
}

/// Taylor's deformation D = (L − B)/(L + B) of a closed surface in the x–y plane and the angle
/// (degrees, from +x towards +y) of its long axis: L and B are the semi-axes of the ellipsoid with
/// the same second moments of volume (∫ x_i² dV = V a_i² / 5 on an ellipsoid).
struct ShearDeformation {
    double d = 0.0;
    double angle = 0.0;
};

ShearDeformation shear_deformation(const tracker::SurfaceMesh& mesh) {
    // ∫ x xᵀ dV by tetrahedra from the origin: V_t/20 (Σ v vᵀ + s sᵀ) over the 4 corners.
    double volume = 0.0;
    Eigen::Vector3d first = Eigen::Vector3d::Zero();
    Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const tracker::Triangle& t = mesh.triangle(ti);
        const Eigen::Vector3d &a = mesh.position(t[0]), &b = mesh.position(t[1]),
                              &c = mesh.position(t[2]);
        const double v = a.dot(b.cross(c)) / 6.0;
        const Eigen::Vector3d sum = a + b + c;
        volume += v;
        first += v * sum / 4.0;
        second += v / 20.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() +
                              sum * sum.transpose());
    }
    const Eigen::Vector3d centre = first / volume;
    const Eigen::Matrix3d central = second - volume * centre * centre.transpose();
    // The 2 × 2 x–y block's eigenvalues and long axis.
    const double sxx = central(0, 0), syy = central(1, 1), sxy = central(0, 1);
    const double mean = 0.5 * (sxx + syy), radius = std::hypot(0.5 * (sxx - syy), sxy);
    const double long_axis = std::sqrt(5.0 * (mean + radius) / volume);
    const double short_axis = std::sqrt(5.0 * (mean - radius) / volume);
    ShearDeformation out;
    out.d = (long_axis - short_axis) / (long_axis + short_axis);
    out.angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy) * 180.0 / M_PI;
    return out;
}

TEST(ScenePhysics, DropInShearStretchesAlongTheExtensionalAxis) {
    // drop_shear: walls at y = 0 and 8 mm slide at ∓4 cm/s (G = 10 1/s), the 2 mm drop in the
    // middle. From rest the shear reaches the drop by diffusion and stretches it along the
    // extensional axis (45°), turning towards the flow as it deforms; the full run levels off
    // at D = 0.191, 29.5° (the README's numbers). After 0.02 s (2 frames) measured: D = 0.053 at
    // 42.5°. Without the moving walls nothing would move at all.
    Scene scene = load_scene(std::string(MENISCUS_SOURCE_DIR) + "/scenes/drop_shear.json");
    scene.tracker.verify_intersection_free = true;
    scene.output.vdb = false;
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() / "meniscus_drop_shear").string();
    options.frames = 2;
    options.quiet = true;
    const std::atomic<bool> stop{false};
    const RunResult r = run_scene(scene, options, stop);
    EXPECT_EQ(r.max_intersecting_pairs, 0);
    const tracker::SurfaceMesh start = tracker::to_surface_mesh(
        tracker::read_ply((fs::path(options.out_dir) / "surface_0000.ply").string()), "start");
    const tracker::SurfaceMesh end = tracker::to_surface_mesh(
        tracker::read_ply((fs::path(options.out_dir) / "surface_0002.ply").string()), "end");
    const ShearDeformation d0 = shear_deformation(start), d1 = shear_deformation(end);
    std::cout << "[ measured ] drop in shear at t = 0.02 s: D = " << d1.d << " at " << d1.angle
              << " degrees (start D = " << d0.d << ")\n";
    EXPECT_LT(d0.d, 0.005);
    EXPECT_GT(d1.d, 0.035);
    EXPECT_LT(d1.d, 0.07);
    EXPECT_GT(d1.angle, 38.0);
    EXPECT_LT(d1.angle, 46.0);
    EXPECT_NEAR(tracker::enclosed_volume(end), tracker::enclosed_volume(start),
                0.005 * tracker::enclosed_volume(start));
    fs::remove_all(options.out_dir);
}

std::vector<nlohmann::json> read_stats(const fs::path& dir) {
    std::ifstream stats(dir / "stats.jsonl");
    std::vector<nlohmann::json> lines;
    for (std::string line; std::getline(stats, line);)
        lines.push_back(nlohmann::json::parse(line));
    return lines;
}

/// The static drop for `frames` frames with `edit` applied to the scene.
std::vector<nlohmann::json> static_drop_stats(int frames, const std::function<void(Scene&)>& edit,
                                              const std::string& dir_name) {
    Scene scene = load_scene(std::string(MENISCUS_SOURCE_DIR) + "/scenes/static_drop.json");
    scene.output.vdb = false;
    scene.output.ply = false;
    edit(scene);
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() / dir_name).string();
    options.frames = frames;
    options.quiet = true;
    const std::atomic<bool> stop{false};
    run_scene(scene, options, stop);
    std::vector<nlohmann::json> lines = read_stats(options.out_dir);
    fs::remove_all(options.out_dir);
    return lines;
}

TEST(FluidScenes, TimeDtCapsTheFluidStep) {
    // Issue 34: /time/dt was documented as the largest step but fluid scenes ignored it.
    Scene reference = load_scene(std::string(MENISCUS_SOURCE_DIR) + "/scenes/static_drop.json");
    const double frame = reference.time.end / reference.time.frames;
    const std::vector<nlohmann::json> free = static_drop_stats(1, [](Scene&) {}, "meniscus_dt_a");
    ASSERT_EQ(free.size(), 2u);
    const double own_dt = free[1]["dt"];
    EXPECT_NE(free[1]["dt_limit"], "max_dt");
    const double cap = 0.25 * own_dt;
    const std::vector<nlohmann::json> capped =
        static_drop_stats(1, [&](Scene& s) { s.time.dt = cap; }, "meniscus_dt_b");
    ASSERT_EQ(capped.size(), 2u);
    EXPECT_LE(capped[1]["dt"].get<double>(), cap * (1.0 + 1e-12));
    EXPECT_GE(capped[1]["steps"].get<long long>(), static_cast<long long>(frame / cap));
    // dt_limits counts the frame's steps by what set their Δt: here the cap, and the last step
    // at most the frame's end.
    const nlohmann::json& limits = capped[1]["dt_limits"];
    long long counted = 0;
    for (const auto& [limit, steps] : limits.items())
        counted += steps.get<long long>();
    EXPECT_EQ(counted, capped[1]["steps"].get<long long>());
    EXPECT_GE(limits.value("max_dt", 0LL), capped[1]["steps"].get<long long>() - 1);
}

TEST(FluidScenes, StatsReportTheViscousAndPressureSolves) {
    const std::vector<nlohmann::json> lines =
        static_drop_stats(1, [](Scene&) {}, "meniscus_solves");
    ASSERT_EQ(lines.size(), 2u);
    const nlohmann::json& solves = lines[1]["solves"];
    EXPECT_GT(solves["pressure"]["iterations_per_step"].get<double>(), 0.0);
    EXPECT_GT(solves["viscosity"]["iterations_per_step"].get<double>(), 0.0);
    EXPECT_EQ(solves["pressure"]["unconverged_steps"], 0);
    EXPECT_EQ(solves["viscosity"]["unconverged_steps"], 0);
    // The coupled scheme's passes solve their viscous impulses to a tenth of pass_tolerance.
    EXPECT_LE(solves["viscosity"]["max_residual"].get<double>(), 1e-4);
    const nlohmann::json& passes = solves["viscous_pressure_passes"];
    // The cells the passes ran on (their region's or the grid's), when there were passes.
    if (passes["per_step"].get<double>() > 0.0)
        EXPECT_GT(passes["mean_cells"].get<double>(), 0.0);
    else
        EXPECT_EQ(passes["mean_cells"].get<double>(), 0.0);
}

TEST(FluidScenes, StatsSplitTheStepIntoPhasesInWallAndCpuSeconds) {
    // Issue 36: where the time goes, per phase of the coupling and of the fluid step.
    const std::vector<nlohmann::json> lines = static_drop_stats(1, [](Scene&) {}, "meniscus_phases");
    ASSERT_EQ(lines.size(), 2u);
    const char* coupled[] = {"rasterize",         "curvature", "fluid", "interpolate",
                             "volume_correction", "tracker",   "output"};
    const char* fluid[] = {"advection",      "forces",         "viscosity",
                           "pressure_build", "pressure_solve", "extrapolation"};
    for (const nlohmann::json& line : lines) {
        const int frame = line["frame"];
        for (const nlohmann::json* seconds : {&line["seconds"], &line["seconds"]["cpu"]}) {
            double phase_sum = 0.0;
            for (const char* name : fluid) {
                ASSERT_TRUE((*seconds)["fluid_phases"].contains(name)) << name;
                const double s = (*seconds)["fluid_phases"][name];
                EXPECT_GE(s, 0.0) << name;
                phase_sum += s;
            }
            for (const char* name : coupled) {
                ASSERT_TRUE(seconds->contains(name)) << name;
                EXPECT_GE((*seconds)[name].get<double>(), 0.0) << name;
                if (frame == 0 && std::string(name) != "output") {
                    EXPECT_EQ((*seconds)[name].get<double>(), 0.0) << name << " before any step";
                }
            }
            // The fluid step is its phases, up to the bookkeeping between them.
            const double fluid_total = (*seconds)["fluid"];
            EXPECT_LE(phase_sum, fluid_total * (1.0 + 1e-9) + 1e-9);
            if (frame > 0) {
                EXPECT_GE(phase_sum, 0.7 * fluid_total);
                EXPECT_GT((*seconds)["fluid_phases"]["pressure_solve"].get<double>(), 0.0);
                EXPECT_GT((*seconds)["fluid_phases"]["viscosity"].get<double>(), 0.0);
                EXPECT_GT((*seconds)["rasterize"].get<double>(), 0.0);
                EXPECT_GT((*seconds)["tracker"].get<double>(), 0.0);
            }
        }
    }
}

TEST(FluidScenes, UnconvergedSolvesAreCountedInTheStats) {
    // One viscous CG iteration cannot reach 1e-12: every step is counted as unconverged (and
    // `meniscus run` warns; the CLI test checks the message).
    const std::vector<nlohmann::json> lines = static_drop_stats(
        1,
        [](Scene& s) {
            s.fluid.viscosity.iteration.max_iterations = 1;
            s.fluid.viscosity.iteration.tolerance = 1e-12;
        },
        "meniscus_unconverged");
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_EQ(lines[1]["solves"]["viscosity"]["unconverged_steps"].get<long long>(),
              lines[1]["steps"].get<long long>());
}

const std::string FLOW_SCENES = std::string(MENISCUS_SOURCE_DIR) + "/scenes/flows/";

/// The stats.jsonl lines of a shipped flow scene run for `frames` frames without PLY output;
/// the run itself must stay intersection-free.
std::vector<nlohmann::json> flow_scene_stats(const std::string& name, int frames) {
    Scene scene = load_scene(FLOW_SCENES + name);
    scene.output.ply = false;
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() / ("meniscus_" + name)).string();
    options.frames = frames;
    options.quiet = true;
    const std::atomic<bool> stop{false};
    const RunResult r = run_scene(scene, options, stop);
    EXPECT_EQ(r.max_intersecting_pairs, 0) << name;
    std::vector<nlohmann::json> stats = read_stats(options.out_dir);
    fs::remove_all(options.out_dir);
    return stats;
}

TEST(FlowScenes, A1ErrorInStatsIsTheFlowErrorsComputation) {
    Scene scene = load_scene(FLOW_SCENES + "a1_face_offsetting_xi0.04.json");
    scene.output.length_unit = "m";  // the PLY is compared with the exact solution in metres
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() / "meniscus_a1_exact").string();
    options.frames = 1;  // t = 0.1: 20 steps of Δt = 0.005
    options.quiet = true;
    const std::atomic<bool> stop{false};
    const RunResult r = run_scene(scene, options, stop);
    EXPECT_EQ(r.max_intersecting_pairs, 0);
    const auto lines = read_stats(options.out_dir);
    ASSERT_EQ(lines.size(), 2u);
    const double t = lines[1]["time"];
    EXPECT_DOUBLE_EQ(t, 0.1);
    // The same error from the written surface and docs/validation.md A1's exact solution.
    const tracker::SurfaceMesh mesh = tracker::to_surface_mesh(
        tracker::read_mesh_file((fs::path(options.out_dir) / "surface_0001.ply").string()), "ply");
    tracker::TwoSphereNormalFlow flow;  // defaults: A1's spheres and speed
    flow.reversal_time = 1.0;
    const tracker::SurfaceError expected = tracker::two_sphere_normal_flow_error(mesh, flow, t);
    const nlohmann::json& recorded = lines[1]["exact_error"];
    EXPECT_EQ(recorded["type"], "two_sphere_normal_flow");
    EXPECT_NEAR(recorded["linf"].get<double>(), expected.linf, 1e-12);
    EXPECT_NEAR(recorded["l1"].get<double>(), expected.l1, 1e-12);
    EXPECT_NEAR(recorded["vertex_linf"].get<double>(), expected.vertex_linf, 1e-12);
    EXPECT_NEAR(recorded["vertex_l1"].get<double>(), expected.vertex_l1, 1e-12);
    // Before the spheres touch (t = 0.25) face offsetting is close to exact.
    EXPECT_LT(expected.vertex_linf, 1e-3);
    EXPECT_EQ(lines[0]["exact_error"]["vertex_linf"].get<double>() < 1e-12, true);
    fs::remove_all(options.out_dir);
}

TEST(FlowScenes, SphereUnderMeanCurvatureRecordsTheExactRadius) {
    Scene scene = load_scene(FLOW_SCENES + "a2_sphere_xi0.04.json");
    scene.tracker.verify_intersection_free = false;
    scene.output.length_unit = "m";  // the PLY is compared with the exact sphere in metres
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() / "meniscus_a2_exact").string();
    const fs::path last_frame = fs::path(options.out_dir) / "surface_0002.ply";
    ASSERT_FALSE(scene.time.land_on_frames);  // steps as in `meniscus validate`
    options.frames = 2;                       // frame times 0.00125 and 0.0025
    options.quiet = true;
    const std::atomic<bool> stop{false};
    run_scene(scene, options, stop);
    auto lines = read_stats(options.out_dir);
    ASSERT_EQ(lines.size(), 3u);
    // Frame 1 is written after the first step reaching its time; the last lands on the end.
    const double frame_dt = scene.time.end / scene.time.frames;
    EXPECT_GE(lines[1]["time"].get<double>(), frame_dt);
    EXPECT_LT(lines[1]["time"].get<double>(), frame_dt + lines[1]["dt"].get<double>());
    EXPECT_EQ(lines[2]["time"].get<double>(), 2 * frame_dt);
    lines.erase(lines.begin() + 1);
    const double t = lines[1]["time"];
    const double exact_radius = std::sqrt(0.3 * 0.3 - 4.0 * t);
    EXPECT_DOUBLE_EQ(lines[1]["exact_error"]["radius"].get<double>(), exact_radius);
    // The sphere shrank by 0.017 m; the discrete flow follows it to a small fraction of that.
    EXPECT_LT(lines[1]["exact_error"]["vertex_linf"].get<double>(), 0.1 * (0.3 - exact_radius));
    const tracker::SurfaceMesh mesh =
        tracker::to_surface_mesh(tracker::read_mesh_file(last_frame.string()), "ply");
    EXPECT_NEAR(lines[1]["exact_error"]["l1"].get<double>(),
                tracker::sphere_error(mesh, Eigen::Vector3d::Zero(), exact_radius).l1, 1e-12);
    fs::remove_all(options.out_dir);
}

/// Signed vertex distances to the exact sphere of the last frame of the A2 sphere scene at edge
/// length ξ run to t_end, with tangent-plane smoothing or smoothing along a cubic fitted over
/// each two-ring where it turns by at most 0.6 rad, and collapses to the butterfly point or to
/// the fitted surface.
tracker::SurfaceError shrunk_sphere_error(double xi, double t_end, bool fitted_smoothing,
                                          bool fitted_collapses) {
    Scene scene = load_scene(FLOW_SCENES + "a2_sphere_xi0.02.json");
    scene.surface.edge_length = xi;
    scene.tracker.verify_intersection_free = false;
    scene.tracker.remesh.smoothing_onto_fitted_surface = fitted_smoothing;
    scene.tracker.remesh.smoothing_fit_degree = 3;
    scene.tracker.remesh.smoothing_fit_max_turn = 0.6;
    scene.tracker.remesh.collapse_on_fitted_surface = fitted_collapses;
    scene.time.end = t_end;
    scene.time.frames = 1;
    scene.output.length_unit = "m";  // the PLY is compared with the exact sphere in metres
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() / "meniscus_a2_shrunk").string();
    options.quiet = true;
    const std::atomic<bool> stop{false};
    run_scene(scene, options, stop);
    const tracker::SurfaceMesh mesh = tracker::to_surface_mesh(
        tracker::read_mesh_file((fs::path(options.out_dir) / "surface_0001.ply").string()), "ply");
    fs::remove_all(options.out_dir);
    return tracker::sphere_error(mesh, Eigen::Vector3d::Zero(), std::sqrt(0.09 - 4.0 * t_end));
}

TEST(FlowScenes, ShrinkingSphereStaysOnItsRadiusWithFittedSmoothingAndCollapses) {
    // Issue #5: R = 0.3 → 0.1, a mesh collapsing to an eighth of its triangles. Tangent-plane
    // smoothing of the irregular rings the collapses leave sinks every vertex inside the exact
    // sphere (the A2 dumbbell's drops at ξ = 0.01 likewise, by 2.3e-5, above the paper's error):
    // the quadric's area-weighted normal leans towards the larger triangles, which is where the
    // vertex moves, so its tangent plane dips into the surface. Smoothing along a cubic fitted
    // over each two-ring does not (the drops' two-rings turn by about 0.4, under the bound), and
    // with collapses onto the fitted surface too every vertex stays close to the sphere.
    // Measured mean signed vertex error at ξ = 0.03 (36 s for the three runs): tangent plane
    // −1.88e-4, fitted smoothing −1.30e-5, both fitted +1.52e-5 (max |error| 2.38e-5). At
    // ξ = 0.02 (169 s in the suite, so no longer run here): −8.66e-5, −6.6e-6, +3.1e-6 (all
    // vertices in [+2.3e-6, +4.4e-6]); at ξ = 0.04 the both-fitted max is 0.20 of the tangent
    // plane's mean, too close to tell apart.
    constexpr double XI = 0.03;
    const double plane = shrunk_sphere_error(XI, 0.02, false, false).vertex_mean_signed;
    const double fitted = shrunk_sphere_error(XI, 0.02, true, false).vertex_mean_signed;
    const tracker::SurfaceError both = shrunk_sphere_error(XI, 0.02, true, true);
    std::cout << "[ measured ] A2 sphere 0.3 → 0.1, ξ = " << XI
              << ": mean signed vertex error, tangent "
              << "plane " << plane << ", fitted smoothing " << fitted << ", fitted smoothing and "
              << "collapses " << both.vertex_mean_signed << " (max |error| " << both.vertex_linf
              << ")\n";
    EXPECT_LT(plane, -1e-4);
    EXPECT_LT(std::abs(fitted), 0.25 * std::abs(plane));
    EXPECT_LT(both.vertex_linf, 5e-5);
    EXPECT_LT(both.vertex_linf, std::abs(plane) / 4.0);
}

TEST(FlowScenes, OpenSheetKeepsItsBoundaryUnderCurlNoise) {
    Scene scene = load_scene(FLOW_SCENES + "a4_curl_noise_open_xi0.04.json");
    scene.output.length_unit = "m";  // positions below are compared in metres
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() / "meniscus_open_sheet").string();
    options.frames = 5;  // t = 0.5: 10 RK4 steps
    options.quiet = true;
    const std::atomic<bool> stop{false};
    const RunResult r = run_scene(scene, options, stop);
    EXPECT_EQ(r.max_intersecting_pairs, 0);
    const auto count_boundary = [](const tracker::SurfaceMesh& m) {
        int n = 0;
        for (int ei = 0; ei < m.num_edges(); ++ei)
            n += !m.edge_triangles(ei).empty() && m.is_boundary_edge(ei) ? 1 : 0;
        return n;
    };
    const auto load = [&](const char* name) {
        return tracker::to_surface_mesh(
            tracker::read_mesh_file((fs::path(options.out_dir) / name).string()), name);
    };
    const tracker::SurfaceMesh before = load("surface_0000.ply"), after = load("surface_0005.ply");
    tracker::ValidationOptions open;
    open.allow_boundary = true;
    EXPECT_TRUE(tracker::validate_mesh(after, open).empty());
    // Boundary edges are never split, flipped or collapsed: the same boundary, moved.
    EXPECT_GT(count_boundary(before), 0);
    EXPECT_EQ(count_boundary(after), count_boundary(before));
    // The sheet starts in the plane y = 0; the planar field moves it in x and y.
    double moved = 0.0;
    for (int vi = 0; vi < after.num_vertices(); ++vi)
        if (after.vertex_alive(vi) && after.is_boundary_vertex(vi))
            moved = std::max(moved, std::abs(after.position(vi).y()));
    EXPECT_GT(moved, 1e-3);
    fs::remove_all(options.out_dir);
}

TEST(FlowScenes, CurlNoiseStretchesTheSphereAndKeepsItsVolume) {
    // A4's paper-like field at ξ = 0.04 to t = 15, collision safety on: the field is
    // divergence-free, so the enclosed volume may change only by discretization. Measured:
    // 1090 → 9736 triangles (8.9×), volume +0.13 %, of which collision handling +0.014 %.
    const std::vector<nlohmann::json> stats = flow_scene_stats("a4_curl_noise_xi0.04.json", 15);
    ASSERT_EQ(stats.size(), 16u);
    EXPECT_DOUBLE_EQ(stats.back()["time"].get<double>(), 15.0);
    const double v0 = stats.front()["volume"].get<double>();
    double by_collisions = 0.0;
    for (size_t i = 1; i < stats.size(); ++i) {
        EXPECT_EQ(stats[i]["intersecting_pairs"].get<int>(), 0) << "frame " << i;
        by_collisions += stats[i]["volume_change_by_phase"]["collisions"].get<double>();
    }
    const double change = stats.back()["volume"].get<double>() / v0 - 1.0;
    const int triangles = stats.back()["triangles"].get<int>();
    std::cout << "[ measured ] A4 ξ=0.04 at t=15: " << triangles << " triangles, volume "
              << 100.0 * change << " %, by collision handling " << 100.0 * by_collisions / v0
              << " %\n";
    EXPECT_GT(triangles, 8 * stats.front()["triangles"].get<int>());
    EXPECT_LT(std::abs(change), 0.003);
    EXPECT_LT(std::abs(by_collisions / v0), 0.0005);
}

TEST(FlowScenes, ThinSheetSizingGainsLessVolumeUnderCurlNoise) {
    // A4's three-octave field to t = 12, when the sphere has been drawn into folded sheets: the
    // discretized sides of sheets thinner than their chord sag meet and collision handling holds
    // them apart, which adds volume; thin-sheet sizing refines there. Measured: +0.34 % on 7868
    // triangles uniform, +0.09 % on 11000 sized with order-preserving compaction; +0.15 % on 7872
    // and +0.02 % on 11086 since the mesh is renumbered spatially (the folding is chaotic: the
    // order in which the remesher visits edges changes the numbers, not the ratio). (The
    // paper-like one-octave field folds later: collision handling has added under 0.001 % by
    // t = 12, too little to compare.)
    const auto volume_change = [](const char* name, int& triangles, double& by_collisions) {
        const std::vector<nlohmann::json> stats = flow_scene_stats(name, 12);
        triangles = stats.back()["triangles"].get<int>();
        const double v0 = stats.front()["volume"].get<double>();
        // The frames' changes by phase add up to the whole change.
        double by_phase = 0.0;
        by_collisions = 0.0;
        for (size_t i = 1; i < stats.size(); ++i) {
            const nlohmann::json& b = stats[i]["volume_change_by_phase"];
            by_phase += b["remeshing"].get<double>() + b["motion"].get<double>() +
                        b["collisions"].get<double>();
            by_collisions += b["collisions"].get<double>();
        }
        EXPECT_NEAR(by_phase, stats.back()["volume"].get<double>() - v0, 1e-12 * v0) << name;
        by_collisions /= v0;
        return stats.back()["volume"].get<double>() / v0 - 1.0;
    };
    int uniform_triangles = 0, sized_triangles = 0;
    double uniform_by_collisions = 0.0, sized_by_collisions = 0.0;
    const double uniform = volume_change("a4_curl_noise_multiscale_xi0.04.json", uniform_triangles,
                                         uniform_by_collisions);
    const double sized = volume_change("a4_curl_noise_multiscale_thin_sheet_xi0.04.json",
                                       sized_triangles, sized_by_collisions);
    std::cout << "[ measured ] A4 three octaves ξ=0.04 at t=12: volume " << 100.0 * uniform
              << " % on " << uniform_triangles << " triangles uniform, " << 100.0 * sized
              << " % on " << sized_triangles << " with thin-sheet sizing; by collision handling "
              << 100.0 * uniform_by_collisions << " % and " << 100.0 * sized_by_collisions
              << " %\n";
    EXPECT_GT(uniform, 0.001);
    EXPECT_LT(std::abs(sized), 0.5 * uniform);
    // Collision handling's share: measured +0.12 % uniform by t = 12.
    EXPECT_GT(uniform_by_collisions, 0.0005);
    EXPECT_LT(sized_by_collisions, uniform_by_collisions);
    EXPECT_GT(sized_triangles, uniform_triangles);
}

TEST(FlowScenes, ExactSolutionMustOutlastTheRun) {
    // A1's merged balls (radius 0.4 at t = 1) erode away at t = 3; --frames 40 would run to 4.
    const Scene scene = load_scene(FLOW_SCENES + "a1_face_offsetting_xi0.04.json");
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() / "meniscus_exact_end").string();
    options.frames = 40;
    options.quiet = true;
    const std::atomic<bool> stop{false};
    try {
        run_scene(scene, options, stop);
        ADD_FAILURE() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("/flow/exact: the run ends at t = 4 s"),
                  std::string::npos)
            << e.what();
    }
    fs::remove_all(options.out_dir);
}

TEST(FlowScenes, ExactSolutionMustMatchTheInitialSurface) {
    // One sphere where /flow/exact describes two: refused before any step.
    Scene scene = parse_scene(R"({"surface": {"edge_length": 0.05,
        "shape": {"type": "sphere", "center": [-0.25, 0, 0], "radius": 0.2}},
        "flow": {"type": "normal_speed", "exact": {"type": "two_sphere_normal_flow"}},
        "time": {"end": 0.1, "frames": 1, "dt": 0.01}, "output": {"vdb": false}})",
                              "one_sphere.json", ".");
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() / "meniscus_exact_mismatch").string();
    options.quiet = true;
    const std::atomic<bool> stop{false};
    try {
        run_scene(scene, options, stop);
        ADD_FAILURE() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(
                      "one_sphere.json: /flow/exact: the initial surface is not the exact"),
                  std::string::npos)
            << e.what();
    }
    fs::remove_all(options.out_dir);
}

}  // namespace
}  // namespace meniscus::app
