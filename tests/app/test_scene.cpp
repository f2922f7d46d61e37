#include "app/errors.h"
#include "app/json_fields.h"
#include "app/run.h"
#include "app/scene.h"
#include "app/scene_setup.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace meniscus::app {
namespace {

std::string error_of(const std::string& json) {
    try {
        parse_scene(json, "test.json", ".");
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

TEST(Scene, EveryShippedSceneParses) {
    int count = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(
             std::string(MENISCUS_SOURCE_DIR) + "/scenes")) {
        if (entry.path().extension() != ".json")
            continue;
        ++count;
        EXPECT_NO_THROW(load_scene(entry.path().string())) << entry.path();
    }
    EXPECT_GT(count, 0);
}

TEST(Scene, InputThatWouldOverflowOrNestWithoutBoundIsRefusedWithItsPath) {
    // Numbers beyond a double (the JSON library's overflow, which has no position) name the
    // file and the JSON path, also inside arrays.
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere", "radius": 1e400}}})")
                  .find("test.json: /surface/shape/radius: expected a number, got 1e400, beyond "
                        "the range of a double"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}}, "fluid": {"gravity": [0, 0, -1e400]}})")
                  .find("test.json: /fluid/gravity/2: expected a number, got -1e400"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"initial_velocity": [{"velocity": [1, 2, 3]}, {"velocity": [1, 2e999, 3]}]})")
                  .find("test.json: /initial_velocity/1/velocity/1: expected a number, got 2e999"),
              std::string::npos);
    // Magnitudes whose products overflow.
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}}, "fluid": {"gravity": [0, 0, -1e308]}})")
                  .find("/fluid/gravity/2: expected a number, got -1e+308 (magnitudes outside"),
              std::string::npos);
    // Integers beyond long long are shown as written, not wrapped.
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}}, "domain": {"cells": 18446744073709551615}})")
                  .find("/domain/cells: expected an integer in [2, 4096], got 18446744073709551615"),
              std::string::npos);
    // Shape trees: depth and size are bounded.
    std::string shape = R"({"type": "sphere"})";
    for (int i = 0; i < 17; ++i)
        shape = R"({"type": "difference", "a": )" + shape + R"(, "b": {"type": "sphere", "radius": 0.01}})";
    EXPECT_NE(error_of(R"({"surface": {"shape": )" + shape + "}}")
                  .find("/surface/shape/a/a/a/a/a/a/a/a/a/a/a/a/a/a/a/a: shapes nested more than 16 deep"),
              std::string::npos);
    std::string deep = "0";
    for (int i = 0; i < 100; ++i)
        deep = "[" + deep + "]";
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}}, "name": )" + deep + "}")
                  .find("arrays and objects nested 101 deep (at most 64)"),
              std::string::npos);
    std::string regions;
    for (int i = 0; i < 65; ++i)
        regions += std::string(i ? ", " : "") + R"({"shape": {"type": "sphere"}, "velocity": [1, 0, 0]})";
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}}, "initial_velocity": [)" + regions + "]}")
                  .find("/initial_velocity: 65 regions; at most 64"),
              std::string::npos);
    // Validation errors name the key the user wrote, not a C++ name.
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}}, "tracker": {"topology": {"separation": {"nudge_fraction": 0.6}}}})")
                  .find("/tracker/topology/separation/nudge_fraction: expected a number in (0, 0.5)"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}}, "flow": {"type": "curl_noise",
                        "curl_noise": {"octaves": 16, "modes_per_octave": 10000}}})")
                  .find("/flow/curl_noise: 16 octaves x 10000 modes_per_octave = 160000 modes; at "
                        "most 4096"),
              std::string::npos);
}

TEST(Scene, ADirectoryIsNotASceneFile) {
    const auto dir = std::filesystem::temp_directory_path() / "meniscus_scene_dir.json";
    std::filesystem::create_directories(dir);
    try {
        load_scene(dir.string());
        ADD_FAILURE() << "a directory was read as a scene";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("is a directory, not a scene file"), std::string::npos);
    }
    std::filesystem::remove_all(dir);
}

