// The axisymmetric level-set mean-curvature reference (tracker/flows/axisymmetric_mcf_reference.h):
// a sphere follows R(t) = sqrt(R₀² − 4t) and a long cylinder R(t) = sqrt(R₀² − 2t) at second
// order, the A2 dumbbell pinches off and converges under refinement, it agrees with the 3-D
// OpenVDB reference of coupling/ within that reference's own error, and bad options throw.

#include "tracker/flows/axisymmetric_mcf_reference.h"

#include "coupling/levelset_reference.h"
#include "tracker/implicit_shape.h"
#include "tests/sphere_samples.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace meniscus::tracker {
namespace {


constexpr double SPHERE_R0 = 0.3;
/// Half the extinction time R₀²/4: the radius falls from 0.3 to 0.212.
constexpr double SPHERE_END = 0.5 * SPHERE_R0 * SPHERE_R0 / 4.0;
/// Off the voxel lattice, on a tilted axis: nothing about the grid or the x axis helps.
const Vec3 SPHERE_CENTER(0.0123, -0.0071, 0.0037);
const Vec3 TILTED_AXIS(1.0, 2.0, 2.0);
constexpr int SPHERE_SAMPLES = 400;
/// Measured max radius errors 2.0e-5, 5.0e-6, 1.25e-6 at Δx = 0.01, 0.005, 0.0025 (order 2.0).
constexpr double SPHERE_ERROR_BOUND_COARSE = 3e-5;  ///< at Δx = 0.01
constexpr double MIN_ORDER = 1.8;

/// Long capped cylinder: the middle is a cylinder until the rounding ends get there.
constexpr double CYLINDER_R0 = 0.2;
constexpr double CYLINDER_HEIGHT = 2.0;
constexpr double CYLINDER_END = 0.005;  ///< R falls to sqrt(0.04 − 0.01) = 0.173
constexpr double CYLINDER_MIDDLE = 0.4;  ///< |a| ≤ this is compared with the exact radius
/// Measured 1.03e-5 at Δx = 0.01, 2.6e-6 at 0.005 (order 2.0).
constexpr double CYLINDER_ERROR_BOUND_COARSE = 1.5e-5;  ///< at Δx = 0.01

/// The A2 dumbbell (app/validate.cpp) at the paper's comparison time.
constexpr double DUMBBELL_BULB = 0.4, DUMBBELL_SEPARATION = 1.1, DUMBBELL_HANDLE = 0.15,
                 DUMBBELL_BLEND = 0.05, DUMBBELL_END = 0.025;
/// Successive max differences at the finer surface must shrink at least this much per halving.
/// Second order gives 4; measured 2.9 for Δx = 0.02 → 0.01 → 0.005 (at Δx = 0.02 the handle's
/// radius at pinch-off time is a few cells) and 3.8–3.9 for 0.005 → 0.0025 → 0.00125 (too slow
/// for this test; `meniscus validate --full` reports it).
constexpr double MIN_DIFFERENCE_RATIO = 2.5;
/// The 3-D OpenVDB reference (coupling/levelset_reference.h) at Δx = 0.02 is off by ~2–3e-3
/// near the pinched tips (its Δx = 0.02 and 0.01 runs differ by about that much); measured max
/// |φ_vdb| on the axisymmetric surface 2.8e-3, so agreement is asserted within 4e-3.
constexpr double OPENVDB_AGREEMENT = 4e-3;

std::vector<Vec3> sphere_points(const Vec3& center, double radius) {
    return testing::fibonacci_sphere_points(center, radius, SPHERE_SAMPLES);
}

/// max |φ_ref| over the exact sphere at SPHERE_END.
double sphere_error(double voxel_size, double cfl = 1.0) {
    AxisymmetricMcfOptions o;
    o.voxel_size = voxel_size;
    o.end_time = SPHERE_END;
    o.cfl = cfl;
    const AxisymmetricMcfReference ref(*make_sphere(SPHERE_CENTER, SPHERE_R0), SPHERE_CENTER,
                                       TILTED_AXIS, o);
    EXPECT_NEAR(ref.stats().time_step * static_cast<double>(ref.stats().steps), SPHERE_END,
                1e-14);
    EXPECT_LE(ref.stats().time_step, cfl * voxel_size * voxel_size / 4.0 * (1.0 + 1e-12));
    const double exact = std::sqrt(SPHERE_R0 * SPHERE_R0 - 4.0 * SPHERE_END);
    double worst = 0.0;
    for (const Vec3& p : sphere_points(SPHERE_CENTER, exact))
        worst = std::max(worst, std::abs(ref.distance(p)));
    std::cout << "[ measured ] sphere Δx=" << voxel_size << " cfl=" << cfl
              << ": max radius error " << worst << " (" << ref.stats().steps << " steps, "
              << ref.stats().seconds << " s)\n";
    return worst;
}

double order(double e_coarse, double e_fine) { return std::log2(e_coarse / e_fine); }

TEST(AxisymmetricMcfReference, InitialFieldIsTheSignedDistance) {
    AxisymmetricMcfOptions o;
    o.voxel_size = 0.01;
    const AxisymmetricMcfReference ref(*make_sphere(SPHERE_CENTER, SPHERE_R0), SPHERE_CENTER,
                                       TILTED_AXIS, o);
    EXPECT_EQ(ref.stats().steps, 0);
    for (double s : {-0.03, -0.01, 0.0, 0.005, 0.02})
        for (const Vec3& p : sphere_points(SPHERE_CENTER, SPHERE_R0 + s))
            ASSERT_NEAR(ref.distance(p), s, 1e-6);
    EXPECT_LT(ref.distance(SPHERE_CENTER), 0.0);
    EXPECT_GT(ref.distance(SPHERE_CENTER + Vec3(1.0, 1.0, 1.0)), 0.0);
}

TEST(AxisymmetricMcfReference, SphereShrinksAtSecondOrder) {
    const double e1 = sphere_error(0.01), e2 = sphere_error(0.005), e3 = sphere_error(0.0025);
    EXPECT_LT(e1, SPHERE_ERROR_BOUND_COARSE);
    EXPECT_GE(order(e1, e2), MIN_ORDER);
    EXPECT_GE(order(e2, e3), MIN_ORDER);
}

// cfl = 1 (Δt = Δx²/4) is stable and as accurate as half that step.
TEST(AxisymmetricMcfReference, FullCflStepIsStable) {
    const double full = sphere_error(0.005, 1.0), half = sphere_error(0.005, 0.5);
    EXPECT_LT(full, 2.0 * half);
    EXPECT_LT(half, 2.0 * full);
}

TEST(AxisymmetricMcfReference, LongCylinderShrinksAtSecondOrder) {
    const Vec3 center(0.003, 0.001, -0.002);
    const auto shape = make_cylinder(center, Vec3::UnitX(), CYLINDER_R0, CYLINDER_HEIGHT);
    const double exact = std::sqrt(CYLINDER_R0 * CYLINDER_R0 - 2.0 * CYLINDER_END);
    std::vector<double> errors;
    for (double dx : {0.01, 0.005}) {
        AxisymmetricMcfOptions o;
        o.voxel_size = dx;
        o.end_time = CYLINDER_END;
        const AxisymmetricMcfReference ref(*shape, center, Vec3::UnitX(), o);
        double worst = 0.0;
        for (double a = -CYLINDER_MIDDLE; a <= CYLINDER_MIDDLE; a += 0.01237)
            for (double angle : {0.0, 1.0, 2.5})
                worst = std::max(worst, std::abs(ref.distance(
                                            center + Vec3(a, exact * std::cos(angle),
                                                          exact * std::sin(angle)))));
        std::cout << "[ measured ] cylinder Δx=" << dx << ": max radius error " << worst << "\n";
        errors.push_back(worst);
    }
    EXPECT_LT(errors[0], CYLINDER_ERROR_BOUND_COARSE);
    EXPECT_GE(order(errors[0], errors[1]), MIN_ORDER);
}

/// Points on the zero set of `ref` in the meridian half-plane: for each axial station the
/// radius where φ changes sign (bisection), and the tips on the axis.
std::vector<Vec3> dumbbell_surface_points(const AxisymmetricMcfReference& ref) {
    std::vector<Vec3> out;
    const auto bisect = [](auto&& f, double lo, double hi) {  // f(lo) < 0 < f(hi)
        for (int it = 0; it < 60; ++it) {
            const double mid = 0.5 * (lo + hi);
            (f(mid) < 0.0 ? lo : hi) = mid;
        }
        return 0.5 * (lo + hi);
    };
    for (double a = -0.9; a <= 0.9; a += 0.0173) {
        const auto f = [&](double r) { return ref.meridian_distance(a, r); };
        if (!(f(0.0) < 0.0))
            continue;
        out.emplace_back(a, bisect(f, 0.0, 0.5), 0.0);
    }
    for (double side : {-1.0, 1.0}) {  // the pinched tips, between x = 0 and a bulb centre
        const double from_centre = bisect(
            [&](double s) { return ref.meridian_distance(side * (0.55 - s), 0.0); }, 0.0, 0.55);
        out.emplace_back(side * (0.55 - from_centre), 0.0, 0.0);
    }
    return out;
}

/// max |φ_other| at the zero set of `ref`.
double difference_at_surface(const AxisymmetricMcfReference& ref,
                             const std::function<double(const Vec3&)>& other) {
    double worst = 0.0;
    for (const Vec3& p : dumbbell_surface_points(ref))
        worst = std::max(worst, std::abs(other(p)));
    return worst;
}

class AxisymmetricDumbbell : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        s_shape = make_dumbbell(Vec3::Zero(), DUMBBELL_BULB, DUMBBELL_SEPARATION, DUMBBELL_HANDLE,
                                DUMBBELL_BLEND);
        for (double dx : {0.02, 0.01, 0.005}) {
            AxisymmetricMcfOptions o;
            o.voxel_size = dx;
            o.end_time = DUMBBELL_END;
            s_refs.emplace_back(*s_shape, Vec3::Zero(), Vec3::UnitX(), o);
            std::cout << "[ measured ] dumbbell Δx=" << dx << ": " << s_refs.back().stats().steps
                      << " steps, " << s_refs.back().stats().seconds << " s\n";
        }
    }
    static void TearDownTestSuite() { s_refs.clear(); }

    static ShapePtr s_shape;
    static std::vector<AxisymmetricMcfReference> s_refs;
};

