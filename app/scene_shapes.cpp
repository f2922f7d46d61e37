#include "app/scene_shapes.h"

#include "app/json_fields.h"

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace meniscus::app {

using tracker::ShapePtr;
using Vec3 = Eigen::Vector3d;

namespace {

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
struct PerturbedCylinderParams {
    Vec3 center = Vec3::Zero();
    Vec3 axis = Vec3::UnitX();
    double radius = 0.1;
    double height = 1.0;
    double amplitude = 0.01;
    double wavelength = 0.9;
};
struct TorusParams {
    Vec3 center = Vec3::Zero();
    Vec3 axis = Vec3::UnitZ();
    double major_radius = 0.3;
    double minor_radius = 0.1;
};
struct WavyHalfSpaceParams {
    Vec3 origin = Vec3::Zero();
    Vec3 up = Vec3::UnitZ();
    Vec3 direction = Vec3::UnitX();
    double amplitude = 0.01;
    double wavelength = 1.0;
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
void visit_fields(V& v, PerturbedCylinderParams& p) {
    v.vec3("center", p.center, Range::any(), "m", "centre of the axis segment");
    v.vec3("axis", p.axis, Range::any(), "", "axis direction (normalized)");
    v.number("radius", p.radius, Range::positive(), "m", "mean radius R");
    v.number("height", p.height, Range::positive(), "m", "length along the axis (capped)");
    v.number("amplitude", p.amplitude, Range{0.0, 1.0, false, true}, "",
             "relative radius perturbation ε: r(s) = R(1 + ε cos(2πs/λ))");
    v.number("wavelength", p.wavelength, Range::positive(), "m", "perturbation wavelength λ");
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

template <typename V>
void visit_fields(V& v, WavyHalfSpaceParams& p) {
    v.vec3("origin", p.origin, Range::any(), "m",
           "a crest on the mean plane: the surface passes through origin + amplitude·up");
    v.vec3("up", p.up, Range::any(), "",
           "outward normal of the mean plane (normalized); the region lies below");
    v.vec3("direction", p.direction, Range::any(), "",
           "wave direction (its component along `up` is removed, then normalized)");
    v.number("amplitude", p.amplitude, Range::non_negative(), "m",
             "A: the surface is s = A cos(2π t / λ), s along `up`, t along `direction`, both "
             "measured from `origin`");
    v.number("wavelength", p.wavelength, Range::positive(), "m", "λ");
}

const std::vector<std::string> SHAPE_TYPES = {
    "sphere", "ellipsoid", "box",   "cylinder",     "perturbed_cylinder",
    "torus",  "dumbbell",  "wavy_half_space", "union", "intersection", "difference"};

/// Limits on a shape tree: every evaluation of φ visits every primitive, and a combination's
/// gradient re-evaluates its subtree at every level, so size and depth set the meshing cost.
constexpr int MAX_SHAPE_DEPTH = 16;
constexpr int MAX_SHAPE_PRIMITIVES = 256;

/// Counts of the tree parsed so far (primitives) and where parsing is (depth).
struct ShapeBudget {
    int primitives = 0;
};

ShapePtr parse_shape_at(const nlohmann::json& j, const std::string& path, int depth,
                        ShapeBudget& budget);

template <typename Params>
Params read_params(JsonReader& r) {
    Params p;
    visit_fields(r, p);
    r.finish();
    return p;
}

std::vector<ShapePtr> parse_shape_list(JsonReader& r, const char* key, int depth,
                                       ShapeBudget& budget) {
    r.known(key);
    if (!r.has(key))
        r.fail(key, "required: an array of shapes");
    const nlohmann::json& list = r.raw(key);
    if (!list.is_array() || list.empty())
        r.fail(key, "expected a non-empty array of shapes");
    std::vector<ShapePtr> shapes;
    for (size_t i = 0; i < list.size(); ++i)
        shapes.push_back(parse_shape_at(list[i], r.path() + "/" + key + "/" + std::to_string(i),
                                        depth + 1, budget));
    return shapes;
}

ShapePtr parse_shape_at(const nlohmann::json& j, const std::string& path, int depth,
                        ShapeBudget& budget) {
    if (depth > MAX_SHAPE_DEPTH)
        throw SceneError(path + ": shapes nested more than " + std::to_string(MAX_SHAPE_DEPTH) +
                         " deep (union, intersection and difference inside each other)");
    JsonReader r(j, path);
    std::string type;
    r.choice("type", type, SHAPE_TYPES, "");
    if (type.empty())
        r.fail("type",
               "required: one of sphere, ellipsoid, box, cylinder, perturbed_cylinder, torus, "
               "dumbbell, wavy_half_space, union, intersection, difference");
    const bool combination = type == "union" || type == "intersection" || type == "difference";
    if (!combination && ++budget.primitives > MAX_SHAPE_PRIMITIVES)
        throw SceneError(path + ": more than " + std::to_string(MAX_SHAPE_PRIMITIVES) +
                         " primitive shapes in one shape tree");
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
        if (type == "perturbed_cylinder") {
            const auto p = read_params<PerturbedCylinderParams>(r);
            return tracker::make_perturbed_cylinder(p.center, p.axis, p.radius, p.height,
                                                    p.amplitude, p.wavelength);
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
        if (type == "wavy_half_space") {
            const auto p = read_params<WavyHalfSpaceParams>(r);
            return tracker::make_wavy_half_space(p.origin, p.up, p.direction, p.amplitude,
                                                 p.wavelength);
        }
        if (type == "union" || type == "intersection") {
            auto shapes = parse_shape_list(r, "shapes", depth, budget);
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
        ShapePtr a = parse_shape_at(r.raw("a"), path + "/a", depth + 1, budget);
        ShapePtr b = parse_shape_at(r.raw("b"), path + "/b", depth + 1, budget);
        r.finish();
        return tracker::make_difference(std::move(a), std::move(b));
    } catch (const std::invalid_argument& e) {
        throw SceneError(path + ": " + e.what());
    }
}

}  // namespace

ShapePtr parse_shape(const nlohmann::json& j, const std::string& path) {
    ShapeBudget budget;
    return parse_shape_at(j, path, 1, budget);
}

void add_shape_reference(std::vector<ReferenceWriter::Table>& tables) {
    // The shape tree: one table per shape type.
    ReferenceWriter shape(tables, "/surface/shape",
                          "An implicit shape: an object with `type` and that type's keys. "
                          "`union`/`intersection` take `shapes` (array of shapes), "
                          "`difference` takes `a` minus `b`.");
    shape.add({"type", "string", "(required)", "",
               "sphere, ellipsoid, box, cylinder, perturbed_cylinder, torus, dumbbell, "
               "wavy_half_space, union, intersection, difference"});
    SphereParams sp;
    EllipsoidParams ep;
    BoxParams bp;
    CylinderParams cp;
    TorusParams tp;
    PerturbedCylinderParams pp;
    DumbbellParams dp;
    ReferenceWriter s1(tables, "/surface/shape (type sphere)", "");
    visit_fields(s1, sp);
    ReferenceWriter s2(tables, "/surface/shape (type ellipsoid)", "");
    visit_fields(s2, ep);
    ReferenceWriter s3(tables, "/surface/shape (type box)", "");
    visit_fields(s3, bp);
    ReferenceWriter s4(tables, "/surface/shape (type cylinder)", "");
    visit_fields(s4, cp);
    ReferenceWriter s7(tables, "/surface/shape (type perturbed_cylinder)", "");
    visit_fields(s7, pp);
    ReferenceWriter s5(tables, "/surface/shape (type torus)", "");
    visit_fields(s5, tp);
    ReferenceWriter s6(tables, "/surface/shape (type dumbbell)", "");
    visit_fields(s6, dp);
    WavyHalfSpaceParams wp;
    ReferenceWriter s8(tables, "/surface/shape (type wavy_half_space)",
                       "Unbounded: the region below a cosine-perturbed plane. Use it inside an "
                       "`intersection` with a box (e.g. a liquid slab for a capillary wave; "
                       "the box may extend past the fluid domain's walls).");
    visit_fields(s8, wp);
}

}  // namespace meniscus::app
