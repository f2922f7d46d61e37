#include "tracker/intersection.h"

#include "exact_oracle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>

namespace meniscus::tracker {
namespace {

using Eigen::Vector3d;
using oracle::Q3;
using Kind = SegmentTriangleContact;
using Feature = TriangleFeature;

// ---------------------------------------------------------------------------------------------
// Independent rational oracle: barycentric coordinates by Cramer's rule instead of the
// orientation-sign (Plücker) tests the library uses.

Q3 sub(const Q3& a, const Q3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Q3 cross(const Q3& a, const Q3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
mpq_class dot(const Q3& a, const Q3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// Barycentric (α, β, γ) of x (assumed in the plane) w.r.t. a non-degenerate triangle.
std::array<mpq_class, 3> barycentric(const Q3& x, const Q3& a, const Q3& b, const Q3& c) {
    const Q3 n = cross(sub(b, a), sub(c, a));
    const mpq_class nn = dot(n, n);
    const mpq_class beta = dot(cross(sub(x, a), sub(c, a)), n) / nn;
    const mpq_class gamma = dot(cross(sub(b, a), sub(x, a)), n) / nn;
    return {1 - beta - gamma, beta, gamma};
}

bool collinear_q(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
    const Q3 n =
        cross(sub(oracle::to_q(b), oracle::to_q(a)), sub(oracle::to_q(c), oracle::to_q(a)));
    return n[0] == 0 && n[1] == 0 && n[2] == 0;
}

struct OracleAnswer {
    Kind kind;
    Feature feature;
};

/// Oracle for non-coplanar configurations with a non-degenerate triangle.
std::optional<OracleAnswer> oracle_segment_triangle(const Vector3d& s0d, const Vector3d& s1d,
                                                    const Vector3d& ad, const Vector3d& bd,
                                                    const Vector3d& cd) {
    const Q3 s0 = oracle::to_q(s0d), s1 = oracle::to_q(s1d), a = oracle::to_q(ad),
             b = oracle::to_q(bd), c = oracle::to_q(cd);
    const Q3 n = cross(sub(b, a), sub(c, a));
    if (dot(n, n) == 0) {
        return std::nullopt;  // degenerate triangle: not handled by this oracle
    }
    const mpq_class d0 = dot(sub(s0, a), n), d1 = dot(sub(s1, a), n);
    if (d0 == 0 && d1 == 0) {
        return std::nullopt;  // coplanar
    }
    if ((d0 > 0 && d1 > 0) || (d0 < 0 && d1 < 0)) {
        return OracleAnswer{Kind::none, Feature::none};
    }
    const mpq_class t = d0 / (d0 - d1);
    const Q3 x{s0[0] + t * (s1[0] - s0[0]), s0[1] + t * (s1[1] - s0[1]),
               s0[2] + t * (s1[2] - s0[2])};
    const auto w = barycentric(x, a, b, c);
    if (w[0] < 0 || w[1] < 0 || w[2] < 0) {
        return OracleAnswer{Kind::none, Feature::none};
    }
    Feature f = Feature::interior;
    const int zeros = (w[0] == 0) + (w[1] == 0) + (w[2] == 0);
    if (zeros == 1) {
        f = w[2] == 0 ? Feature::edge_ab : (w[0] == 0 ? Feature::edge_bc : Feature::edge_ca);
    } else if (zeros == 2) {
        f = w[0] != 0 ? Feature::vertex_a : (w[1] != 0 ? Feature::vertex_b : Feature::vertex_c);
    }
    Kind k = Kind::proper;
    if (d0 == 0 || d1 == 0) {
        k = Kind::endpoint_on_triangle;
    } else if (zeros == 1) {
        k = Kind::through_edge;
    } else if (zeros == 2) {
        k = Kind::through_vertex;
    }
    return OracleAnswer{k, f};
}

/// Coplanar oracle: the segment meets the triangle iff an endpoint is inside or it meets an
/// edge; segment–segment by exact parameters.
bool oracle_coplanar_segments(const Q3& p0, const Q3& p1, const Q3& q0, const Q3& q1, const Q3& n) {
    const Q3 d = sub(p1, p0), f = sub(q1, q0);
    const mpq_class den = dot(cross(d, f), n);
    if (den != 0) {
        const mpq_class lam = dot(cross(sub(q0, p0), f), n) / den;
        const mpq_class mu = dot(cross(sub(q0, p0), d), n) / den;
        return lam >= 0 && lam <= 1 && mu >= 0 && mu <= 1;
    }
    // Parallel: overlap only if collinear; compare projections on d (or f).
    if (dot(cross(sub(q0, p0), d), n) != 0 && dot(d, d) != 0) {
        return false;
    }
    const Q3 axis = dot(d, d) != 0 ? d : f;
    if (dot(axis, axis) == 0) {
        return p0 == q0;
    }
    const mpq_class a0 = dot(p0, axis), a1 = dot(p1, axis), b0 = dot(q0, axis), b1 = dot(q1, axis);
    if (dot(cross(sub(q0, p0), axis), cross(sub(q0, p0), axis)) != 0) {
        return false;
    }
    return std::max(std::min(a0, a1), std::min(b0, b1)) <=
           std::min(std::max(a0, a1), std::max(b0, b1));
}

bool oracle_coplanar_segment_triangle(const Vector3d& s0d, const Vector3d& s1d, const Vector3d& ad,
                                      const Vector3d& bd, const Vector3d& cd) {
    const Q3 s0 = oracle::to_q(s0d), s1 = oracle::to_q(s1d), a = oracle::to_q(ad),
             b = oracle::to_q(bd), c = oracle::to_q(cd);
    const Q3 n = cross(sub(b, a), sub(c, a));
    for (const Q3* p : {&s0, &s1}) {
        const auto w = barycentric(*p, a, b, c);
        if (w[0] >= 0 && w[1] >= 0 && w[2] >= 0) {
            return true;
        }
    }
    return oracle_coplanar_segments(s0, s1, a, b, n) || oracle_coplanar_segments(s0, s1, b, c, n) ||
           oracle_coplanar_segments(s0, s1, c, a, n);
}

// ---------------------------------------------------------------------------------------------

TEST(SegmentTriangle, HandClassifiedCases) {
    const Vector3d a(0, 0, 0), b(4, 0, 0), c(0, 4, 0);
    auto classify = [&](const Vector3d& s0, const Vector3d& s1) {
        return segment_triangle_intersection(s0, s1, a, b, c);
    };
    auto r = classify(Vector3d(1, 1, -1), Vector3d(1, 1, 1));
    EXPECT_EQ(r.kind, Kind::proper);
    EXPECT_EQ(r.feature, Feature::interior);
    r = classify(Vector3d(2, 0, -1), Vector3d(2, 0, 1));
    EXPECT_EQ(r.kind, Kind::through_edge);
    EXPECT_EQ(r.feature, Feature::edge_ab);
    r = classify(Vector3d(2, 2, -1), Vector3d(2, 2, 1));
    EXPECT_EQ(r.kind, Kind::through_edge);
    EXPECT_EQ(r.feature, Feature::edge_bc);
    r = classify(Vector3d(0, 4, 1), Vector3d(0, 4, -3));
    EXPECT_EQ(r.kind, Kind::through_vertex);
    EXPECT_EQ(r.feature, Feature::vertex_c);
    r = classify(Vector3d(1, 1, 0), Vector3d(3, 3, 5));
    EXPECT_EQ(r.kind, Kind::endpoint_on_triangle);
    EXPECT_EQ(r.segment_endpoint, 0);
    EXPECT_EQ(r.feature, Feature::interior);
    r = classify(Vector3d(7, 7, 7), Vector3d(0, 0, 0));
    EXPECT_EQ(r.kind, Kind::endpoint_on_triangle);
    EXPECT_EQ(r.segment_endpoint, 1);
    EXPECT_EQ(r.feature, Feature::vertex_a);
    EXPECT_FALSE(classify(Vector3d(3, 3, -1), Vector3d(3, 3, 1)).intersects());  // beside
    EXPECT_FALSE(classify(Vector3d(1, 1, 1), Vector3d(1, 1, 2)).intersects());   // same side
    EXPECT_FALSE(classify(Vector3d(1, 1, 1e-300), Vector3d(1, 1, 2)).intersects());
    EXPECT_EQ(classify(Vector3d(-1, 1, 0), Vector3d(5, 1, 0)).kind, Kind::coplanar);
    EXPECT_EQ(classify(Vector3d(1, 1, 0), Vector3d(1.5, 1, 0)).kind, Kind::coplanar);  // inside
    EXPECT_FALSE(classify(Vector3d(3, 3, 0), Vector3d(5, 1, 0)).intersects());  // parallel to bc
    EXPECT_EQ(classify(Vector3d(2, 2, 0), Vector3d(5, -1, 0)).kind, Kind::coplanar);  // along bc
    // ±1 ulp around touching the edge ab from below.
    const double tiny = std::nextafter(0.0, 1.0);
    EXPECT_EQ(classify(Vector3d(2, -tiny, -1), Vector3d(2, -tiny, 1)).kind, Kind::none);
    EXPECT_EQ(classify(Vector3d(2, tiny, -1), Vector3d(2, tiny, 1)).kind, Kind::proper);
    // Zero-length segment (a point) on the face is coplanar; above it, nothing.
    EXPECT_EQ(classify(Vector3d(1, 1, 0), Vector3d(1, 1, 0)).kind, Kind::coplanar);
    EXPECT_FALSE(classify(Vector3d(1, 1, 1), Vector3d(1, 1, 1)).intersects());
    // Zero-area triangle: a segment crossing its line is a coplanar contact.
    EXPECT_EQ(segment_triangle_intersection(Vector3d(1, -1, 0), Vector3d(1, 1, 0), a, b,
                                            Vector3d(2, 0, 0))
                  .kind,
              Kind::coplanar);
    EXPECT_FALSE(segment_triangle_intersection(Vector3d(1, -1, 1), Vector3d(1, 1, 1), a, b,
                                               Vector3d(2, 0, 0))
                     .intersects());
}

TEST(SegmentTriangle, MatchesRationalOracleOnSmallGrids) {
    // Coordinates in a small integer grid (then scaled and shifted exactly), so that exact
    // degeneracies — through edges, through vertices, endpoints on the face, coplanar — are common.
    std::mt19937_64 rng(7);
    std::uniform_int_distribution<int> g(-2, 2);
    auto grid = [&] { return Vector3d(g(rng), g(rng), g(rng)); };
    int counts[6] = {0, 0, 0, 0, 0, 0};
    for (int n = 0; n < 60000; ++n) {
        const double scale = n % 3 == 0 ? 0x1p-30 : (n % 3 == 1 ? 1.0 : 0x1p30);
        const Vector3d shift = n % 2 == 0 ? Vector3d(Vector3d::Zero())
                                          : Vector3d(Vector3d(0x1p20, -0x1p21, 0x1p19) * scale);
        const Vector3d s0 = grid() * scale + shift, s1 = grid() * scale + shift;
        const Vector3d a = grid() * scale + shift, b = grid() * scale + shift,
                       c = grid() * scale + shift;
        const auto r = segment_triangle_intersection(s0, s1, a, b, c);
        ++counts[static_cast<int>(r.kind)];
        const auto expected = oracle_segment_triangle(s0, s1, a, b, c);
        if (expected) {
            ASSERT_EQ(r.kind, expected->kind) << "case " << n;
            if (r.kind != Kind::none) {
                ASSERT_EQ(r.feature, expected->feature) << "case " << n;
            }
        } else if (!collinear_q(a, b, c)) {
            // Coplanar with a non-degenerate triangle.
            ASSERT_EQ(r.intersects(), oracle_coplanar_segment_triangle(s0, s1, a, b, c))
                << "coplanar case " << n;
            ASSERT_TRUE(r.kind == Kind::coplanar || r.kind == Kind::none);
        }
    }
    for (int k = 0; k < 6; ++k) {
        EXPECT_GT(counts[k], 50) << "kind " << k << " is not exercised";
    }
}

TEST(PointInTetrahedron, MatchesRationalBarycentricOracle) {
    std::mt19937_64 rng(8);
    std::uniform_int_distribution<int> g(-2, 2);
    auto grid = [&] { return Vector3d(g(rng), g(rng), g(rng)); };
    int inside = 0, boundary_hits = 0;
    for (int n = 0; n < 30000; ++n) {
        const Vector3d a = grid(), b = grid(), c = grid(), d = grid(), p = grid();
        const Q3 qa = oracle::to_q(a), qb = oracle::to_q(b), qc = oracle::to_q(c),
                 qd = oracle::to_q(d), qp = oracle::to_q(p);
        const mpq_class vol = oracle::orient3d_q(qa, qb, qc, qd);
        if (vol == 0) {
            continue;  // flat tetrahedra are checked by hand below
        }
        const mpq_class w0 = oracle::orient3d_q(qp, qb, qc, qd) / vol;
        const mpq_class w1 = oracle::orient3d_q(qa, qp, qc, qd) / vol;
        const mpq_class w2 = oracle::orient3d_q(qa, qb, qp, qd) / vol;
        const mpq_class w3 = 1 - w0 - w1 - w2;
        const bool expected = w0 >= 0 && w1 >= 0 && w2 >= 0 && w3 >= 0;
        boundary_hits += expected && (w0 == 0 || w1 == 0 || w2 == 0 || w3 == 0);
        inside += expected;
        ASSERT_EQ(point_in_tetrahedron(p, a, b, c, d), expected) << "case " << n;
    }
    EXPECT_GT(inside, 100);
    EXPECT_GT(boundary_hits, 50);
}

TEST(PointInTetrahedron, FlatAndDegenerate) {
    const Vector3d a(0, 0, 0), b(2, 0, 0), c(0, 2, 0), d(2, 2, 0);  // flat square
    EXPECT_TRUE(point_in_tetrahedron(Vector3d(1.5, 1.5, 0), a, b, c, d));
    EXPECT_TRUE(point_in_tetrahedron(Vector3d(2, 1, 0), a, b, c, d));
    EXPECT_FALSE(point_in_tetrahedron(Vector3d(1, 1, 1e-300), a, b, c, d));
    EXPECT_FALSE(point_in_tetrahedron(Vector3d(2.5, 1, 0), a, b, c, d));
    const Vector3d e(1, 0, 0);  // collinear a, e, b
    EXPECT_TRUE(point_in_tetrahedron(Vector3d(1.5, 0, 0), a, e, b, a));
    EXPECT_FALSE(point_in_tetrahedron(Vector3d(1.5, 1e-300, 0), a, e, b, a));
    // Regular tetrahedron: vertex, face, outside by one ulp.
    const Vector3d t0(0, 0, 0), t1(1, 0, 0), t2(0, 1, 0), t3(0, 0, 1);
    EXPECT_TRUE(point_in_tetrahedron(t3, t0, t1, t2, t3));
    EXPECT_TRUE(point_in_tetrahedron(Vector3d(0.25, 0.25, 0), t0, t1, t2, t3));
    EXPECT_FALSE(
        point_in_tetrahedron(Vector3d(0.25, 0.25, -std::nextafter(0.0, 1.0)), t0, t1, t2, t3));
    EXPECT_TRUE(point_in_tetrahedron(Vector3d(0.25, 0.25, 0.5), t3, t1, t2, t0));  // orientation
}

TEST(TrianglesIntersect, SharedVerticesDoNotCount) {
    using T = std::array<Vector3d, 3>;
    using I = std::array<int, 3>;
    const Vector3d o(0, 0, 0), x(1, 0, 0), y(0, 1, 0), z(0, 0, 1), mx(-1, 0, 0), my(0, -1, 0);
    // Two triangles of a flat fan sharing an edge: no intersection.
    EXPECT_FALSE(triangles_intersect(T{o, x, y}, I{0, 1, 2}, T{o, y, mx}, I{0, 2, 3}));
    // Folded flat onto each other across the shared edge o–y: intersection.
    EXPECT_TRUE(
        triangles_intersect(T{o, x, y}, I{0, 1, 2}, T{o, y, Vector3d(0.5, 0.5, 0)}, I{0, 2, 3}));
    // Dihedral angle (not coplanar): only the edge is shared.
    EXPECT_FALSE(triangles_intersect(T{o, x, y}, I{0, 1, 2}, T{o, y, z}, I{0, 2, 3}));
    // Sharing one vertex, opposite quadrants in the plane: touching at o only.
    EXPECT_FALSE(triangles_intersect(T{o, x, y}, I{0, 1, 2}, T{o, mx, my}, I{0, 3, 4}));
    // Sharing one vertex, overlapping wedges in the plane.
    EXPECT_TRUE(
        triangles_intersect(T{o, x, y}, I{0, 1, 2}, T{o, Vector3d(1, 1, 0), my}, I{0, 3, 4}));
    // Sharing one vertex, edge of one running along an edge of the other from o.
    EXPECT_TRUE(
        triangles_intersect(T{o, x, y}, I{0, 1, 2}, T{o, Vector3d(2, 0, 0), my}, I{0, 3, 4}));
    // Sharing one vertex, the other triangle pierced by an opposite edge.
    EXPECT_TRUE(triangles_intersect(T{o, Vector3d(2, 2, -1), Vector3d(2, 2, 1)}, I{0, 1, 2},
                                    T{o, Vector3d(4, 0, 0), Vector3d(0, 4, 0)}, I{0, 3, 4}));
    // Sharing one vertex, the other triangle only out of plane: touching at o only.
    EXPECT_FALSE(
        triangles_intersect(T{o, x, y}, I{0, 1, 2}, T{o, z, Vector3d(-1, -1, 1)}, I{0, 3, 4}));
    // No shared vertex but the same positions as the shared-vertex case: touching counts.
    EXPECT_TRUE(triangles_intersect(T{o, x, y}, I{0, 1, 2}, T{o, mx, my}, I{5, 3, 4}));
    // No shared vertex, crossing, separated, separated by one ulp.
    EXPECT_TRUE(triangles_intersect(
        T{o, x, y}, I{0, 1, 2}, T{Vector3d(0.2, 0.2, -1), Vector3d(0.2, 0.2, 1), Vector3d(5, 5, 0)},
        I{3, 4, 5}));
    const double up = std::nextafter(0.0, 1.0);
    EXPECT_FALSE(triangles_intersect(T{o, x, y}, I{0, 1, 2},
                                     T{Vector3d(0, 0, up), Vector3d(1, 0, up), Vector3d(0, 1, up)},
                                     I{3, 4, 5}));
    EXPECT_TRUE(triangles_intersect(T{o, x, y}, I{0, 1, 2},
                                    T{Vector3d(0, 0, 0), Vector3d(1, 0, up), Vector3d(0, 1, up)},
                                    I{3, 4, 5}));
    // Duplicated triangle.
    EXPECT_FALSE(triangles_intersect(T{o, x, y}, I{0, 1, 2}, T{y, o, x}, I{2, 0, 1}));
    // Vertex order of either triangle does not matter.
    EXPECT_TRUE(
        triangles_intersect(T{o, y, Vector3d(0.5, 0.5, 0)}, I{0, 2, 3}, T{x, y, o}, I{1, 2, 0}));
}

TEST(TrianglesIntersect, SharedVertexRandomAgreesWithPerturbedDefinition) {
    // For triangles sharing vertex s by index, the answer must equal "the two triangles, with
    // the shared vertex's corner shrunk away, intersect" whenever that shrinking is exact:
    // use s as a corner and test the other triangle against the sub-triangle beyond its edge
    // midpoints. Only one direction is implied (shrunk ⊂ original): shrunk-intersect ⇒ true.
    std::mt19937_64 rng(9);
    std::uniform_int_distribution<int> g(-2, 2);
    auto grid = [&] { return Vector3d(2 * g(rng), 2 * g(rng), 2 * g(rng)); };
    int positives = 0;
    for (int n = 0; n < 20000; ++n) {
        const Vector3d s = grid(), p1 = grid(), p2 = grid(), q1 = grid(), q2 = grid();
        if (collinear_q(s, p1, p2)) {
            continue;  // the shrunk quadrilateral would contain s
        }
        const bool answer = triangles_intersect({s, p1, p2}, {0, 1, 2}, {s, q1, q2}, {0, 3, 4});
        const Vector3d m1 = 0.5 * (s + p1), m2 = 0.5 * (s + p2);
        const std::array<Vector3d, 3> q{s, q1, q2};
        // Quadrilateral m1, p1, p2, m2 = triangles (m1, p1, p2) and (m1, p2, m2): away from s.
        const bool shrunk = triangles_intersect({m1, p1, p2}, {10, 11, 12}, q, {13, 14, 15}) ||
                            triangles_intersect({m1, p2, m2}, {10, 12, 16}, q, {13, 14, 15});
        if (shrunk) {
            ++positives;
            ASSERT_TRUE(answer) << "case " << n;
        }
        ASSERT_EQ(answer, triangles_intersect({p1, p2, s}, {1, 2, 0}, {q2, s, q1}, {4, 0, 3}))
            << "vertex order changed the answer, case " << n;
    }
    EXPECT_GT(positives, 100);
}

TEST(SegmentsIntersect, CollinearAndSkew) {
    const Vector3d a(0, 0, 0), b(2, 2, 2);
    EXPECT_TRUE(segments_intersect(a, b, Vector3d(1, 1, 1), Vector3d(3, 3, 3)));
    EXPECT_TRUE(segments_intersect(a, b, b, Vector3d(3, 3, 3)));
    EXPECT_FALSE(segments_intersect(a, b, Vector3d(2.5, 2.5, 2.5), Vector3d(3, 3, 3)));
    EXPECT_TRUE(segments_intersect(a, b, Vector3d(0, 2, 0), Vector3d(2, 0, 2)));
    EXPECT_FALSE(segments_intersect(a, b, Vector3d(0, 2, 0), Vector3d(2, 0, 2.000001)));
    EXPECT_TRUE(segments_intersect(a, a, a, b));
    EXPECT_FALSE(segments_intersect(a, a, b, b));
}

}  // namespace
}  // namespace meniscus::tracker