TEST(Scene, DefaultsComeFromTheStructs) {
    const Scene s = parse_scene(R"({"surface": {"shape": {"type": "sphere"}}})", "t.json", ".");
    const Scene d;
    EXPECT_EQ(s.time.dt, d.time.dt);
    EXPECT_EQ(s.time.frames, d.time.frames);
    EXPECT_EQ(s.output.half_width_voxels, d.output.half_width_voxels);
    ASSERT_TRUE(s.shape);
    EXPECT_DOUBLE_EQ(s.shape->value({0, 0, 0}), -0.2);  // default sphere radius 0.2
}

TEST(Scene, SurfaceCreaseRefinementIsReadAndChecked) {
    const Scene s = parse_scene(
        R"({"surface": {"shape": {"type": "sphere"}, "crease": {"levels": 2, "angle": 0.5}}})",
        "t.json", ".");
    EXPECT_EQ(s.surface.crease.levels, 2);
    EXPECT_DOUBLE_EQ(s.surface.crease.angle, 0.5);
    EXPECT_DOUBLE_EQ(s.surface.crease.band, tracker::CreaseRefinementOptions{}.band);
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}, "crease": {"level": 1}}})")
                  .find("/surface/crease/level: unknown key"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}, "crease": {"levels": 9}}})")
                  .find("/surface/crease/levels"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {"mesh_file": "m.obj", "crease": {"levels": 1}}})")
                  .find("/surface/crease/levels: crease refinement needs a `shape`"),
              std::string::npos);
}

TEST(Scene, CreaseRefinedSurfaceGivesTheTrackerItsUnrefinedXi) {
    const std::string shape =
        R"("shape": {"type": "dumbbell", "bulb_radius": 0.3, "handle_radius": 0.2, "blend_radius": 0})";
    const Scene plain =
        parse_scene(R"({"surface": {"edge_length": 0.04, )" + shape + "}}", "t.json", ".");
    const Scene refined =
        parse_scene(R"({"surface": {"edge_length": 0.04, "crease": {"levels": 1}, )" + shape + "}}",
                    "t.json", ".");
    double xi_plain = -1.0, xi_refined = -1.0;
    const tracker::SurfaceMesh plain_mesh = build_initial_surface(plain, nullptr, &xi_plain);
    const tracker::SurfaceMesh refined_mesh = build_initial_surface(refined, nullptr, &xi_refined);
    EXPECT_EQ(xi_plain, 0.0);  // measure it from the mesh, as the paper does
    EXPECT_DOUBLE_EQ(xi_refined, tracker::edge_length_stats(plain_mesh).mean);
    EXPECT_GT(refined_mesh.count_live_triangles(), plain_mesh.count_live_triangles());
    EXPECT_DOUBLE_EQ(tracker_options(refined, xi_refined).characteristic_length, xi_refined);
}

TEST(Scene, FixedCharacteristicLengthWinsOverTheMeshedOne) {
    const Scene s = parse_scene(
        R"({"surface": {"shape": {"type": "sphere"}}, "tracker": {"characteristic_length": 0.05}})",
        "t.json", ".");
    EXPECT_DOUBLE_EQ(tracker_options(s, 0.03).characteristic_length, 0.05);
    EXPECT_NE(
        error_of(
            R"({"surface": {"shape": {"type": "sphere"}}, "tracker": {"characteristic_length": -1}})")
            .find("/tracker/characteristic_length: expected a number >= 0"),
        std::string::npos);
}

