// One impact zone's inelastic projection (tracker/impact_zone.h) against hand-solved cases.
#include "tracker/impact_zone.h"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

namespace meniscus::tracker {
namespace {

/// A point (vertex 0) under a triangle (vertices 1–3) at its centroid, normal +z: the row is
/// d₀ − (d₁ + d₂ + d₃)/3 along z.
Contact point_over_centroid(double target) {
    return {{0, 1, 2, 3}, {1.0, -1.0 / 3.0, -1.0 / 3.0, -1.0 / 3.0}, Vec3::UnitZ(), target, false};
}

/// The solve regularizes its matrix by 1e-12 of its diagonal: answers are that close.
constexpr double SOLVE_TOLERANCE = 1e-13;

std::vector<int> all_rows(const std::vector<Contact>& c) {
    std::vector<int> rows;
    for (int r = 0; r < static_cast<int>(c.size()); ++r)
        rows.push_back(r);
    return rows;
}

TEST(ImpactZone, OneContactGetsTheMinimumNormCorrection) {
    // Unit masses: Δd = M⁻¹ Cᵀ λ with λ = b / (C M⁻¹ Cᵀ) = b / (1 + 3 · 1/9) = 0.75 b.
    const std::vector<Contact> rows{point_over_centroid(1e-3)};
    std::vector<Vec3> d(4, Vec3::Zero());
    d[0] = Vec3(0, 0, -2e-3);  // the point moves down through the triangle
    CollisionReport report;
    project_impact_zone(rows, all_rows(rows), std::vector<double>(4, 1.0),
                        std::numeric_limits<int>::max(), d, report);
    const double b = 1e-3 - (-2e-3);
    EXPECT_NEAR(d[0].z(), -2e-3 + 0.75 * b, SOLVE_TOLERANCE);
    for (int k = 1; k < 4; ++k)
        EXPECT_NEAR(d[k].z(), -0.25 * b, SOLVE_TOLERANCE);
    EXPECT_NEAR(relative_normal_displacement(rows[0], d), 1e-3, SOLVE_TOLERANCE);
    EXPECT_EQ(report.largest_impact_zone, 4);
}

TEST(ImpactZone, PinnedTriangleLeavesTheWholeCorrectionToThePoint) {
    const std::vector<Contact> rows{point_over_centroid(1e-3)};
    std::vector<Vec3> d(4, Vec3::Zero());
    d[0] = Vec3(0, 0, -2e-3);
    CollisionReport report;
    project_impact_zone(rows, all_rows(rows), {1.0, 0.0, 0.0, 0.0},
                        std::numeric_limits<int>::max(), d, report);
    EXPECT_NEAR(d[0].z(), 1e-3, SOLVE_TOLERANCE);
    for (int k = 1; k < 4; ++k)
        EXPECT_EQ(d[k], Vec3::Zero());
}

// Two rows for nearly the same contact with different targets (what a point–triangle and an
// edge–edge hit at one place give): as equalities they are inconsistent and need huge λ of
// both signs. The projection must meet both, push only, and stay as small as the stricter row
// alone asks.
TEST(ImpactZone, NearlyDependentRowsWithDifferentTargetsArePushedNotPulled) {
    Contact strict = point_over_centroid(2e-3);
    Contact loose = point_over_centroid(1e-3);
    loose.weights = {1.0, -0.34, -0.33, -0.33};  // the same place, weights a hair apart
    const std::vector<Contact> rows{strict, loose};
    std::vector<Vec3> d(4, Vec3::Zero());
    d[0] = Vec3(0, 0, -2e-3);
    CollisionReport report;
    project_impact_zone(rows, all_rows(rows), std::vector<double>(4, 1.0),
                        std::numeric_limits<int>::max(), d, report);
    for (const Contact& c : rows)
        EXPECT_GE(relative_normal_displacement(c, d), c.target * (1.0 - 1e-3));
    // The stricter row alone moves the point up by 0.75 · 4e-3 = 3e-3 (to +1e-3): no more
    // than a hair beyond that.
    EXPECT_LT(d[0].z(), 1e-3 * 1.01);
    EXPECT_GT(d[0].z(), 1e-3 * 0.99);
}

TEST(ImpactZone, AZoneTooLargeForTheMatrixBoundIsLeftAlone) {
    const std::vector<Contact> rows{point_over_centroid(1e-3)};
    std::vector<Vec3> d(4, Vec3::Zero());
    d[0] = Vec3(0, 0, -2e-3);
    const std::vector<Vec3> before = d;
    CollisionReport report;
    project_impact_zone(rows, all_rows(rows), std::vector<double>(4, 1.0), 3, d, report);
    EXPECT_EQ(d, before);
    EXPECT_GE(report.oversized_zone_solves, 1);
}

}  // namespace
}  // namespace meniscus::tracker
