#include "tracker/implicit_mesher.h"
#include "tracker/mesh_intersections.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"
#include "tracker/surface_tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace meniscus::tracker {
namespace {

struct ShapeCase {
    std::string name;
    ShapePtr shape;
    double edge_length;
    int components;
    int euler;         ///< expected V − E + F
    double volume;     ///< exact enclosed volume (0 = do not check)
    double min_angle;  ///< required minimum triangle angle, degrees
};

std::string case_name(const testing::TestParamInfo<ShapeCase>& info) {
    return info.param.name;
}

class ImplicitMesherTest : public testing::TestWithParam<ShapeCase> {};

TEST_P(ImplicitMesherTest, ClosedOrientedWellShapedAtRequestedEdgeLength) {
    const ShapeCase& c = GetParam();
    ImplicitMeshOptions options;
    options.edge_length = c.edge_length;
    ImplicitMeshReport report;
    const SurfaceMesh mesh = mesh_implicit_shape(*c.shape, options, &report);

    const auto violations = validate_mesh(mesh);
    EXPECT_TRUE(violations.empty())
        << violations.size()
        << " violations, first: " << (violations.empty() ? "" : violations.front().message);
    EXPECT_NEAR(report.mean_edge_length, c.edge_length, 0.1 * c.edge_length);
    EXPECT_GE(report.min_angle_degrees, c.min_angle);
    EXPECT_EQ(triangle_components(mesh).count, c.components);
    EXPECT_EQ(euler_characteristic(mesh), c.euler);
    EXPECT_LT(report.max_abs_phi, 1e-3 * c.edge_length);
    const double volume = enclosed_volume(mesh);
    EXPECT_GT(volume, 0.0) << "normals must point outward";
    if (c.volume > 0.0) {
        EXPECT_NEAR(volume, c.volume, 0.02 * c.volume);
    }
}

const double PI = M_PI;

INSTANTIATE_TEST_SUITE_P(
    Shapes, ImplicitMesherTest,
    testing::Values(
        ShapeCase{"sphere", make_sphere({0.1, -0.2, 0.3}, 0.2), 0.02, 1, 2, 4.0 / 3.0 * PI * 0.008,
                  25.0},
        ShapeCase{"two_spheres",
                  make_union({make_sphere({-0.25, 0, 0}, 0.2), make_sphere({0.25, 0, 0}, 0.2)}),
                  0.04, 2, 4, 2 * 4.0 / 3.0 * PI * 0.008, 25.0},
        ShapeCase{"ellipsoid", make_ellipsoid({0, 0, 0}, {0.3, 0.2, 0.15}), 0.02, 1, 2,
                  4.0 / 3.0 * PI * 0.3 * 0.2 * 0.15, 20.0},
        ShapeCase{"torus", make_torus({0, 0, 0}, {0, 0, 1}, 0.3, 0.1), 0.02, 1, 0,
                  2 * PI* PI * 0.3 * 0.01, 20.0},
        ShapeCase{"dumbbell", make_dumbbell({0, 0, 0}, 0.4, 1.0, 0.2, 0.1), 0.04, 1, 2, 0.0, 20.0},
        ShapeCase{"cylinder", make_cylinder({0, 0, 0}, {0, 1, 1}, 0.2, 0.6), 0.03, 1, 2,
                  PI * 0.04 * 0.6, 10.0},
        ShapeCase{"box", make_box({-0.2, -0.1, -0.3}, {0.2, 0.1, 0.3}), 0.03, 1, 2, 0.4 * 0.2 * 0.6,
                  10.0},
        ShapeCase{"sphere_minus_box",
                  make_difference(make_sphere({0, 0, 0}, 0.3), make_box({0, 0, 0}, {1, 1, 1})),
                  0.03, 1, 2, 7.0 / 8.0 * 4.0 / 3.0 * PI * 0.027, 10.0}),
    case_name);

TEST(ImplicitMesher, RejectsNonPositiveEdgeLength) {
    ImplicitMeshOptions options;
    options.edge_length = 0.0;
    EXPECT_THROW(mesh_implicit_shape(*make_sphere({0, 0, 0}, 1.0), options), std::invalid_argument);
}

/// |x| of the A2 dumbbell's creases (balls of 0.3 at ±0.5, handle of radius 0.2).
const double A2_CREASE_X = 0.5 - std::sqrt(0.3 * 0.3 - 0.2 * 0.2);

TEST(ImplicitMesher, CreaseRefinementHalvesEdgesNearTheCreaseOnlyWithVerticesOnTheShape) {
    const ShapePtr dumbbell = make_dumbbell({0, 0, 0}, 0.3, 1.0, 0.2, 0.0);
    const double xi = 0.04;
    ImplicitMeshOptions options;
    options.edge_length = xi;
    const SurfaceMesh plain = mesh_implicit_shape(*dumbbell, options);
    options.crease.levels = 1;
    ImplicitMeshReport report;
    const SurfaceMesh refined = mesh_implicit_shape(*dumbbell, options, &report);

    EXPECT_GT(report.crease_vertices, 0);
    EXPECT_GT(report.crease_splits, 0);
    EXPECT_TRUE(validate_mesh(refined).empty());
    EXPECT_TRUE(find_self_intersections(refined).intersection_free());
    EXPECT_EQ(euler_characteristic(refined), 2);
    EXPECT_LT(report.max_abs_phi, 1e-12);  // split points are moved onto φ = 0
    // Edges straddling the crease line are halved; far from it the mesh is the plain one.
    const auto crease_distance = [](const Vec3& p) {
        return std::abs(std::abs(p.x()) - A2_CREASE_X);
    };
    const auto mean_across = [](const SurfaceMesh& m) {  // edges straddling the crease line
        double sum = 0.0;
        int n = 0;
        for (int ei = 0; ei < m.num_edges(); ++ei) {
            if (!m.edge_alive(ei))
                continue;
            const Vec3 a = m.position(m.edge(ei)[0]), b = m.position(m.edge(ei)[1]);
            if ((std::abs(a.x()) - A2_CREASE_X) * (std::abs(b.x()) - A2_CREASE_X) < 0.0) {
                sum += (a - b).norm();
                ++n;
            }
        }
        return n > 0 ? sum / n : 0.0;
    };
    EXPECT_GT(mean_across(plain), 0.8 * xi);
    EXPECT_LT(mean_across(refined), 0.7 * mean_across(plain));
    const auto far_positions = [&](const SurfaceMesh& m) {
        std::vector<std::array<double, 3>> p;
        for (int vi = 0; vi < m.num_vertices(); ++vi)
            if (m.vertex_alive(vi) && crease_distance(m.position(vi)) > 4.0 * xi)
                p.push_back({m.position(vi).x(), m.position(vi).y(), m.position(vi).z()});
        std::sort(p.begin(), p.end());
        return p;
    };
    EXPECT_EQ(far_positions(refined), far_positions(plain));
    EXPECT_GT(refined.count_live_triangles(), plain.count_live_triangles());
}

TEST(ImplicitMesher, CreaseRefinedMeshKeepsItsNominalXiInTheTracker) {
    ImplicitMeshOptions options;
    options.edge_length = 0.04;
    options.crease.levels = 1;
    ImplicitMeshReport report;
    const SurfaceMesh mesh =
        mesh_implicit_shape(*make_dumbbell({0, 0, 0}, 0.3, 1.0, 0.2, 0.0), options, &report);
    ASSERT_GT(report.crease_splits, 0);
    EXPECT_LT(report.mean_edge_length, 0.95 * report.unrefined_mean_edge_length);
    TrackerOptions tracker;
    EXPECT_DOUBLE_EQ(SurfaceTracker(mesh, tracker).characteristic_length(),
                     edge_length_stats(mesh).mean);  // measured: every size would shrink
    EXPECT_EQ(report.nominal_characteristic_length(), report.unrefined_mean_edge_length);
    tracker.characteristic_length = report.nominal_characteristic_length();
    EXPECT_DOUBLE_EQ(SurfaceTracker(mesh, tracker).characteristic_length(),
                     report.unrefined_mean_edge_length);
    tracker.characteristic_length = -1.0;
    try {
        SurfaceTracker bad(mesh, tracker);
        ADD_FAILURE() << "a negative characteristic_length was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("characteristic_length"), std::string::npos);
    }
}

TEST(ImplicitMesher, CreaseRefinementLeavesASmoothShapeAlone) {
    ImplicitMeshOptions options;
    options.edge_length = 0.04;
    const ShapePtr sphere = make_sphere({0, 0, 0}, 0.3);
    const SurfaceMesh plain = mesh_implicit_shape(*sphere, options);
    options.crease.levels = 2;
    ImplicitMeshReport report;
    const SurfaceMesh refined = mesh_implicit_shape(*sphere, options, &report);
    EXPECT_EQ(report.crease_vertices, 0);  // an edge turns by about 0.13 rad < 0.35
    EXPECT_EQ(report.crease_splits, 0);
    EXPECT_EQ(refined.count_live_triangles(), plain.count_live_triangles());
    EXPECT_EQ(report.nominal_characteristic_length(), 0.0);  // the tracker measures the mesh
}

TEST(ImplicitMesher, CreaseOptionsAreValidatedByName) {
    ImplicitMeshOptions options;
    options.edge_length = 0.04;
    const auto message = [&options]() -> std::string {
        try {
            options.validate();
        } catch (const std::invalid_argument& e) {
            return e.what();
        }
        return "";
    };
    options.crease.levels = 5;
    EXPECT_NE(message().find("crease.levels"), std::string::npos);
    options.crease.levels = 1;
    options.crease.angle = 0.0;
    EXPECT_NE(message().find("crease.angle"), std::string::npos);
    options.crease.angle = 0.35;
    options.crease.band = -1.0;
    EXPECT_NE(message().find("crease.band"), std::string::npos);
    options.crease.band = 0.0;
    EXPECT_EQ(message(), "");
}

TEST(ImplicitMesher, ShapeSmallerThanTheGridGivesAClearError) {
    ImplicitMeshOptions options;
    options.edge_length = 1.0;
    // A sphere far below the grid spacing may fall between nodes entirely.
    try {
        mesh_implicit_shape(*make_sphere({0.123, 0.456, 0.789}, 1e-4), options);
        SUCCEED();  // caught by a node: then it must still be a valid (tiny) mesh
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("no surface"), std::string::npos);
    }
}