TEST(Scene, ErrorsNameTheJsonPath) {
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}}, "fluids": {}})")
                  .find("test.json: /fluids: unknown key"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}}, "tracker": {"remesh": {"max_edge_fractoin": 2}}})")
                  .find("/tracker/remesh/max_edge_fractoin: unknown key"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}}, "tracker": {"remesh": {"max_edge_fraction": -1}}})")
                  .find("/tracker/remesh/max_edge_fraction: expected a number > 0"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere", "radius": "big"}}})")
                  .find("/surface/shape/radius: expected a number > 0, got a string"),
              std::string::npos);
    EXPECT_NE(
        error_of(
            R"({"surface": {"shape": {"type": "union", "shapes": [{"type": "sphere"}, {"type": "cone"}]}}})")
            .find("/surface/shape/shapes/1/type: expected one of"),
        std::string::npos);
    EXPECT_NE(
        error_of(
            R"({"surface": {"shape": {"type": "torus", "major_radius": 0.1, "minor_radius": 0.2}}})")
            .find("/surface/shape: torus major_radius - minor_radius"),
        std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "box", "min": [0, 0]}}})")
                  .find("/surface/shape/min: expected an array of 3 numbers"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}}, "tracker": {"proximity_fraction": 0.5}})")
                  .find("/tracker/topology/merge_distance_fraction: must exceed proximity_fraction"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {}})").find("/surface: give either `shape` or `mesh_file`"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"time": {"frames": 2.5}, "surface": {"shape": {"type": "sphere"}}})")
                  .find("/time/frames: expected an integer"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"flow": {"type": "wind"}, "surface": {"shape": {"type": "sphere"}}})")
                  .find("/flow/type: expected one of \"fluid\", \"enright\", \"normal_speed\", "
                        "\"mean_curvature\", \"curl_noise\", \"rigid\", \"expression\", "
                        "\"none\", got \"wind\""),
              std::string::npos);
    EXPECT_NE(error_of("[1, 2]").find("/: expected an object"), std::string::npos);
}

TEST(Scene, BoundariesAreATypeOrAnObjectAndErrorsNameTheFace) {
    // Issue 39: /fluid/boundaries/<face> is a type name, or an object with the type's data.
    const Scene s = parse_scene(
        R"({"surface": {"shape": {"type": "sphere"}}, "fluid": {"boundaries": {
             "y_min": "no_slip",
             "y_max": {"type": "no_slip", "velocity": [0.5, 0, 0]},
             "x_min": {"type": "inflow", "inflow": {"speed": 0.2, "profile": "parabolic",
                       "region": "disc", "centre": [0, 0.5, 0.5], "radius": 0.1}},
             "x_max": {"type": "outflow", "pressure": 10}}}})",
        "t.json", ".");
    const fluid::BoundaryOptions& b = s.fluid.boundaries;
    EXPECT_EQ(b.y_min.type, fluid::BoundaryType::no_slip);
    EXPECT_EQ(b.y_max.velocity.x(), 0.5);
    EXPECT_EQ(b.x_min.type, fluid::BoundaryType::inflow);
    EXPECT_EQ(b.x_min.inflow.profile, fluid::InflowProfile::parabolic);
    EXPECT_EQ(b.x_min.inflow.region, fluid::InflowRegion::disc);
    EXPECT_EQ(b.x_min.inflow.radius, 0.1);
    EXPECT_EQ(b.x_max.type, fluid::BoundaryType::outflow);
    EXPECT_EQ(b.x_max.pressure, 10.0);
    EXPECT_EQ(b.z_min.type, fluid::BoundaryType::free_slip);
    const std::string sphere = R"({"surface": {"shape": {"type": "sphere"}}, "fluid": )";
    EXPECT_NE(error_of(sphere + R"({"boundaries": {"x_min": "open"}}})")
                  .find("/fluid/boundaries/x_min: expected one of \"free_slip\""),
              std::string::npos);
    EXPECT_NE(error_of(sphere + R"({"boundaries": {"x_min": {"type": "inflow", "speeed": 1}}}})")
                  .find("/fluid/boundaries/x_min/speeed: unknown key"),
              std::string::npos);
    EXPECT_NE(error_of(sphere + R"({"boundaries": {"x_min": {"type": "inflow", "inflow": {"speed": 1}}}}})")
                  .find("/fluid/boundaries/x_min/inflow/speed: an inflow without an outflow face"),
              std::string::npos);
    EXPECT_NE(error_of(sphere + R"({"boundaries": {"z_max": {"type": "outflow", "velocity": [1, 0, 0]}}}})")
                  .find("/fluid/boundaries/z_max/velocity: only a no_slip wall"),
              std::string::npos)
        << error_of(sphere + R"({"boundaries": {"z_max": {"type": "outflow", "velocity": [1, 0, 0]}}}})");
    EXPECT_NE(error_of(sphere + R"({"walls": {"x_min": "no_slip"}}})").find("/fluid/walls: unknown key"),
              std::string::npos);
    // A periodic face pairs with its opposite; what does not wrap around the box yet (open
    // faces, a surface from a file) is refused when the simulation is set up, naming the face.
    EXPECT_NE(error_of(sphere + R"({"boundaries": {"y_min": "periodic"}}})")
                  .find("/fluid/boundaries/y_max: y_min is periodic and y_max free_slip: a "
                        "periodic face is paired with the opposite face"),
              std::string::npos)
        << error_of(sphere + R"({"boundaries": {"y_min": "periodic"}}})");
    const Scene periodic = parse_scene(
        R"({"flow": {"type": "fluid"}, "surface": {"shape": {"type": "sphere", "center": [0.005, 0.005, 0.005], "radius": 0.002}},
            "domain": {"cells": 8}, "fluid": {"boundaries": {"y_min": "periodic", "y_max": "periodic",
            "z_max": "outflow"}}})",
        "test.json", ".");
    try {
        make_fluid_simulation(periodic);
        FAIL() << "a scene with periodic and outflow faces was set up";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("/fluid/boundaries/y_min: periodic faces are not "
                                             "available together with inflow or outflow faces"),
                  std::string::npos)
            << e.what();
    }
}

