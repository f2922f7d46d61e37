#include "tracker/intersection.h"

#include "tracker/predicates.h"

#include <algorithm>

namespace meniscus::tracker {
namespace {

using Eigen::Vector3d;

/// A projection axis (0, 1, 2) along which non-collinear a, b, c project to a non-degenerate
/// triangle (always exists), or -1 when a, b, c are collinear.
int projection_axis(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
    for (int axis = 0; axis < 3; ++axis) {
        if (orient2d_projected(a, b, c, axis) != 0) {
            return axis;
        }
    }
    return -1;
}

/// The two extreme points of collinear points (their convex hull is the segment between them).
/// Collinear points are ordered the same way along every axis on which they are not all equal.
void hull_of_collinear(const std::array<Vector3d, 3>& points, Vector3d& lo, Vector3d& hi) {
    int axis = 0;
    for (int k = 0; k < 3; ++k) {
        if (points[0][k] != points[1][k] || points[0][k] != points[2][k]) {
            axis = k;
            break;
        }
    }
    lo = hi = points[0];
    for (const Vector3d& p : points) {
        if (p[axis] < lo[axis]) {
            lo = p;
        }
        if (p[axis] > hi[axis]) {
            hi = p;
        }
    }
}

/// p (known collinear with a and b) lies within the bounding box of [a, b], i.e. on the segment.
bool within_bounds(const Vector3d& p, const Vector3d& a, const Vector3d& b) {
    for (int k = 0; k < 3; ++k) {
        if (p[k] < std::min(a[k], b[k]) || p[k] > std::max(a[k], b[k])) {
            return false;
        }
    }
    return true;
}

bool point_on_segment(const Vector3d& p, const Vector3d& a, const Vector3d& b) {
    return collinear3d(p, a, b) && within_bounds(p, a, b);
}

/// Closed 2D segment intersection in the projection dropping `axis` (inputs coplanar and the
/// projection injective on their plane, or all collinear with the projection injective on it).
bool segments_intersect_projected(const Vector3d& p0, const Vector3d& p1, const Vector3d& q0,
                                  const Vector3d& q1, int axis) {
    const int d0 = orient2d_projected(q0, q1, p0, axis);
    const int d1 = orient2d_projected(q0, q1, p1, axis);
    const int d2 = orient2d_projected(p0, p1, q0, axis);
    const int d3 = orient2d_projected(p0, p1, q1, axis);
    if (d0 * d1 < 0 && d2 * d3 < 0) {
        return true;
    }
    return (d0 == 0 && within_bounds(p0, q0, q1)) || (d1 == 0 && within_bounds(p1, q0, q1)) ||
           (d2 == 0 && within_bounds(q0, p0, p1)) || (d3 == 0 && within_bounds(q1, p0, p1));
}

/// p in the closed 2D triangle (a, b, c), non-degenerate in the projection dropping `axis`.
bool point_in_triangle_projected(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                                 const Vector3d& c, int axis) {
    const int o = orient2d_projected(a, b, c, axis);
    return orient2d_projected(a, b, p, axis) * o >= 0 &&
           orient2d_projected(b, c, p, axis) * o >= 0 && orient2d_projected(c, a, p, axis) * o >= 0;
}

/// Coplanar segment [s0, s1] against the non-degenerate triangle (a, b, c).
bool coplanar_segment_meets_triangle(const Vector3d& s0, const Vector3d& s1, const Vector3d& a,
                                     const Vector3d& b, const Vector3d& c) {
    const int axis = projection_axis(a, b, c);
    return point_in_triangle_projected(s0, a, b, c, axis) ||
           point_in_triangle_projected(s1, a, b, c, axis) ||
           segments_intersect_projected(s0, s1, a, b, axis) ||
           segments_intersect_projected(s0, s1, b, c, axis) ||
           segments_intersect_projected(s0, s1, c, a, axis);
}

TriangleFeature feature_from_zeros(int s_ab, int s_bc, int s_ca) {
    const int zeros = (s_ab == 0) + (s_bc == 0) + (s_ca == 0);
    if (zeros == 0) {
        return TriangleFeature::interior;
    }
    if (zeros == 1) {
        return s_ab == 0 ? TriangleFeature::edge_ab
                         : (s_bc == 0 ? TriangleFeature::edge_bc : TriangleFeature::edge_ca);
    }
    if (s_ab == 0 && s_ca == 0) {
        return TriangleFeature::vertex_a;
    }
    return s_ab == 0 ? TriangleFeature::vertex_b : TriangleFeature::vertex_c;
}

/// Same direction of x - s and t - s, for x, t collinear with s and t != s.
bool same_direction(const Vector3d& s, const Vector3d& x, const Vector3d& t) {
    for (int k = 0; k < 3; ++k) {
        if (t[k] != s[k]) {
            return (x[k] - s[k] > 0) == (t[k] - s[k] > 0) && x[k] != s[k];
        }
    }
    return false;
}

/// Does segment s→x, without s, meet the closed triangle (s, t1, t2) arbitrarily close to s —
/// i.e. is x - s a nonzero direction of the triangle's tangent cone at its vertex s?
bool enters_triangle_at_vertex(const Vector3d& s, const Vector3d& x, const Vector3d& t1,
                               const Vector3d& t2) {
    if (x == s) {
        return false;
    }
    const int axis = projection_axis(s, t1, t2);
    if (axis >= 0) {
        if (orient3d(s, t1, t2, x) != 0) {
            return false;
        }
        const int o = orient2d_projected(s, t1, t2, axis);
        return orient2d_projected(s, t1, x, axis) * o >= 0 &&
               orient2d_projected(s, x, t2, axis) * o >= 0;
    }
    // Zero-area triangle: its tangent cone at s is spanned by the nonzero ones of t1 - s, t2 - s.
    for (const Vector3d* t : {&t1, &t2}) {
        if (*t != s && collinear3d(s, *t, x) && same_direction(s, x, *t)) {
            return true;
        }
    }
    return false;
}

bool share_none(const std::array<Vector3d, 3>& p, const std::array<Vector3d, 3>& q) {
    for (int i = 0; i < 3; ++i) {
        if (segment_triangle_intersection(p[i], p[(i + 1) % 3], q[0], q[1], q[2]).intersects() ||
            segment_triangle_intersection(q[i], q[(i + 1) % 3], p[0], p[1], p[2]).intersects()) {
            return true;
        }
    }
    return false;
}

/// Triangles (s, p1, p2) and (s, q1, q2).
bool share_vertex(const Vector3d& s, const Vector3d& p1, const Vector3d& p2, const Vector3d& q1,
                  const Vector3d& q2) {
    return segment_triangle_intersection(p1, p2, s, q1, q2).intersects() ||
           segment_triangle_intersection(q1, q2, s, p1, p2).intersects() ||
           enters_triangle_at_vertex(s, p1, q1, q2) || enters_triangle_at_vertex(s, p2, q1, q2) ||
           enters_triangle_at_vertex(s, q1, p1, p2) || enters_triangle_at_vertex(s, q2, p1, p2);
}

/// Triangles (s0, s1, p) and (s0, s1, q).
bool share_edge(const Vector3d& s0, const Vector3d& s1, const Vector3d& p, const Vector3d& q) {
    if (orient3d(s0, s1, p, q) != 0) {
        return false;
    }
    const bool p_flat = collinear3d(s0, s1, p);
    const bool q_flat = collinear3d(s0, s1, q);
    if (!p_flat && !q_flat) {
        const int axis = projection_axis(s0, s1, q);
        return orient2d_projected(s0, s1, p, axis) == orient2d_projected(s0, s1, q, axis);
    }
    if (p_flat != q_flat) {
        // A zero-area triangle lies on the edge's line, which meets the other triangle in e only.
        return false;
    }
    if (s0 == s1) {
        // Both are segments from s0: they overlap beyond s0 iff they leave it the same way.
        return p != s0 && q != s0 && collinear3d(s0, p, q) && same_direction(s0, p, q);
    }
    // Both on the edge's line: they overlap beyond e iff p and q stick out past the same end.
    auto beyond = [](const Vector3d& end, const Vector3d& other_end, const Vector3d& x) {
        for (int k = 0; k < 3; ++k) {
            if (end[k] != other_end[k]) {
                return x[k] != end[k] && (x[k] > end[k]) == (end[k] > other_end[k]);
            }
        }
        return false;
    };
    return (beyond(s1, s0, p) && beyond(s1, s0, q)) || (beyond(s0, s1, p) && beyond(s0, s1, q));
}

}  // namespace

SegmentTriangleIntersection segment_triangle_intersection(const Vector3d& s0, const Vector3d& s1,
                                                          const Vector3d& a, const Vector3d& b,
                                                          const Vector3d& c) {
    SegmentTriangleIntersection out;
    const int o0 = orient3d(a, b, c, s0);
    const int o1 = orient3d(a, b, c, s1);
    if (o0 == 0 && o1 == 0) {
        bool meets = false;
        if (projection_axis(a, b, c) >= 0) {
            meets = coplanar_segment_meets_triangle(s0, s1, a, b, c);
        } else {
            Vector3d lo, hi;
            hull_of_collinear({a, b, c}, lo, hi);
            meets = segments_intersect(s0, s1, lo, hi);
        }
        if (meets) {
            out.kind = SegmentTriangleContact::coplanar;
        }
        return out;
    }
    if (o0 == o1) {
        return out;  // strictly on one side
    }
    const int s_ab = orient3d(s0, s1, a, b);
    const int s_bc = orient3d(s0, s1, b, c);
    const int s_ca = orient3d(s0, s1, c, a);
    const bool has_positive = s_ab > 0 || s_bc > 0 || s_ca > 0;
    const bool has_negative = s_ab < 0 || s_bc < 0 || s_ca < 0;
    if (has_positive && has_negative) {
        return out;  // the line passes beside the triangle
    }
    out.feature = feature_from_zeros(s_ab, s_bc, s_ca);
    if (o0 == 0 || o1 == 0) {
        out.kind = SegmentTriangleContact::endpoint_on_triangle;
        out.segment_endpoint = o0 == 0 ? 0 : 1;
        return out;
    }
    switch (out.feature) {
        case TriangleFeature::interior:
            out.kind = SegmentTriangleContact::proper;
            break;
        case TriangleFeature::edge_ab:
        case TriangleFeature::edge_bc:
        case TriangleFeature::edge_ca:
            out.kind = SegmentTriangleContact::through_edge;
            break;
        default:
            out.kind = SegmentTriangleContact::through_vertex;
            break;
    }
    return out;
}

bool segments_intersect(const Vector3d& p0, const Vector3d& p1, const Vector3d& q0,
                        const Vector3d& q1) {
    if (orient3d(p0, p1, q0, q1) != 0) {
        return false;
    }
    // Coplanar: find a projection injective on a plane containing all four points.
    for (const auto& tri :
         {std::array<Vector3d, 3>{p0, p1, q0}, std::array<Vector3d, 3>{p0, p1, q1},
          std::array<Vector3d, 3>{p0, q0, q1}, std::array<Vector3d, 3>{p1, q0, q1}}) {
        const int axis = projection_axis(tri[0], tri[1], tri[2]);
        if (axis >= 0) {
            return segments_intersect_projected(p0, p1, q0, q1, axis);
        }
    }
    // All four collinear (or coincident): intervals on the common line.
    return point_on_segment(p0, q0, q1) || point_on_segment(p1, q0, q1) ||
           point_on_segment(q0, p0, p1) || point_on_segment(q1, p0, p1);
}

bool point_in_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
    const int axis = projection_axis(a, b, c);
    if (axis >= 0) {
        return orient3d(a, b, c, p) == 0 && point_in_triangle_projected(p, a, b, c, axis);
    }
    Vector3d lo, hi;
    hull_of_collinear({a, b, c}, lo, hi);
    return point_on_segment(p, lo, hi);
}

