#include "tracker/implicit_mesher.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

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

}  // namespace
}  // namespace meniscus::tracker