TEST(ImplicitShapes, PerturbedCylinderRadiusFollowsTheCosine) {
    const auto c = make_perturbed_cylinder({0, 0, 0}, {1, 0, 0}, 0.5, 10.0, 0.1, 2.0);
    EXPECT_NEAR(c->value({0.0, 0.55, 0.0}), 0.0, 1e-15);  // crest at s = 0: r = 0.55
    EXPECT_NEAR(c->value({1.0, 0.0, 0.45}), 0.0, 1e-15);  // trough at s = λ/2: r = 0.45
    EXPECT_LT(c->value({1.0, 0.0, 0.44}), 0.0);
    EXPECT_GT(c->value({5.5, 0.0, 0.0}), 0.0);  // beyond the cap
    EXPECT_THROW(make_perturbed_cylinder({0, 0, 0}, {1, 0, 0}, 0.5, 1.0, 1.0, 2.0),
                 std::invalid_argument);
}

TEST(ImplicitShapes, WavyHalfSpaceFollowsTheCosineWithUnitLipschitzBound) {
    // z < 0.5 + 0.1 cos(2π(x − 0.2)/0.4)
    const auto w = make_wavy_half_space({0.2, 0, 0.5}, {0, 0, 1}, {1, 0, 0}, 0.1, 0.4);
    EXPECT_NEAR(w->value({0.2, 0.3, 0.6}), 0.0, 1e-15);  // crest at x = x0
    EXPECT_NEAR(w->value({0.4, -1.0, 0.4}), 0.0, 1e-15);  // trough half a wavelength on
    EXPECT_LT(w->value({0.4, 0.0, 0.39}), 0.0);
    EXPECT_GT(w->value({0.4, 0.0, 0.41}), 0.0);
    // |φ| never exceeds the distance to the surface: sample points against a dense polyline.
    for (double x = -0.3; x < 0.7; x += 0.037)
        for (double z = 0.2; z < 0.8; z += 0.041) {
            double dist = 1e300;
            for (double s = -1.0; s < 1.5; s += 5e-4) {
                const double zs = 0.5 + 0.1 * std::cos(2 * PI * (s - 0.2) / 0.4);
                dist = std::min(dist, std::hypot(x - s, z - zs));
            }
            EXPECT_LE(std::abs(w->value({x, 0.0, z})), dist + 1e-6) << x << " " << z;
            EXPECT_LE(w->gradient({x, 0.0, z}).norm(), 1.0 + 1e-12);
        }
    // Bounded only above (up = +z).
    EXPECT_DOUBLE_EQ(w->bounds().max().z(), 0.6);
    EXPECT_FALSE(std::isfinite(w->bounds().min().z()));
    EXPECT_THROW(make_wavy_half_space({0, 0, 0}, {0, 0, 1}, {0, 0, 2}, 0.1, 0.4),
                 std::invalid_argument);
    EXPECT_THROW(make_wavy_half_space({0, 0, 0}, {0, 0, 1}, {1, 0, 0}, -0.1, 0.4),
                 std::invalid_argument);
    EXPECT_THROW(make_wavy_half_space({0, 0, 0}, {0, 0, 1}, {1, 0, 0}, 0.1, 0.0),
                 std::invalid_argument);
}