/// Semi-implicit surface tension: past the capillary limit only with it, and only with the
/// trilinear vertex velocities it is stable with; each refusal names the field.
TEST(Scene, ImplicitTensionAndTheCapillaryLimitAreCheckedTogether) {
    const std::string fluid =
        R"("flow": {"type": "fluid"}, "surface": {"shape": {"type": "sphere"}}, )";
    EXPECT_NE(error_of("{" + fluid + R"("coupling": {"capillary_safety": 3}})")
                  .find("/coupling/capillary_safety: above 1 the explicit surface tension is "
                        "unstable"),
              std::string::npos);
    EXPECT_NE(error_of("{" + fluid + R"("coupling": {"capillary_safety": 3, "implicit_tension": 1}})")
                  .find("/coupling/implicit_tension: needs /coupling/velocity_interpolation"),
              std::string::npos);
    EXPECT_NE(error_of("{" + fluid + R"("coupling": {"implicit_tension": 1.5}})")
                  .find("/coupling/implicit_tension: expected a number in [0, 1]"),
              std::string::npos);
    EXPECT_NE(error_of("{" + fluid + R"("coupling": {"capillary_safety": 25, "implicit_tension": 1, "velocity_interpolation": "trilinear"}})")
                  .find("/coupling/capillary_safety: expected a number in (0, 20]"),
              std::string::npos);
    const Scene scene = parse_scene(
        "{" + fluid +
            R"("coupling": {"capillary_safety": 3, "implicit_tension": 1, "velocity_interpolation": "trilinear"}})",
        "test.json", ".");
    EXPECT_EQ(scene.coupling.simulation.implicit_tension, 1.0);
    EXPECT_EQ(scene.coupling.simulation.capillary_safety, 3.0);
}