bool point_in_tetrahedron(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                          const Vector3d& c, const Vector3d& d) {
    const int o = orient3d(a, b, c, d);
    if (o != 0) {
        return orient3d(p, b, c, d) * o >= 0 && orient3d(a, p, c, d) * o >= 0 &&
               orient3d(a, b, p, d) * o >= 0 && orient3d(a, b, c, p) * o >= 0;
    }
    // Flat tetrahedron: its hull is covered by the four triangles on its vertex triples.
    return point_in_triangle(p, a, b, c) || point_in_triangle(p, a, b, d) ||
           point_in_triangle(p, a, c, d) || point_in_triangle(p, b, c, d);
}

bool triangles_intersect(const std::array<Vector3d, 3>& t1, const std::array<int, 3>& t1_vertices,
                         const std::array<Vector3d, 3>& t2, const std::array<int, 3>& t2_vertices) {
    // shared_in_2[i]: position in t2 of t1's vertex i, or -1.
    std::array<int, 3> shared_in_2{-1, -1, -1};
    int shared = 0;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            if (t1_vertices[i] == t2_vertices[j]) {
                shared_in_2[i] = j;
                ++shared;
            }
        }
    }
    if (shared == 0) {
        return share_none(t1, t2);
    }
    if (shared == 1) {
        const int i = shared_in_2[0] >= 0 ? 0 : (shared_in_2[1] >= 0 ? 1 : 2);
        const int j = shared_in_2[i];
        return share_vertex(t1[i], t1[(i + 1) % 3], t1[(i + 2) % 3], t2[(j + 1) % 3],
                            t2[(j + 2) % 3]);
    }
    if (shared == 2) {
        const int free1 = shared_in_2[0] < 0 ? 0 : (shared_in_2[1] < 0 ? 1 : 2);
        const int i0 = (free1 + 1) % 3;
        const int i1 = (free1 + 2) % 3;
        const int free2 = 3 - shared_in_2[i0] - shared_in_2[i1];
        // The shared edge's positions are taken from t1 (same vertices, same positions).
        return share_edge(t1[i0], t1[i1], t1[free1], t2[free2]);
    }
    return false;
}

}  // namespace meniscus::tracker