TEST(ImplicitMesher, UnboundedShapeIsRejected) {
    ImplicitMeshOptions options;
    options.edge_length = 0.05;
    EXPECT_THROW(
        mesh_implicit_shape(*make_wavy_half_space({0, 0, 0}, {0, 0, 1}, {1, 0, 0}, 0.1, 0.4),
                            options),
        std::invalid_argument);
}

TEST(ImplicitMesher, WavySlabIsClosedIntersectionFreeAndFollowsTheCosine) {
    // A capillary-wave liquid slab: z < h + A cos(2π(x − x0)/λ) cut by a box; two whole
    // wavelengths across x so the enclosed volume equals the flat slab's.
    const double h = 0.3, amplitude = 0.04, wavelength = 0.5, x0 = 0.1, xi = 0.025;
    const Vec3 box_lo(0.1, 0.0, 0.0), box_hi(1.1, 0.4, 0.6);
    const auto slab = make_intersection(
        {make_wavy_half_space({x0, 0, h}, {0, 0, 1}, {1, 0, 0}, amplitude, wavelength),
         make_box(box_lo, box_hi)});
    ImplicitMeshOptions options;
    options.edge_length = xi;
    ImplicitMeshReport report;
    const SurfaceMesh mesh = mesh_implicit_shape(*slab, options, &report);

    const auto violations = validate_mesh(mesh);
    EXPECT_TRUE(violations.empty()) << violations.size() << " violations";
    EXPECT_TRUE(is_intersection_free(mesh));
    EXPECT_EQ(triangle_components(mesh).count, 1);
    EXPECT_EQ(euler_characteristic(mesh), 2);
    EXPECT_GE(report.min_angle_degrees, 10.0);
    const double exact_volume = (box_hi.x() - box_lo.x()) * (box_hi.y() - box_lo.y()) * h;
    EXPECT_NEAR(enclosed_volume(mesh), exact_volume, 0.01 * exact_volume);

    // Every vertex off the box's walls lies on the exact cosine, and the top is all there.
    const double tolerance = 1e-3 * xi;
    int top_vertices = 0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        const Vec3& p = mesh.position(vi);
        const double wall = std::min({p.x() - box_lo.x(), box_hi.x() - p.x(), p.y() - box_lo.y(),
                                      box_hi.y() - p.y(), p.z() - box_lo.z()});
        if (wall < tolerance)
            continue;
        ++top_vertices;
        const double z_exact = h + amplitude * std::cos(2 * PI * (p.x() - x0) / wavelength);
        EXPECT_NEAR(p.z(), z_exact, tolerance) << "vertex " << vi << " at x = " << p.x();
    }
    const double top_area = (box_hi.x() - box_lo.x()) * (box_hi.y() - box_lo.y());
    EXPECT_GT(top_vertices, 0.7 * top_area / (std::sqrt(3.0) / 2.0 * xi * xi));
}