TEST(Scene, OutputKeys) {
    const char* sphere = R"("surface": {"shape": {"type": "sphere"}})";
    const Scene defaults = parse_scene(std::string("{") + sphere + "}", "test.json", ".");
    EXPECT_EQ(defaults.output.length_unit, "mm");
    EXPECT_TRUE(defaults.output.vdb_velocity);
    EXPECT_TRUE(defaults.output.vdb_pressure);
    const Scene set = parse_scene(
        std::string("{") + sphere +
            R"(, "output": {"length_unit": "cm", "vdb_velocity": false, "vdb_pressure": false,
                "density_ramp_voxels": 1.5}})",
        "test.json", ".");
    EXPECT_EQ(set.output.length_unit, "cm");
    EXPECT_FALSE(set.output.vdb_velocity);
    EXPECT_FALSE(set.output.vdb_pressure);
    EXPECT_DOUBLE_EQ(set.output.density_ramp_voxels, 1.5);
    EXPECT_NE(error_of(std::string("{") + sphere + R"(, "output": {"length_unit": "in"}})")
                  .find(R"(/output/length_unit: expected one of "m", "cm", "mm", got "in")"),
              std::string::npos);
    EXPECT_NE(error_of(std::string("{") + sphere +
                       R"(, "output": {"half_width_voxels": 2, "density_ramp_voxels": 5}})")
                  .find("/output/density_ramp_voxels: expected at most 2 · "
                        "/output/half_width_voxels"),
              std::string::npos);
}

TEST(Scene, GeometricFlowKeys) {
    const Scene s = parse_scene(R"({"surface": {"shape": {"type": "sphere"}},
        "flow": {"type": "normal_speed", "normal_speed": {"method": "vertex_normals",
                 "speed": -0.1, "reversal_time": 0.5, "min_area_fraction": 0.2,
                 "face_offsetting": {"expansion": "planes", "max_offset_ratio": 2}}}})",
                                "t.json", ".");
    EXPECT_EQ(s.flow.normal_speed.method, "vertex_normals");
    EXPECT_EQ(s.flow.normal_speed.speed, -0.1);
    EXPECT_EQ(s.flow.normal_speed.reversal_time, 0.5);
    EXPECT_EQ(s.flow.normal_speed.inversion.min_area_fraction, 0.2);
    EXPECT_EQ(s.flow.normal_speed.face_offsetting.expansion, tracker::ExpansionRule::planes);
    EXPECT_EQ(s.flow.normal_speed.face_offsetting.max_offset_ratio, 2.0);
    const Scene c = parse_scene(R"({"surface": {"shape": {"type": "sphere"}},
        "flow": {"type": "curl_noise", "curl_noise": {"seed": 7, "planar": true,
                 "rms_speed": 0.3, "time_frequency": 2}}})",
                                "t.json", ".");
    EXPECT_EQ(c.flow.curl_noise.seed, 7u);
    EXPECT_TRUE(c.flow.curl_noise.planar);
    EXPECT_EQ(c.flow.curl_noise.rms_speed, 0.3);
    EXPECT_EQ(c.flow.curl_noise.time_frequency, 2.0);
    EXPECT_EQ(c.flow.curl_noise.octaves, tracker::CurlNoiseOptions{}.octaves);
    const Scene m = parse_scene(R"({"surface": {"shape": {"type": "sphere"}},
        "flow": {"type": "mean_curvature", "mean_curvature": {"integrator": "heun",
                 "curvature_operator": "quartic_fit", "fit_max_turn": 0.5,
                 "fit_sphere_refit": false}}})",
                                "t.json", ".");
    EXPECT_EQ(m.flow.mean_curvature.integrator, tracker::MeanCurvatureIntegrator::heun);
    EXPECT_EQ(m.flow.mean_curvature.curvature_operator, tracker::CurvatureOperator::quartic_fit);
    EXPECT_EQ(m.flow.mean_curvature.fit_max_turn, 0.5);
    EXPECT_FALSE(m.flow.mean_curvature.fit_sphere_refit);
    EXPECT_EQ(parse_scene(R"({"surface": {"shape": {"type": "sphere"}}, "flow": {"type": "mean_curvature"}})",
                          "t.json", ".")
                  .flow.mean_curvature.curvature_operator,
              tracker::CurvatureOperator::cotangent);
}