ShapePtr AxisymmetricDumbbell::s_shape;
std::vector<AxisymmetricMcfReference> AxisymmetricDumbbell::s_refs;

TEST_F(AxisymmetricDumbbell, HandlePinchesOffIntoTwoComponents) {
    for (const AxisymmetricMcfReference& ref : s_refs) {
        EXPECT_GT(ref.distance(Vec3::Zero()), 0.0);                         // handle gone
        EXPECT_GT(ref.distance(Vec3(0.15, 0.0, 0.0)), 0.0);
        EXPECT_LT(ref.distance(Vec3(0.55, 0.0, 0.0)), 0.0);                 // bulbs remain
        EXPECT_LT(ref.distance(Vec3(-0.55, 0.0, 0.0)), 0.0);
        // Along the axis: exactly two inside intervals (one per bulb).
        int runs = 0;
        bool inside = false;
        for (double a = -1.0; a <= 1.0; a += 0.001) {
            const bool now = ref.meridian_distance(a, 0.0) < 0.0;
            runs += now && !inside ? 1 : 0;
            inside = now;
        }
        EXPECT_EQ(runs, 2);
    }
}

TEST_F(AxisymmetricDumbbell, ConvergesUnderRefinement) {
    const auto at = [](const AxisymmetricMcfReference& r) {
        return [&r](const Vec3& x) { return r.distance(x); };
    };
    // Differences between successive resolutions, measured on the finer one's surface.
    const double d_coarse = difference_at_surface(s_refs[1], at(s_refs[0]));
    const double d_fine = difference_at_surface(s_refs[2], at(s_refs[1]));
    std::cout << "[ measured ] dumbbell max |φ(Δx) − φ(Δx/2)|: 0.02→0.01 " << d_coarse
              << ", 0.01→0.005 " << d_fine << " (ratio " << d_coarse / d_fine << ")\n";
    EXPECT_GE(d_coarse / d_fine, MIN_DIFFERENCE_RATIO);
    // Symmetric in x like the dumbbell.
    for (const Vec3& p : dumbbell_surface_points(s_refs[2]))
        EXPECT_NEAR(s_refs[2].distance(Vec3(-p.x(), p.y(), p.z())), 0.0, 1e-9);
}

