#include "app/scene.h"

#include "app/json_fields.h"
#include "app/json_text.h"
#include "app/scene_schema.h"
#include "app/scene_shapes.h"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace meniscus::app {

namespace {

/// A scene file larger than this is refused before it is read (scenes are small; meshes go in
/// mesh_file).
constexpr std::uintmax_t MAX_SCENE_FILE_BYTES = 16u << 20;
/// Curl noise: most modes in total (octaves × modes_per_octave; the shipped scenes use 24 to
/// 72). A step evaluates every mode four times per vertex: 20 000 modes on 4 000 vertices took
/// 14 s per step, 160 000 modes (16 octaves of 10 000) made two steps on 550 vertices take 46 s.
constexpr long long MAX_CURL_NOISE_MODES = 4096;
/// Most /initial_velocity regions (each is evaluated at every velocity face of the grid).
constexpr size_t MAX_VELOCITY_REGIONS = 64;
/// Deepest nesting of JSON arrays/objects accepted (the deepest shipped scene nests 6).
constexpr int MAX_JSON_DEPTH = 64;

std::vector<VelocityRegion> parse_velocity_regions(const nlohmann::json& j) {
    const std::string path = "/initial_velocity";
    if (!j.is_array())
        throw SceneError(path + ": expected an array of {shape, velocity}");
    if (j.size() > MAX_VELOCITY_REGIONS)
        throw SceneError(path + ": " + std::to_string(j.size()) + " regions; at most " +
                         std::to_string(MAX_VELOCITY_REGIONS) +
                         " (every velocity face is tested against every region)");
    std::vector<VelocityRegion> regions;
    for (size_t i = 0; i < j.size(); ++i) {
        const std::string item = path + "/" + std::to_string(i);
        JsonReader r(j[i], item);
        VelocityRegion region;
        r.vec3("velocity", region.velocity, Range::any(), "m/s", "");
        r.known("shape");
        if (!r.has("shape"))
            r.fail("shape", "required: the region's shape");
        region.shape = parse_shape(r.raw("shape"), item + "/shape");
        r.finish();
        regions.push_back(std::move(region));
    }
    return regions;
}

/// Calls options.validate(), prefixing its field error with `path`.
template <typename Options>
void validate_at(const Options& options, const std::string& path) {
    try {
        options.validate();
    } catch (const std::invalid_argument& e) {
        throw SceneError(path + e.what());
    }
}

/// Cross-field checks of /flow: each flow's section only with its type, the exact solution
/// only with the flow it solves and within its time of validity.
void validate_flow(const Scene& scene, const nlohmann::json& j) {
    const FlowOptions& f = scene.flow;
    const nlohmann::json* flow = j.contains("flow") ? &j.at("flow") : nullptr;
    for (const char* section :
         {"normal_speed", "mean_curvature", "curl_noise", "rigid", "expression"})
        if (flow && flow->contains(section) && f.type != section)
            throw SceneError(std::string("/flow/") + section + ": given, but /flow/type is \"" +
                             f.type + "\"");
    validate_at(f.normal_speed.face_offsetting, "/flow/normal_speed/face_offsetting/");
    validate_at(f.normal_speed.inversion, "/flow/normal_speed/");
    validate_at(f.mean_curvature, "/flow/mean_curvature/");
    validate_at(f.curl_noise, "/flow/curl_noise/");
    validate_at(f.rigid, "/flow/rigid/");
    validate_at(f.expression, "/flow/expression/");
    const long long modes =
        static_cast<long long>(f.curl_noise.octaves) * f.curl_noise.modes_per_octave;
    if (f.type == "curl_noise" && modes > MAX_CURL_NOISE_MODES)
        throw SceneError("/flow/curl_noise: " + std::to_string(f.curl_noise.octaves) +
                         " octaves x " + std::to_string(f.curl_noise.modes_per_octave) +
                         " modes_per_octave = " + std::to_string(modes) + " modes; at most " +
                         std::to_string(MAX_CURL_NOISE_MODES) +
                         " (every vertex evaluates every mode four times per step)");
    validate_at(f.exact.sampling, "/flow/exact/");
    const ExactSolutionOptions& e = f.exact;
    if (e.type == "none") {
        if (flow && flow->contains("exact") && flow->at("exact").is_object())
            for (const auto& item : flow->at("exact").items())
                if (item.key() != "type")
                    throw SceneError("/flow/exact/" + item.key() +
                                     ": given, but /flow/exact/type is \"none\"");
        return;
    }
    if (e.type == "rigid_motion") {
        if (f.type != "rigid")
            throw SceneError("/flow/exact/type: rigid_motion solves /flow/type rigid");
        for (const char* key : {"center0", "center1", "radius"})
            if (flow->at("exact").contains(key))
                throw SceneError(std::string("/flow/exact/") + key +
                                 ": not used by /flow/exact/type rigid_motion (the exact surface "
                                 "is the initial one, moved)");
        return;
    }
    if (e.type == "two_sphere_normal_flow") {
        if (f.type != "normal_speed" || !(f.normal_speed.speed > 0.0))
            throw SceneError(
                "/flow/exact/type: two_sphere_normal_flow solves /flow/type normal_speed with "
                "/flow/normal_speed/speed > 0 (outward first)");
        if ((e.center1 - e.center0).norm() == 0.0)
            throw SceneError("/flow/exact/center1: must differ from center0");
        tracker::TwoSphereNormalFlow exact = two_sphere_normal_flow(scene, scene.time.end);
        try {
            exact.signed_distance(e.center0, scene.time.end);
        } catch (const std::invalid_argument&) {
            throw SceneError("/time/end: past the time the exact two-sphere surface vanishes");
        }
        return;
    }
    // sphere_mean_curvature
    if (f.type != "mean_curvature")
        throw SceneError("/flow/exact/type: sphere_mean_curvature solves /flow/type mean_curvature");
    if (!(scene.time.end < 0.25 * e.radius * e.radius))
        throw SceneError("/time/end: must be before the sphere's extinction time R0²/4 = " +
                         std::to_string(0.25 * e.radius * e.radius) + " s");
}

std::string read_file(const std::string& path) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (std::filesystem::is_directory(status))
        throw SceneError(path + ": is a directory, not a scene file");
    std::ifstream in(path);
    if (!in)
        throw SceneError(path + ": cannot open the scene file");
    const auto size = std::filesystem::is_regular_file(status)
                          ? std::filesystem::file_size(path, ec)
                          : std::uintmax_t{0};
    if (!ec && size > MAX_SCENE_FILE_BYTES)
        throw SceneError(path + ": " + std::to_string(size) +
                         " bytes is too large for a scene file (at most " +
                         std::to_string(MAX_SCENE_FILE_BYTES) + "; meshes go in mesh_file)");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace

Scene parse_scene(const std::string& json_text, const std::string& source,
                  const std::string& base_dir) {
    try {
        const int depth = json_nesting_depth(json_text);
        if (depth > MAX_JSON_DEPTH)
            throw SceneError("invalid scene: arrays and objects nested " + std::to_string(depth) +
                             " deep (at most " + std::to_string(MAX_JSON_DEPTH) + ")");
        nlohmann::json j;
        try {
            j = nlohmann::json::parse(json_text);
        } catch (const nlohmann::json::out_of_range&) {
            // A number beyond the range of a double (1e400): the library names no position.
            throw SceneError(number_overflow_message(json_text));
        } catch (const nlohmann::json::exception& e) {
            throw SceneError(std::string("invalid JSON: ") + e.what());
        }
        Scene scene;
        scene.source_path = source;
        scene.source_text = json_text;
        JsonReader root(j, "");
        read_scene_fields(root, scene);
        // /surface/shape is a tree, parsed separately.
        if (j.contains("surface") && j["surface"].is_object() && j["surface"].contains("shape"))
            scene.shape = parse_shape(j["surface"]["shape"], "/surface/shape");
        if (j.contains("initial_velocity"))
            scene.initial_velocity = parse_velocity_regions(j["initial_velocity"]);
        root.finish();
        try {
            scene.fluid.validate();
        } catch (const std::invalid_argument& e) {
            throw SceneError(std::string("/fluid/") + e.what());
        }
        if (scene.coupling.simulation.implicit_tension > 0.0 &&
            scene.coupling.simulation.interpolate.method !=
                coupling::VelocityInterpolation::trilinear)
            throw SceneError(
                "/coupling/implicit_tension: needs /coupling/velocity_interpolation "
                "\"trilinear\" (with the default one_sided velocities a drop at 3× the "
                "capillary limit grows unstable)");
        if (scene.coupling.simulation.implicit_tension == 0.0 &&
            scene.coupling.simulation.capillary_safety > 1.0)
            throw SceneError(
                "/coupling/capillary_safety: above 1 the explicit surface tension is unstable; "
                "set /coupling/implicit_tension > 0 (e.g. 1) to go past the capillary limit");
        if (scene.flow.type == "fluid" && scene.coupling.edge_length_cells > 0.0)
            scene.surface.edge_length =
                scene.coupling.edge_length_cells * scene.domain.size.x() / scene.domain.cells;
        validate_flow(scene, j);
        try {
            scene.tracker.validate();
        } catch (const std::invalid_argument& e) {
            throw SceneError(std::string("/tracker/") + e.what());
        }
        if (!scene.shape && scene.surface.mesh_file.empty())
            throw SceneError("/surface: give either `shape` or `mesh_file`");
        if (scene.shape && !scene.surface.mesh_file.empty())
            throw SceneError("/surface: give either `shape` or `mesh_file`, not both");
        if (!scene.time.land_on_frames && scene.flow.type == "fluid")
            throw SceneError("/time/land_on_frames: fluid scenes always land on frame times");
        if (scene.surface.open && scene.shape)
            throw SceneError("/surface/open: only a mesh_file can be open (shapes are closed)");
        if ((scene.surface.crease.levels > 0 || scene.surface.crease.snap) && !scene.shape)
            throw SceneError(
                "/surface/crease/levels: crease refinement needs a `shape` (it "
                "moves new vertices onto the exact surface)");
        if (scene.surface.open && scene.flow.type == "fluid")
            throw SceneError("/surface/open: fluid scenes need a closed surface");
        if (scene.output.density_ramp_voxels > 2.0 * scene.output.half_width_voxels)
            throw SceneError(
                "/output/density_ramp_voxels: expected at most 2 · "
                "/output/half_width_voxels (the ramp must fit in the band)");
        if (!scene.surface.mesh_file.empty() && scene.surface.mesh_file.front() != '/' &&
            !base_dir.empty())
            scene.surface.mesh_file = base_dir + "/" + scene.surface.mesh_file;
        return scene;
    } catch (const SceneError& e) {
        throw SceneError(source + ": " + e.what());
    }
}

tracker::TwoSphereNormalFlow two_sphere_normal_flow(const Scene& scene, double end_time) {
    tracker::TwoSphereNormalFlow exact;
    exact.center0 = scene.flow.exact.center0;
    exact.center1 = scene.flow.exact.center1;
    exact.initial_radius = scene.flow.exact.radius;
    exact.speed = scene.flow.normal_speed.speed;
    // A speed that never reverses: the balls grow for the whole run.
    exact.reversal_time = scene.flow.normal_speed.reversal_time > 0.0
                              ? scene.flow.normal_speed.reversal_time
                              : end_time;
    return exact;
}

Scene load_scene(const std::string& path) {
    const auto slash = path.rfind('/');
    const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash);
    return parse_scene(read_file(path), path, dir);
}

std::string scene_reference_markdown() {
    std::vector<ReferenceWriter::Table> tables;
    Scene defaults;
    ReferenceWriter root(tables, "", "A scene file is one JSON object. Units are SI.");
    describe_scene_fields(root, defaults);
    add_shape_reference(tables);
    {
        ReferenceWriter velocity(
            tables, "/initial_velocity",
            "Array of regions; every velocity face whose centre is inside "
            "`shape` starts with that component of `velocity` (later regions win).");
        velocity.add({"shape", "shape", "(required)", "", "a shape as in /surface/shape"});
        Eigen::Vector3d zero = Eigen::Vector3d::Zero();
        velocity.vec3("velocity", zero, Range::any(), "m/s", "initial velocity inside the shape");
    }
    return "# Scene file reference\n\nGenerated by `meniscus scene-reference`; every default "
           "shown is the one in the options struct.\n\n" +
           ReferenceWriter::markdown(tables);
}

}  // namespace meniscus::app