TEST(Scene, GeometricFlowErrorsNameTheJsonPath) {
    const std::string sphere = R"("surface": {"shape": {"type": "sphere"}})";
    const auto error_with = [&](const std::string& rest) {
        return error_of("{" + sphere + ", " + rest + "}");
    };
    EXPECT_NE(error_with(R"("flow": {"type": "normal_speed", "normal_speed": {"method": "levelset"}})")
                  .find("/flow/normal_speed/method: expected one of"),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "normal_speed", "normal_speed": {"face_offsetting": {"max_offset_ratio": 0.5}}})")
                  .find("/flow/normal_speed/face_offsetting/max_offset_ratio: expected a number >= 1"),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "mean_curvature", "mean_curvature": {"cfl_number": 0}})")
                  .find("/flow/mean_curvature/cfl_number: expected a number in (0, 1]"),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "mean_curvature", "mean_curvature": {"integrator": "rk4"}})")
                  .find("/flow/mean_curvature/integrator: expected one of"),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "mean_curvature", "mean_curvature": {"curvature_operator": "jet"}})")
                  .find("/flow/mean_curvature/curvature_operator: expected one of"),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "mean_curvature", "mean_curvature": {"fit_max_turn": 0}})")
                  .find("/flow/mean_curvature/fit_max_turn: expected a number > 0"),
              std::string::npos);
    EXPECT_NE(error_with(R"("tracker": {"remesh": {"collapse_preserves_volume": 1}})")
                  .find("/tracker/remesh/collapse_preserves_volume: expected"),
              std::string::npos);
    EXPECT_NE(error_with(R"("tracker": {"remesh": {"collapse_on_fitted_surface": "yes"}})")
                  .find("/tracker/remesh/collapse_on_fitted_surface: expected"),
              std::string::npos);
    EXPECT_NE(error_with(R"("tracker": {"remesh": {"smoothing_fit_degree": 4}})")
                  .find("/tracker/remesh/smoothing_fit_degree: expected an integer in [2, 3]"),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "curl_noise", "curl_noise": {"seed": -1}})")
                  .find("/flow/curl_noise/seed: expected an integer"),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "enright", "curl_noise": {"planar": true}})")
                  .find("/flow/curl_noise: given, but /flow/type is \"enright\""),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "mean_curvature", "exact": {"type": "two_sphere_normal_flow"}})")
                  .find("/flow/exact/type: two_sphere_normal_flow solves /flow/type normal_speed"),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "normal_speed", "normal_speed": {"speed": -0.2}, "exact": {"type": "two_sphere_normal_flow"}})")
                  .find("/flow/exact/type: two_sphere_normal_flow solves"),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "normal_speed", "exact": {"type": "sphere_mean_curvature"}})")
                  .find("/flow/exact/type: sphere_mean_curvature solves /flow/type mean_curvature"),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "mean_curvature", "exact": {"type": "sphere_mean_curvature", "radius": 0.2}}, "time": {"end": 0.02})")
                  .find("/time/end: must be before the sphere's extinction time"),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "normal_speed", "exact": {"radius": 0.3}})")
                  .find("/flow/exact/radius: given, but /flow/exact/type is \"none\""),
              std::string::npos);
    EXPECT_NE(error_with(R"("flow": {"type": "normal_speed", "normal_speed": {"reversal_time": 1}, "exact": {"type": "two_sphere_normal_flow"}}, "time": {"end": 5})")
                  .find("/time/end: past the time the exact two-sphere surface vanishes"),
              std::string::npos);
}

