#include "app/scene.h"

#include "app/json_fields.h"

#include <fstream>
#include <sstream>

namespace meniscus::app {

namespace {

using tracker::ShapePtr;
using Vec3 = Eigen::Vector3d;

const std::vector<std::string> FLOW_TYPES = {"enright", "none"};

template <typename V>
void visit_fields(V& v, SurfaceOptions& o) {
    v.number("edge_length", o.edge_length, Range::positive(), "m",
             "requested mean edge length ξ of the mesh generated from `shape`");
    v.text("mesh_file", o.mesh_file,
           "OBJ or PLY file with the initial surface (relative to the scene file); "
           "closed, consistently oriented, no degenerate or duplicate triangles");
    v.integer("remesh_iterations", o.remesh_iterations, Range::between(0, 100), "",
              "isotropic remeshing passes after marching tetrahedra");
}

template <typename V>
void visit_fields(V& v, FlowOptions& o) {
    v.choice("type", o.type, FLOW_TYPES,
             "velocity field: `enright` (paper §4.3 deformation test, RK4), `none`");
    v.number("period", o.period, Range::positive(), "s",
             "Enright period T; the field is modulated by sin(2πt/T)");
}

template <typename V>
void visit_fields(V& v, TimeOptions& o) {
    v.number("end", o.end, Range::positive(), "s", "simulated end time");
    v.integer("frames", o.frames, Range::between(1, 1000000), "",
              "frames after the initial one, evenly spaced in time");
    v.number("dt", o.dt, Range::positive(), "s",
             "maximum time step (shortened to land exactly on frame times)");
}

template <typename V>
void visit_fields(V& v, OutputOptions& o) {
    v.boolean("ply", o.ply, "write surface_NNNN.ply (binary little-endian)");
    v.boolean("ply_velocity", o.ply_velocity, "include per-vertex velocity vx, vy, vz in the PLY");
    v.boolean("obj", o.obj, "also write surface_NNNN.obj");
    v.boolean("vdb", o.vdb,
              "write fields_NNNN.vdb with grids `surface` (level set) and `density` (fog)");
    v.number("voxel_size", o.voxel_size, Range::non_negative(), "m",
             "VDB voxel size; 0 = half of /surface/edge_length");
    v.number("half_width_voxels", o.half_width_voxels, Range::at_least(1.0), "voxels",
             "narrow-band half width of the `surface` level set");
}

template <typename V>
void visit_fields(V& v, tracker::CollisionOptions& o) {
    v.boolean("repulsion", o.repulsion, "proximity repulsion impulses before CCD (paper §3.8)");
    v.integer("impulse_sweeps", o.impulse_sweeps, Range::between(0, 100), "",
              "sweeps of individual CCD impulses before impact zones (paper: 3)");
    v.integer("max_impact_zone_iterations", o.max_impact_zone_iterations, Range::between(1, 10000),
              "", "bound on impact-zone detect/solve rounds");
    v.integer("max_rigid_zone_iterations", o.max_rigid_zone_iterations, Range::between(0, 10000),
              "", "bound on rigid impact-zone rounds (fallback)");
    v.integer("max_step_shortenings", o.max_step_shortenings, Range::between(0, 60), "",
              "halvings of the motion tried before the mesh is left in place (last fallback)");
}

template <typename V>
void visit_fields(V& v, tracker::RemeshOptions& o) {
    v.boolean("split", o.split, "split edges longer than α (§3.5.1)");
    v.boolean("flip", o.flip, "flip non-Delaunay edges (§3.5.2)");
    v.boolean("collapse", o.collapse, "collapse edges shorter than β (§3.5.3)");
    v.boolean("smooth", o.smooth, "null-space smoothing (§3.6.1)");
    v.number("max_edge_fraction", o.max_edge_fraction, Range::positive(), "ξ",
             "α: maximum edge length");
    v.number("min_edge_fraction", o.min_edge_fraction, Range::positive(), "ξ",
             "β: minimum edge length");
    v.number("max_volume_change_fraction", o.max_volume_change_fraction, Range::positive(), "ξ³",
             "γ: largest volume change of one flip or collapse");
    v.integer("max_split_passes", o.max_split_passes, Range::between(1, 100), "",
              "sweeps over long edges per step");
    v.integer("max_collapse_passes", o.max_collapse_passes, Range::between(1, 100), "",
              "sweeps over short edges per step");
    v.integer("max_flip_sweeps", o.max_flip_sweeps, Range::between(1, 100), "",
              "flip sweeps per step (paper: 5)");
    v.number("min_flip_length_decrease_fraction", o.min_flip_length_decrease_fraction,
             Range{0.0, 1.0, false, true}, "", "a flip must shorten the edge by this fraction");
    v.integer("collapse_position_attempts", o.collapse_position_attempts, Range::between(1, 100),
              "", "collapse trajectories tried from the butterfly position towards the midpoint");
    v.number("max_normal_change_degrees", o.max_normal_change_degrees,
             Range{0.0, 180.0, true, false}, "degrees",
             "largest triangle normal change allowed by a collapse or flip");
    v.number("ridge_eigenvalue_ratio", o.ridge_eigenvalue_ratio, Range{0.0, 1.0, true, true}, "",
             "quadric metric λ₂/λ₁ above which a vertex is on a ridge");
    v.number("corner_eigenvalue_ratio", o.corner_eigenvalue_ratio, Range{0.0, 1.0, true, true}, "",
             "quadric metric λ₃/λ₁ above which a vertex is a corner");
    v.integer("smoothing_iterations", o.smoothing_iterations, Range::between(0, 100), "",
              "null-space smoothing steps per improvement");
    v.number("smoothing_step_fraction", o.smoothing_step_fraction, Range{0.0, 1.0, true, false}, "",
             "fraction of the smoothing displacement applied per step");
}

template <typename V>
void visit_fields(V& v, tracker::TopologyOptions& o) {
    v.boolean("allow_merging", o.allow_merging, "zipper proximal edge pairs (§3.7)");
    v.boolean("allow_separation", o.allow_separation,
              "remove degenerate tetrahedra and split singular vertices (§3.6)");
    v.number("merge_distance_fraction", o.merge_distance_fraction, Range::positive(), "ξ",
             "edge pairs closer than this merge (must exceed /tracker/proximity_fraction)");
    v.integer("max_zipper_alignments", o.max_zipper_alignments, Range::between(1, 4), "",
              "closed-form zipper alignments tried per pair");
    v.number("merge_spacing_fraction", o.merge_spacing_fraction, Range::non_negative(), "ξ",
             "within one step, pairs closer than this to a merge already made wait (0 = none)");
    v.section("separation", "separation of pinched surfaces", [&](auto& r) {
        r.number("nudge_fraction", o.separation.nudge_fraction, Range{0.0, 0.5, true, true}, "",
                 "copies of a singular vertex move this fraction towards their fan's centroid");
        r.integer("max_nudge_halvings", o.separation.max_nudge_halvings, Range::between(0, 60), "",
                  "halvings of the nudge tried when the nudged fans would intersect");
    });
}

template <typename V>
void visit_fields(V& v, tracker::TrackerOptions& o) {
    v.boolean("improve_mesh", o.improve_mesh, "mesh improvement on/off (paper §3.3 switch)");
    v.boolean("allow_topology_changes", o.allow_topology_changes,
              "merging and pinch-off on/off (paper §3.3 switch)");
    v.boolean("collision_safety", o.collision_safety,
              "keep the mesh intersection-free (paper §3.3 switch; off shows why it exists)");
    v.number("proximity_fraction", o.proximity_fraction, Range::positive(), "ξ",
             "repulsion distance ε_p as a fraction of the initial mean edge length ξ");
    v.boolean("verify_intersection_free", o.verify_intersection_free,
              "run the exact static self-intersection test after every step and report it");
    v.section("collision", "collision resolution bounds",
              [&](auto& r) { visit_fields(r, o.collision); });
    v.section("remesh", "mesh improvement", [&](auto& r) { visit_fields(r, o.remesh); });
    v.section("topology", "topology changes", [&](auto& r) { visit_fields(r, o.topology); });
}

template <typename V>
void visit_fields(V& v, Scene& s) {
    v.text("name", s.name, "scene name, used in logs");
    v.text("description", s.description, "free text");
    v.section("surface", "the initial surface: `shape` (implicit) or `mesh_file`", [&](auto& r) {
        visit_fields(r, s.surface);
        r.known("shape");  // the shape tree is parsed by parse_shape()
    });
    v.section("tracker", "the explicit surface tracker",
              [&](auto& r) { visit_fields(r, s.tracker); });
    v.section("flow", "the velocity field that moves the surface",
              [&](auto& r) { visit_fields(r, s.flow); });
    v.section("time", "simulated time and frames", [&](auto& r) { visit_fields(r, s.time); });
    v.section("output", "per-frame files", [&](auto& r) { visit_fields(r, s.output); });
}

// ---- shape trees --------------------------------------------------------------------------

struct SphereParams {
    Vec3 center = Vec3::Zero();
    double radius = 0.2;
};
struct EllipsoidParams {
    Vec3 center = Vec3::Zero();
    Vec3 radii = Vec3(0.3, 0.2, 0.2);
};
struct BoxParams {
    Vec3 min = Vec3::Constant(-0.2);
    Vec3 max = Vec3::Constant(0.2);
};
struct CylinderParams {
    Vec3 center = Vec3::Zero();
    Vec3 axis = Vec3::UnitZ();
    double radius = 0.1;
    double height = 0.5;
};
struct TorusParams {
    Vec3 center = Vec3::Zero();
    Vec3 axis = Vec3::UnitZ();
    double major_radius = 0.3;
    double minor_radius = 0.1;
};
/// Defaults: a Sethian-style dumbbell sized so that, under mean-curvature flow, the handle
/// pinches off before t = 0.025 while the bulbs survive (paper §4.2, Fig. 4.3).
struct DumbbellParams {
    Vec3 center = Vec3::Zero();
    double bulb_radius = 0.4;
    double separation = 1.0;
    double handle_radius = 0.2;
    double blend_radius = 0.05;
};

template <typename V>
void visit_fields(V& v, SphereParams& p) {
    v.vec3("center", p.center, Range::any(), "m", "centre");
    v.number("radius", p.radius, Range::positive(), "m", "radius");
}
template <typename V>
void visit_fields(V& v, EllipsoidParams& p) {
    v.vec3("center", p.center, Range::any(), "m", "centre");
    v.vec3("radii", p.radii, Range::positive(), "m", "semi-axes along x, y, z");
}
template <typename V>
void visit_fields(V& v, BoxParams& p) {
    v.vec3("min", p.min, Range::any(), "m", "minimum corner");
    v.vec3("max", p.max, Range::any(), "m", "maximum corner (> min in every axis)");
}
template <typename V>
void visit_fields(V& v, CylinderParams& p) {
    v.vec3("center", p.center, Range::any(), "m", "centre of the axis segment");
    v.vec3("axis", p.axis, Range::any(), "", "axis direction (normalized)");
    v.number("radius", p.radius, Range::positive(), "m", "radius");
    v.number("height", p.height, Range::positive(), "m", "length along the axis (capped)");
}
template <typename V>
void visit_fields(V& v, TorusParams& p) {
    v.vec3("center", p.center, Range::any(), "m", "centre");
    v.vec3("axis", p.axis, Range::any(), "", "axis of symmetry");
    v.number("major_radius", p.major_radius, Range::positive(), "m",
             "radius of the tube's centre circle");
    v.number("minor_radius", p.minor_radius, Range::positive(), "m",
             "tube radius (< major_radius)");
}
template <typename V>
void visit_fields(V& v, DumbbellParams& p) {
    v.vec3("center", p.center, Range::any(), "m", "centre (the handle runs along x)");
    v.number("bulb_radius", p.bulb_radius, Range::positive(), "m", "radius of the two balls");
    v.number("separation", p.separation, Range::positive(), "m", "distance between ball centres");
    v.number("handle_radius", p.handle_radius, Range::positive(), "m",
             "handle radius (< bulb_radius)");
    v.number("blend_radius", p.blend_radius, Range::non_negative(), "m",
             "smooth-minimum blend where handle meets balls");
}

const std::vector<std::string> SHAPE_TYPES = {"sphere",   "ellipsoid",    "box",
                                              "cylinder", "torus",        "dumbbell",
                                              "union",    "intersection", "difference"};

template <typename Params>
Params read_params(JsonReader& r) {
    Params p;
    visit_fields(r, p);
    r.finish();
    return p;
}

ShapePtr parse_shape(const nlohmann::json& j, const std::string& path);

std::vector<ShapePtr> parse_shape_list(JsonReader& r, const char* key) {
    r.known(key);
    if (!r.has(key))
        r.fail(key, "required: an array of shapes");
    const nlohmann::json& list = r.raw(key);
    if (!list.is_array() || list.empty())
        r.fail(key, "expected a non-empty array of shapes");
    std::vector<ShapePtr> shapes;
    for (size_t i = 0; i < list.size(); ++i)
        shapes.push_back(parse_shape(list[i], r.path() + "/" + key + "/" + std::to_string(i)));
    return shapes;
}

ShapePtr parse_shape(const nlohmann::json& j, const std::string& path) {
    JsonReader r(j, path);
    std::string type;
    r.choice("type", type, SHAPE_TYPES, "");
    if (type.empty())
        r.fail("type",
               "required: one of sphere, ellipsoid, box, cylinder, torus, "
               "dumbbell, union, intersection, difference");
    try {
        if (type == "sphere") {
            const auto p = read_params<SphereParams>(r);
            return tracker::make_sphere(p.center, p.radius);
        }
        if (type == "ellipsoid") {
            const auto p = read_params<EllipsoidParams>(r);
            return tracker::make_ellipsoid(p.center, p.radii);
        }
        if (type == "box") {
            const auto p = read_params<BoxParams>(r);
            return tracker::make_box(p.min, p.max);
        }
        if (type == "cylinder") {
            const auto p = read_params<CylinderParams>(r);
            return tracker::make_cylinder(p.center, p.axis, p.radius, p.height);
        }
        if (type == "torus") {
            const auto p = read_params<TorusParams>(r);
            return tracker::make_torus(p.center, p.axis, p.major_radius, p.minor_radius);
        }
        if (type == "dumbbell") {
            const auto p = read_params<DumbbellParams>(r);
            return tracker::make_dumbbell(p.center, p.bulb_radius, p.separation, p.handle_radius,
                                          p.blend_radius);
        }
        if (type == "union" || type == "intersection") {
            auto shapes = parse_shape_list(r, "shapes");
            r.finish();
            return type == "union" ? tracker::make_union(std::move(shapes))
                                   : tracker::make_intersection(std::move(shapes));
        }
        // difference
        r.known("a");
        r.known("b");
        if (!r.has("a"))
            r.fail("a", "required: the shape to subtract from");
        if (!r.has("b"))
            r.fail("b", "required: the shape to subtract");
        ShapePtr a = parse_shape(r.raw("a"), path + "/a");
        ShapePtr b = parse_shape(r.raw("b"), path + "/b");
        r.finish();
        return tracker::make_difference(std::move(a), std::move(b));
    } catch (const std::invalid_argument& e) {
        throw SceneError(path + ": " + e.what());
    }
}

std::string read_file(const std::string& path) {
    std::ifstream in(path);
    if (!in)
        throw SceneError(path + ": cannot open the scene file");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace

Scene parse_scene(const std::string& json_text, const std::string& source,
                  const std::string& base_dir) {
    try {
        nlohmann::json j;
        try {
            j = nlohmann::json::parse(json_text);
        } catch (const nlohmann::json::parse_error& e) {
            throw SceneError(std::string("invalid JSON: ") + e.what());
        }
        Scene scene;
        scene.source_path = source;
        JsonReader root(j, "");
        visit_fields(root, scene);
        // /surface/shape is a tree, parsed separately.
        if (j.contains("surface") && j["surface"].is_object() && j["surface"].contains("shape"))
            scene.shape = parse_shape(j["surface"]["shape"], "/surface/shape");
        root.finish();
        try {
            scene.tracker.validate();
        } catch (const std::invalid_argument& e) {
            throw SceneError(std::string("/tracker/") + e.what());
        }
        if (!scene.shape && scene.surface.mesh_file.empty())
            throw SceneError("/surface: give either `shape` or `mesh_file`");
        if (scene.shape && !scene.surface.mesh_file.empty())
            throw SceneError("/surface: give either `shape` or `mesh_file`, not both");
        if (!scene.surface.mesh_file.empty() && scene.surface.mesh_file.front() != '/' &&
            !base_dir.empty())
            scene.surface.mesh_file = base_dir + "/" + scene.surface.mesh_file;
        return scene;
    } catch (const SceneError& e) {
        throw SceneError(source + ": " + e.what());
    }
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
    visit_fields(root, defaults);
    {
        // The shape tree: one table per shape type.
        ReferenceWriter shape(tables, "/surface/shape",
                              "An implicit shape: an object with `type` and that type's keys. "
                              "`union`/`intersection` take `shapes` (array of shapes), "
                              "`difference` takes `a` minus `b`.");
        shape.add(
            {"type", "string", "(required)", "",
             "sphere, ellipsoid, box, cylinder, torus, dumbbell, union, intersection, difference"});
        SphereParams sp;
        EllipsoidParams ep;
        BoxParams bp;
        CylinderParams cp;
        TorusParams tp;
        DumbbellParams dp;
        ReferenceWriter s1(tables, "/surface/shape (type sphere)", "");
        visit_fields(s1, sp);
        ReferenceWriter s2(tables, "/surface/shape (type ellipsoid)", "");
        visit_fields(s2, ep);
        ReferenceWriter s3(tables, "/surface/shape (type box)", "");
        visit_fields(s3, bp);
        ReferenceWriter s4(tables, "/surface/shape (type cylinder)", "");
        visit_fields(s4, cp);
        ReferenceWriter s5(tables, "/surface/shape (type torus)", "");
        visit_fields(s5, tp);
        ReferenceWriter s6(tables, "/surface/shape (type dumbbell)", "");
        visit_fields(s6, dp);
    }
    return "# Scene file reference\n\nGenerated by `meniscus scene-reference`; every default "
           "shown is the one in the options struct.\n\n" +
           ReferenceWriter::markdown(tables);
}

}  // namespace meniscus::app