TEST(ImplicitShapes, RejectBadParameters) {
    EXPECT_THROW(make_sphere({0, 0, 0}, -1.0), std::invalid_argument);
    EXPECT_THROW(make_torus({0, 0, 0}, {0, 0, 1}, 0.1, 0.2), std::invalid_argument);
    EXPECT_THROW(make_cylinder({0, 0, 0}, {0, 0, 0}, 0.1, 0.2), std::invalid_argument);
    EXPECT_THROW(make_box({0, 0, 0}, {1, -1, 1}), std::invalid_argument);
    EXPECT_THROW(make_union({}), std::invalid_argument);
}

TEST(ImplicitShapes, SignedDistancesOfPrimitives) {
    EXPECT_DOUBLE_EQ(make_sphere({0, 0, 0}, 1.0)->value({2, 0, 0}), 1.0);
    EXPECT_DOUBLE_EQ(make_box({-1, -1, -1}, {1, 1, 1})->value({0, 0, 0}), -1.0);
    EXPECT_DOUBLE_EQ(make_torus({0, 0, 0}, {0, 0, 1}, 1.0, 0.25)->value({1, 0, 0}), -0.25);
    EXPECT_DOUBLE_EQ(make_cylinder({0, 0, 0}, {0, 0, 1}, 1.0, 2.0)->value({0, 0, 3}), 2.0);
    const auto diff = make_difference(make_sphere({0, 0, 0}, 1.0), make_sphere({1, 0, 0}, 0.5));
    EXPECT_GT(diff->value({0.9, 0, 0}), 0.0);
    EXPECT_LT(diff->value({-0.9, 0, 0}), 0.0);
}