TEST(Scene, PrescribedVelocityFieldKeys) {
    const Scene r = parse_scene(R"J({"surface": {"shape": {"type": "sphere"}},
        "flow": {"type": "rigid", "rigid": {"angular_velocity": [0, 0, 6.283185307179586],
                 "center": [0.5, 0.5, 0.5], "velocity": [0.1, 0, 0]}}})J",
                                "t.json", ".");
    EXPECT_EQ(r.flow.type, "rigid");
    EXPECT_EQ(r.flow.rigid.angular_velocity, Eigen::Vector3d(0, 0, 6.283185307179586));
    EXPECT_EQ(r.flow.rigid.center, Eigen::Vector3d(0.5, 0.5, 0.5));
    EXPECT_EQ(r.flow.rigid.velocity, Eigen::Vector3d(0.1, 0, 0));
    const Scene e = parse_scene(R"J({"surface": {"shape": {"type": "sphere"}},
        "flow": {"type": "expression", "expression": {
                 "velocity": ["-omega*(y - 0.5)", "omega*(x - 0.5)", 0.25],
                 "constants": {"omega": 6.28}}}})J",
                                "t.json", ".");
    EXPECT_EQ(e.flow.expression.velocity[0], "-omega*(y - 0.5)");
    EXPECT_EQ(e.flow.expression.velocity[2], "0.25");  // a number stands for its text
    EXPECT_EQ(e.flow.expression.constants.at("omega"), 6.28);
    const tracker::ExpressionField field(e.flow.expression);
    EXPECT_LT((field.velocity({1.0, 0.5, 0.0}, 0.0) - tracker::Vec3(0, 6.28 * 0.5, 0.25)).norm(),
              1e-15);
    // Defaults: no motion.
    const Scene d = parse_scene(
        R"J({"surface": {"shape": {"type": "sphere"}}, "flow": {"type": "expression"}})J", "t.json",
        ".");
    EXPECT_EQ(d.flow.expression.velocity[1], "0");
    EXPECT_EQ(d.flow.rigid.angular_velocity, Eigen::Vector3d::Zero());
}

TEST(Scene, PrescribedVelocityFieldErrorsNameTheJsonPathAndColumn) {
    const std::string sphere = R"J("surface": {"shape": {"type": "sphere"}})J";
    const auto error_with = [&](const std::string& rest) {
        return error_of("{" + sphere + ", " + rest + "}");
    };
    const auto expect_error = [&](const std::string& rest, const std::string& says) {
        const std::string what = error_with(rest);
        EXPECT_NE(what.find(says), std::string::npos) << "got: " << what;
    };
    expect_error(R"J("flow": {"type": "rigid", "rigid": {"omega": [0, 0, 1]}})J",
                 "/flow/rigid/omega: unknown key (known keys here: angular_velocity, center, "
                 "velocity)");
    expect_error(R"J("flow": {"type": "rigid", "rigid": {"center": [0, 0]}})J",
                 "/flow/rigid/center: expected an array of 3 numbers");
    expect_error(R"J("flow": {"type": "enright", "rigid": {"center": [0, 0, 0]}})J",
                 "/flow/rigid: given, but /flow/type is \"enright\"");
    expect_error(R"J("flow": {"type": "rigid", "expression": {"velocity": ["0", "0", "0"]}})J",
                 "/flow/expression: given, but /flow/type is \"rigid\"");
    expect_error(R"J("flow": {"type": "expression", "expression": {"speed": 1}})J",
                 "/flow/expression/speed: unknown key (known keys here: constants, velocity)");
    expect_error(R"J("flow": {"type": "expression", "expression": {"velocity": ["x", "y"]}})J",
                 "/flow/expression/velocity: expected an array of 3 strings (or numbers), got an "
                 "array of 2");
    expect_error(R"J("flow": {"type": "expression", "expression": {"velocity": ["x", true, "0"]}})J",
                 "/flow/expression/velocity/1: expected a string or a number, got a boolean");
    expect_error(R"J("flow": {"type": "expression", "expression": {"velocity": ["x", "sin(y", "0"]}})J",
                 "/flow/expression/velocity/1: column 6: missing ')' for the call of sin at "
                 "column 1");
    expect_error(R"J("flow": {"type": "expression", "expression": {"velocity": ["0", "0", "2*k"]}})J",
                 "/flow/expression/velocity/2: column 3: unknown name 'k'");
    expect_error(R"J("flow": {"type": "expression", "expression": {"constants": {"k": "1"}}})J",
                 "/flow/expression/constants/k: expected a number, got a string");
    expect_error(R"J("flow": {"type": "expression", "expression": {"constants": {"t": 1}}})J",
                 "/flow/expression/constants/t: ");
    expect_error(R"J("flow": {"type": "expression", "expression": {"constants": {"sin": 1}}})J",
                 "/flow/expression/constants/sin: a built-in name");
    expect_error(R"J("flow": {"type": "spin"})J", "/flow/type: expected one of");
}

TEST(Scene, ExpressionFieldThatIsNotFiniteOnTheSurfaceStopsTheRunNamingIt) {
    Scene scene = parse_scene(R"J({"surface": {"shape": {"type": "sphere", "radius": 0.2},
        "edge_length": 0.1}, "flow": {"type": "expression",
        "expression": {"velocity": ["0", "sqrt(x)", "0"]}}, "output": {"vdb": false}})J",
                              "field.json", ".");
    RunOptions options;
    options.out_dir = (std::filesystem::temp_directory_path() / "meniscus_nan_field").string();
    options.quiet = true;
    options.max_steps = 2;
    const std::atomic<bool> stop{false};
    try {
        run_scene(scene, options, stop);
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("field.json: /flow/expression/velocity/1 (\"sqrt(x)\") is"),
                  std::string::npos)
            << what;
    }
    std::filesystem::remove_all(options.out_dir);
}