TEST_F(AxisymmetricDumbbell, AgreesWithTheOpenVdbReference) {
    coupling::LevelSetReferenceOptions o;
    o.voxel_size = 0.02;
    o.end_time = DUMBBELL_END;
    const coupling::LevelSetReference vdb(*s_shape, o);
    // Points around the axis, not only in the x–y plane.
    double worst = 0.0;
    for (const Vec3& p : dumbbell_surface_points(s_refs[2]))
        for (double angle : {0.0, 0.7, 2.0, 4.0}) {
            const Vec3 q(p.x(), p.y() * std::cos(angle), p.y() * std::sin(angle));
            worst = std::max(worst, std::abs(vdb.distance(q)));
        }
    std::cout << "[ measured ] OpenVDB reference (Δx = 0.02, " << vdb.stats().seconds
              << " s) at the axisymmetric surface (Δx = 0.005): max |φ| " << worst << "\n";
    EXPECT_LT(worst, OPENVDB_AGREEMENT);
}

TEST(AxisymmetricMcfReference, BadInputThrowsNamingTheField) {
    const auto sphere = make_sphere(Vec3::Zero(), 0.2);
    const auto expect_field = [&](const std::string& field, auto&& edit) {
        AxisymmetricMcfOptions o;
        edit(o);
        try {
            AxisymmetricMcfReference(*sphere, Vec3::Zero(), Vec3::UnitX(), o);
            ADD_FAILURE() << field << " accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
        }
    };
    expect_field("voxel_size", [](AxisymmetricMcfOptions& o) { o.voxel_size = 0.0; });
    expect_field("voxel_size", [](AxisymmetricMcfOptions& o) { o.voxel_size = NAN; });
    expect_field("end_time", [](AxisymmetricMcfOptions& o) { o.end_time = -1.0; });
    expect_field("cfl", [](AxisymmetricMcfOptions& o) { o.cfl = 1.5; });
    expect_field("cfl", [](AxisymmetricMcfOptions& o) { o.cfl = 0.0; });
    expect_field("reinit_interval", [](AxisymmetricMcfOptions& o) { o.reinit_interval = 0; });
    expect_field("reinit_iterations", [](AxisymmetricMcfOptions& o) { o.reinit_iterations = 0; });
    expect_field("band_half_width_voxels",
                 [](AxisymmetricMcfOptions& o) { o.band_half_width_voxels = 3; });
    expect_field("projection_width_voxels",
                 [](AxisymmetricMcfOptions& o) { o.projection_width_voxels = 11.0; });
    expect_field("padding_voxels", [](AxisymmetricMcfOptions& o) { o.padding_voxels = 1; });
    expect_field("final_reinit_iterations",
                 [](AxisymmetricMcfOptions& o) { o.final_reinit_iterations = -1; });
    EXPECT_THROW(AxisymmetricMcfReference(*sphere, Vec3::Zero(), Vec3::Zero(), {}),
                 std::invalid_argument);
    const auto half_space = make_wavy_half_space(Vec3::Zero(), Vec3::UnitZ(), Vec3::UnitX(), 0.0,
                                                 1.0);
    EXPECT_THROW(AxisymmetricMcfReference(*half_space, Vec3::Zero(), Vec3::UnitZ(), {}),
                 std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::tracker