TEST(ImplicitShapes, SurfaceAreasMatchTheirMeshes) {
    // The closed forms the run's memory estimate uses: within 2 % of the meshed area for the
    // primitives, and an upper bound for combinations (sum of parts).
    constexpr double INF = std::numeric_limits<double>::infinity();
    const Box3 everywhere(Vec3::Constant(-INF), Vec3::Constant(INF));
    ImplicitMeshOptions options;
    options.edge_length = 0.02;
    const std::vector<std::pair<std::string, ShapePtr>> primitives = {
        {"sphere", make_sphere({0, 0, 0}, 0.3)},
        {"ellipsoid", make_ellipsoid({0, 0, 0}, {0.4, 0.2, 0.25})},
        {"torus", make_torus({0, 0, 0}, {0, 0, 1}, 0.3, 0.1)},
        {"perturbed_cylinder", make_perturbed_cylinder({0, 0, 0}, {1, 0, 0}, 0.1, 0.8, 0.1, 0.4)},
    };
    for (const auto& [name, shape] : primitives) {
        const double meshed = surface_area(mesh_implicit_shape(*shape, options));
        EXPECT_NEAR(shape->surface_area(everywhere), meshed, 0.02 * meshed) << name;
    }
    const ShapePtr two = make_union({make_sphere({-0.2, 0, 0}, 0.3), make_sphere({0.2, 0, 0}, 0.3)});
    EXPECT_DOUBLE_EQ(two->surface_area(everywhere), 2.0 * 4.0 * M_PI * 0.09);
    EXPECT_GT(two->surface_area(everywhere), surface_area(mesh_implicit_shape(*two, options)));
    // An unbounded surface is finite only inside a box: a flat slab of 1 × 1 × 0.5.
    const ShapePtr slab = make_intersection(
        {make_wavy_half_space({0, 0, 0.5}, {0, 0, 1}, {1, 0, 0}, 0.0, 1.0),
         make_box({0, 0, 0}, {1, 1, 2})});
    EXPECT_TRUE(std::isinf(make_wavy_half_space({0, 0, 0}, {0, 0, 1}, {1, 0, 0}, 0.0, 1.0)
                               ->surface_area(everywhere)));
    const double slab_area = slab->surface_area(everywhere);
    EXPECT_TRUE(std::isfinite(slab_area));
    EXPECT_GE(slab_area, 1.0 + 1.0 + 4 * 0.5);
}

TEST(ImplicitMesher, StopsWhenCancelled) {
    std::atomic<bool> stop{true};
    ImplicitMeshOptions options;
    options.edge_length = 0.02;
    options.cancel = CancellationToken(&stop);
    EXPECT_THROW(mesh_implicit_shape(*make_sphere({0, 0, 0}, 0.3), options), Cancelled);
    stop = false;
    EXPECT_GT(mesh_implicit_shape(*make_sphere({0, 0, 0}, 0.3), options).count_live_triangles(), 0);
}

TEST(ImplicitMesher, HugeGridsAreRefusedWithTheirSizeNotAnOverflow) {
    // Node counts beyond int used to overflow into a negative number in the message.
    ImplicitMeshOptions options;
    options.edge_length = 1e-12;
    try {
        mesh_implicit_shape(*make_sphere({0, 0, 0}, 1.0), options);
        FAIL() << "a grid of 1e37 nodes was accepted";
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("would need 2.33e+37 nodes"), std::string::npos) << what;
        EXPECT_EQ(what.find('-'), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace meniscus::tracker