TEST(Scene, OnlyMeshFilesOfGeometricFlowsMayBeOpen) {
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "sphere"}, "open": true}})")
                  .find("/surface/open: only a mesh_file can be open"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {"mesh_file": "m.obj", "open": true}, "flow": {"type": "fluid"}})")
                  .find("/surface/open: fluid scenes need a closed surface"),
              std::string::npos);
    EXPECT_TRUE(parse_scene(R"({"surface": {"mesh_file": "m.obj", "open": true}})", "t.json", ".")
                    .surface.open);
}

TEST(Scene, WavyHalfSpaceSlab) {
    const Scene s = parse_scene(R"({"surface": {"shape": {"type": "intersection", "shapes": [
        {"type": "wavy_half_space", "origin": [0.25, 0, 0.5], "amplitude": 0.05,
         "wavelength": 1.0},
        {"type": "box", "min": [-1, -1, 0], "max": [2, 2, 1]}]}}})",
                                "t.json", ".");
    ASSERT_TRUE(s.shape);
    // z = 0.5 + 0.05 cos(2π(x − 0.25)): crest at x = 0.25, trough at x = 0.75.
    EXPECT_LT(s.shape->value({0.25, 0.0, 0.54}), 0.0);
    EXPECT_GT(s.shape->value({0.25, 0.0, 0.56}), 0.0);
    EXPECT_GT(s.shape->value({0.75, 0.0, 0.46}), 0.0);
    EXPECT_LT(s.shape->value({0.75, 0.0, 0.44}), 0.0);
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "wavy_half_space", "wavelength": 0}}})")
                  .find("/surface/shape/wavelength: expected a number > 0"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"surface": {"shape": {"type": "wavy_half_space", "direction": [0, 0, 1]}}})")
                  .find("/surface/shape: wavy half-space direction must be"),
              std::string::npos);
}

TEST(Scene, MeshFileIsRelativeToTheScene) {
    const Scene s = parse_scene(R"({"surface": {"mesh_file": "m.obj"}})", "dir/s.json", "dir");
    EXPECT_EQ(s.surface.mesh_file, "dir/m.obj");
}

TEST(Range, DescribesAndChecks) {
    EXPECT_EQ(Range::positive().describe(), "> 0");
    EXPECT_EQ(Range::at_least(1).describe(), ">= 1");
    EXPECT_EQ(Range::between(0, 1).describe(), "in [0, 1]");
    EXPECT_FALSE(Range::positive().contains(0.0));
    EXPECT_TRUE(Range::non_negative().contains(0.0));
    EXPECT_FALSE(Range::any().contains(std::numeric_limits<double>::quiet_NaN()));
}

}  // namespace
}  // namespace meniscus::app

namespace meniscus::app {
namespace {

TEST(Scene, ShippedReferenceIsUpToDate) {
    std::ifstream in(std::string(MENISCUS_SOURCE_DIR) + "/scenes/README.md");
    ASSERT_TRUE(in) << "scenes/README.md is missing";
    std::ostringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), scene_reference_markdown())
        << "regenerate with: build/app/meniscus scene-reference > scenes/README.md";
}

}  // namespace
}  // namespace meniscus::app
