#include "tracker/distance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace meniscus::tracker {
namespace {

using Eigen::Vector3d;

constexpr double TIGHT = 1e-12;

Vector3d weighted(const std::array<double, 4>& w, const Vector3d& x0, const Vector3d& x1,
                  const Vector3d& x2, const Vector3d& x3) {
    return w[0] * x0 + w[1] * x1 + w[2] * x2 + w[3] * x3;
}

/// Brute-force minimum distance from p to the triangle on a barycentric lattice.
double sampled_point_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                              const Vector3d& c, int n) {
    double best = INFINITY;
    for (int i = 0; i <= n; ++i) {
        for (int j = 0; i + j <= n; ++j) {
            const double beta = double(i) / n, gamma = double(j) / n;
            best = std::min(best, (p - ((1 - beta - gamma) * a + beta * b + gamma * c)).norm());
        }
    }
    return best;
}

double sampled_edge_edge(const Vector3d& a0, const Vector3d& a1, const Vector3d& b0,
                         const Vector3d& b1, int n) {
    double best = INFINITY;
    for (int i = 0; i <= n; ++i) {
        for (int j = 0; j <= n; ++j) {
            const double s = double(i) / n, u = double(j) / n;
            best = std::min(best, ((a0 + s * (a1 - a0)) - (b0 + u * (b1 - b0))).norm());
        }
    }
    return best;
}

TEST(PointTriangleProximity, RandomMatchesSamplingAndConventions) {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int n = 0; n < 2000; ++n) {
        const Vector3d p(u(rng), u(rng), u(rng)), a(u(rng), u(rng), u(rng)),
            b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
        const auto r = point_triangle_proximity(p, a, b, c);
        const auto& w = r.weights;
        EXPECT_NEAR(w[0] + w[1] + w[2] + w[3], 0.0, TIGHT);
        EXPECT_EQ(w[0], 1.0);
        for (double bary : r.barycentric) {
            EXPECT_GE(bary, 0.0);
            EXPECT_LE(bary, 1.0);
        }
        const Vector3d gap = weighted(w, p, a, b, c);
        EXPECT_NEAR(gap.norm(), r.distance, TIGHT);
        EXPECT_NEAR(r.normal.norm(), 1.0, TIGHT);
        EXPECT_GT(r.normal.dot(gap), 0.0);  // from the triangle towards the point
        // Optimality: no sampled point of the triangle is closer (up to the lattice spacing
        // error, which only makes the sampled minimum larger).
        EXPECT_LE(r.distance, sampled_point_triangle(p, a, b, c, 60) + TIGHT) << "case " << n;
        EXPECT_GE(r.distance, sampled_point_triangle(p, a, b, c, 60) - 0.1);
    }
}

TEST(PointTriangleProximity, InteriorEdgeVertexRegions) {
    const Vector3d a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
    auto r = point_triangle_proximity(Vector3d(0.5, 0.5, 3), a, b, c);
    EXPECT_NEAR(r.distance, 3.0, TIGHT);
    EXPECT_NEAR(r.barycentric[0], 0.5, TIGHT);
    EXPECT_NEAR(r.normal.z(), 1.0, TIGHT);
    r = point_triangle_proximity(Vector3d(1, -1, 0), a, b, c);  // edge ab region, in plane
    EXPECT_NEAR(r.distance, 1.0, TIGHT);
    EXPECT_NEAR(r.barycentric[1], 0.5, TIGHT);
    EXPECT_NEAR(r.normal.y(), -1.0, TIGHT);
    r = point_triangle_proximity(Vector3d(-1, -1, -1), a, b, c);  // vertex a region
    EXPECT_NEAR(r.distance, std::sqrt(3.0), TIGHT);
    EXPECT_NEAR(r.barycentric[0], 1.0, TIGHT);
}

TEST(PointTriangleProximity, ZeroDistanceAndDegenerateNormals) {
    const Vector3d a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
    // On the face: the triangle normal, oriented by the fallback direction.
    auto r = point_triangle_proximity(Vector3d(0.5, 0.5, 0), a, b, c, Vector3d(0, 0, -5));
    EXPECT_EQ(r.distance, 0.0);
    EXPECT_NEAR(r.normal.z(), -1.0, TIGHT);
    r = point_triangle_proximity(Vector3d(0.5, 0.5, 0), a, b, c);
    EXPECT_NEAR(std::abs(r.normal.z()), 1.0, TIGHT);
    // Below the resolvable distance: still the face normal, oriented by the tiny gap.
    r = point_triangle_proximity(Vector3d(0.5, 0.5, -1e-14), a, b, c, Vector3d(0, 0, 1));
    EXPECT_NEAR(r.normal.z(), -1.0, TIGHT);
    // Zero-area triangle, point on it: orthogonal to the triangle's line, along the fallback.
    const Vector3d m(1, 0, 0);
    r = point_triangle_proximity(Vector3d(0.5, 0, 0), a, b, m, Vector3d(1, 1, 0));
    EXPECT_EQ(r.distance, 0.0);
    EXPECT_NEAR(r.normal.x(), 0.0, TIGHT);
    EXPECT_NEAR(r.normal.y(), 1.0, TIGHT);
    // Zero-area triangle, point off it: regular closest point on the segment.
    r = point_triangle_proximity(Vector3d(0.5, 3, 0), a, b, m);
    EXPECT_NEAR(r.distance, 3.0, TIGHT);
    EXPECT_NEAR(r.normal.y(), 1.0, TIGHT);
    // Everything at one point, no fallback: a unit vector anyway.
    r = point_triangle_proximity(a, a, a, a);
    EXPECT_NEAR(r.normal.norm(), 1.0, TIGHT);
    EXPECT_EQ(r.distance, 0.0);
}

TEST(PointTriangleProximity, ScaleAndTranslationCovariant) {
    const Vector3d p(0.3, 0.7, 0.4), a(0, 0, 0), b(1, 0.1, 0), c(0.2, 1, 0.3);
    const auto ref = point_triangle_proximity(p, a, b, c);
    for (double scale : {1e-6, 1e6}) {
        const Vector3d shift(1e3 * scale, -2e3 * scale, 0);
        const auto r = point_triangle_proximity(p * scale + shift, a * scale + shift,
                                                b * scale + shift, c * scale + shift);
        EXPECT_NEAR(r.distance / scale, ref.distance, 1e-9);
        for (int i = 0; i < 3; ++i) {
            EXPECT_NEAR(r.barycentric[i], ref.barycentric[i], 1e-9);
        }
        EXPECT_NEAR(r.normal.dot(ref.normal), 1.0, 1e-9);
    }
}

TEST(EdgeEdgeProximity, RandomMatchesSamplingAndConventions) {
    std::mt19937_64 rng(2);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int n = 0; n < 2000; ++n) {
        const Vector3d a0(u(rng), u(rng), u(rng)), a1(u(rng), u(rng), u(rng)),
            b0(u(rng), u(rng), u(rng)), b1(u(rng), u(rng), u(rng));
        const auto r = edge_edge_proximity(a0, a1, b0, b1);
        const auto& w = r.weights;
        EXPECT_NEAR(w[0] + w[1] + w[2] + w[3], 0.0, TIGHT);
        EXPECT_GE(r.s, 0.0);
        EXPECT_LE(r.s, 1.0);
        EXPECT_GE(r.u, 0.0);
        EXPECT_LE(r.u, 1.0);
        const Vector3d gap = weighted(w, a0, a1, b0, b1);
        EXPECT_NEAR(gap.norm(), r.distance, TIGHT);
        EXPECT_NEAR(r.normal.norm(), 1.0, TIGHT);
        EXPECT_GT(r.normal.dot(gap), 0.0);  // from edge b towards edge a
        EXPECT_LE(r.distance, sampled_edge_edge(a0, a1, b0, b1, 80) + TIGHT) << "case " << n;
    }
}

TEST(EdgeEdgeProximity, ParallelCrossingAndCollinear) {
    // Parallel, overlapping on x in [0.5, 1]: middle of the overlap.
    auto r = edge_edge_proximity(Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0.5, 1, 0),
                                 Vector3d(2, 1, 0));
    EXPECT_NEAR(r.distance, 1.0, TIGHT);
    EXPECT_NEAR(r.s, 0.75, TIGHT);
    EXPECT_NEAR(r.normal.y(), -1.0, TIGHT);
    // Parallel, disjoint projections: nearest endpoints.
    r = edge_edge_proximity(Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(2, 1, 0),
                            Vector3d(3, 1, 0));
    EXPECT_NEAR(r.distance, std::sqrt(2.0), TIGHT);
    EXPECT_EQ(r.s, 1.0);
    EXPECT_EQ(r.u, 0.0);
    // Crossing (zero distance): the cross product of the edges, oriented by the fallback.
    r = edge_edge_proximity(Vector3d(-1, 0, 0), Vector3d(1, 0, 0), Vector3d(0, -1, 0),
                            Vector3d(0, 1, 0), Vector3d(0, 0, -2));
    EXPECT_EQ(r.distance, 0.0);
    EXPECT_NEAR(r.normal.z(), -1.0, TIGHT);
    EXPECT_NEAR(r.s, 0.5, TIGHT);
    // Collinear overlapping (zero distance, parallel): orthogonal to the edges, near fallback.
    r = edge_edge_proximity(Vector3d(0, 0, 0), Vector3d(2, 0, 0), Vector3d(1, 0, 0),
                            Vector3d(3, 0, 0), Vector3d(1, 0, 1));
    EXPECT_EQ(r.distance, 0.0);
    EXPECT_NEAR(r.normal.x(), 0.0, TIGHT);
    EXPECT_NEAR(r.normal.z(), 1.0, TIGHT);
    // Zero-length edges.
    r = edge_edge_proximity(Vector3d(0, 0, 0), Vector3d(0, 0, 0), Vector3d(-1, 1, 0),
                            Vector3d(1, 1, 0));
    EXPECT_NEAR(r.distance, 1.0, TIGHT);
    EXPECT_NEAR(r.u, 0.5, TIGHT);
    r = edge_edge_proximity(Vector3d(0, 0, 0), Vector3d(0, 0, 0), Vector3d(0, 0, 0),
                            Vector3d(0, 0, 0));
    EXPECT_EQ(r.distance, 0.0);
    EXPECT_NEAR(r.normal.norm(), 1.0, TIGHT);
}

TEST(EdgeEdgeProximity, NearlyParallelIsContinuous) {
    // As the second edge rotates towards parallel, the distance must not jump.
    double previous = -1.0;
    for (int k = 0; k <= 40; ++k) {
        const double angle = std::ldexp(1.0, -k);
        const Vector3d b0(0.25, 1, 0), b1 = b0 + Vector3d(std::cos(angle), 0, std::sin(angle));
        const auto r = edge_edge_proximity(Vector3d(0, 0, 0), Vector3d(1, 0, 0), b0, b1);
        EXPECT_NEAR(r.distance, 1.0, 1e-9);
        if (previous >= 0.0) {
            EXPECT_NEAR(r.distance, previous, 1e-9);
        }
        previous = r.distance;
    }
}

}  // namespace
}  // namespace meniscus::tracker
