#include "tracker/polygon_triangulation.h"

#include "tracker/predicates.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace meniscus::tracker {

namespace {

using Vec2 = Eigen::Vector2d;

/// Is the direction v → x strictly inside the polygon's angle at v, the interior lying to the
/// left of the boundary edges u → v and v → w?
bool in_cone(const Vec2& u, const Vec2& v, const Vec2& w, const Vec2& x) {
    if (orient2d(u, v, w) > 0)  // convex corner: left of both edges
        return orient2d(u, v, x) > 0 && orient2d(v, w, x) > 0;
    return orient2d(u, v, x) > 0 || orient2d(v, w, x) > 0;  // reflex, straight or a spike
}

/// q on the closed segment ab, given that the three are collinear.
bool within(const Vec2& a, const Vec2& b, const Vec2& q) {
    return std::min(a.x(), b.x()) <= q.x() && q.x() <= std::max(a.x(), b.x()) &&
           std::min(a.y(), b.y()) <= q.y() && q.y() <= std::max(a.y(), b.y());
}

/// Do the closed segments ab and cd share a point? Exact.
bool segments_meet(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
    const int o1 = orient2d(a, b, c), o2 = orient2d(a, b, d);
    const int o3 = orient2d(c, d, a), o4 = orient2d(c, d, b);
    if (o1 * o2 < 0 && o3 * o4 < 0)
        return true;
    return (o1 == 0 && within(a, b, c)) || (o2 == 0 && within(a, b, d)) ||
           (o3 == 0 && within(c, d, a)) || (o4 == 0 && within(c, d, b));
}

/// Do a → b and a → c point the same way along one line (b, c collinear with a, neither = a)?
bool same_direction(const Vec2& a, const Vec2& b, const Vec2& c) {
    const auto sign = [](double s) { return (s > 0.0) - (s < 0.0); };
    return sign(b.x() - a.x()) == sign(c.x() - a.x()) && sign(b.y() - a.y()) == sign(c.y() - a.y());
}

/// May the bridge m–p be drawn past the boundary edge cd? It may not cross it or run along it;
/// an edge from one of the bridge's own end points may touch it there.
bool bridge_clears_edge(const Vec2& m, const Vec2& p, const Vec2& c, const Vec2& d) {
    const bool c_end = c == m || c == p;
    const bool d_end = d == m || d == p;
    if (c_end && d_end)
        return !(c == d) && !((c == m && d == p) || (c == p && d == m));
    if (c_end || d_end) {
        const Vec2& shared = c_end ? c : d;
        const Vec2& other = c_end ? d : c;
        const Vec2& far_end = shared == m ? p : m;
        return orient2d(m, p, other) != 0 || !same_direction(shared, other, far_end);
    }
    return !segments_meet(m, p, c, d);
}

/// The loop's position after / before position i.
int next_in(const std::vector<int>& loop, size_t i) {
    return loop[(i + 1) % loop.size()];
}
int prev_in(const std::vector<int>& loop, size_t i) {
    return loop[(i + loop.size() - 1) % loop.size()];
}

/// Joins `hole` (clockwise) into `ring` (the boundary so far) by the shortest admissible bridge
/// from the hole's rightmost vertex; `others` are the holes not joined yet (they must not be
/// crossed). Returns false when no vertex of the ring can be reached.
bool join_hole(const std::vector<Vec2>& pts, std::vector<int>& ring, const std::vector<int>& hole,
               const std::vector<const std::vector<int>*>& others) {
    size_t mi = 0;
    for (size_t i = 1; i < hole.size(); ++i) {
        const Vec2& a = pts[static_cast<size_t>(hole[i])];
        const Vec2& b = pts[static_cast<size_t>(hole[mi])];
        if (a.x() > b.x() || (a.x() == b.x() && a.y() > b.y()))
            mi = i;
    }
    const Vec2& m = pts[static_cast<size_t>(hole[mi])];
    const Vec2& m_prev = pts[static_cast<size_t>(prev_in(hole, mi))];
    const Vec2& m_next = pts[static_cast<size_t>(next_in(hole, mi))];
    std::vector<size_t> order(ring.size());
    std::iota(order.begin(), order.end(), size_t{0});
    const auto distance2 = [&](size_t i) {
        return (pts[static_cast<size_t>(ring[i])] - m).squaredNorm();
    };
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return distance2(a) < distance2(b); });
    const auto clears_loop = [&](const std::vector<int>& loop, const Vec2& p) {
        for (size_t i = 0; i < loop.size(); ++i)
            if (!bridge_clears_edge(m, p, pts[static_cast<size_t>(loop[i])],
                                    pts[static_cast<size_t>(next_in(loop, i))]))
                return false;
        return true;
    };
    for (size_t pi : order) {
        const Vec2& p = pts[static_cast<size_t>(ring[pi])];
        if (p == m)
            continue;
        if (!in_cone(pts[static_cast<size_t>(prev_in(ring, pi))], p,
                     pts[static_cast<size_t>(next_in(ring, pi))], m) ||
            !in_cone(m_prev, m, m_next, p))
            continue;
        bool clear = clears_loop(ring, p) && clears_loop(hole, p);
        for (const std::vector<int>* other : others)
            clear = clear && clears_loop(*other, p);
        if (!clear)
            continue;
        // ring: …, p, m, (the hole from m round to m), m, p, …
        std::vector<int> spliced;
        spliced.reserve(ring.size() + hole.size() + 2);
        spliced.insert(spliced.end(), ring.begin(), ring.begin() + static_cast<long>(pi) + 1);
        for (size_t k = 0; k <= hole.size(); ++k)
            spliced.push_back(hole[(mi + k) % hole.size()]);
        spliced.insert(spliced.end(), ring.begin() + static_cast<long>(pi), ring.end());
        ring = std::move(spliced);
        return true;
    }
    return false;
}

/// Ear clipping of the (weakly simple, counter-clockwise) ring.
bool clip_ears(const std::vector<Vec2>& pts, const std::vector<int>& ring,
               std::vector<std::array<int, 3>>& triangles) {
    const int n = static_cast<int>(ring.size());
    std::vector<int> prev(static_cast<size_t>(n)), next(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
        prev[static_cast<size_t>(i)] = (i + n - 1) % n;
        next[static_cast<size_t>(i)] = (i + 1) % n;
    }
    const auto at = [&](int node) -> const Vec2& {
        return pts[static_cast<size_t>(ring[static_cast<size_t>(node)])];
    };
    // The interior of the counter-clockwise triangle (t[0], t[1], t[2]) near its corner k.
    const auto enters = [&](const std::array<const Vec2*, 3>& t, int k, const Vec2& y) {
        const Vec2& corner = *t[static_cast<size_t>(k)];
        return orient2d(corner, *t[static_cast<size_t>((k + 1) % 3)], y) > 0 &&
               orient2d(*t[static_cast<size_t>((k + 2) % 3)], corner, y) > 0;
    };
    const auto is_ear = [&](int b) {
        const int a = prev[static_cast<size_t>(b)], c = next[static_cast<size_t>(b)];
        const std::array<const Vec2*, 3> t = {&at(a), &at(b), &at(c)};
        if (orient2d(*t[0], *t[1], *t[2]) <= 0)
            return false;
        for (int q = next[static_cast<size_t>(c)]; q != a; q = next[static_cast<size_t>(q)]) {
            const Vec2& x = at(q);
            int corner = -1;
            for (int k = 0; k < 3; ++k)
                if (x == *t[static_cast<size_t>(k)])
                    corner = k;
            if (corner < 0) {
                if (orient2d(*t[0], *t[1], x) >= 0 && orient2d(*t[1], *t[2], x) >= 0 &&
                    orient2d(*t[2], *t[0], x) >= 0)
                    return false;
                continue;
            }
            // A copy of a corner (a bridge's end): its boundary edges must not lead inside.
            for (int y : {prev[static_cast<size_t>(q)], next[static_cast<size_t>(q)]})
                if (!(at(y) == x) && enters(t, corner, at(y)))
                    return false;
        }
        return true;
    };
    int remaining = n;
    int node = 0;
    int tried = 0;
    while (remaining > 3) {
        if (is_ear(node)) {
            const int a = prev[static_cast<size_t>(node)], c = next[static_cast<size_t>(node)];
            triangles.push_back({ring[static_cast<size_t>(a)], ring[static_cast<size_t>(node)],
                                 ring[static_cast<size_t>(c)]});
            next[static_cast<size_t>(a)] = c;
            prev[static_cast<size_t>(c)] = a;
            --remaining;
            tried = 0;
            node = c;
            continue;
        }
        node = next[static_cast<size_t>(node)];
        if (++tried > remaining)
            return false;
    }
    const int a = prev[static_cast<size_t>(node)], c = next[static_cast<size_t>(node)];
    if (orient2d(at(a), at(node), at(c)) <= 0)
        return false;
    triangles.push_back({ring[static_cast<size_t>(a)], ring[static_cast<size_t>(node)],
                         ring[static_cast<size_t>(c)]});
    return true;
}

}  // namespace

double loop_signed_area(const std::vector<Eigen::Vector2d>& points, const std::vector<int>& loop) {
    double twice = 0.0;
    for (size_t i = 0; i < loop.size(); ++i) {
        const Vec2& a = points[static_cast<size_t>(loop[i])];
        const Vec2& b = points[static_cast<size_t>(next_in(loop, i))];
        twice += a.x() * b.y() - a.y() * b.x();
    }
    return 0.5 * twice;
}

bool point_in_loop(const std::vector<Eigen::Vector2d>& points, const std::vector<int>& loop,
                   const Eigen::Vector2d& q) {
    // Crossings of the ray from q towards +x, counting an edge when it goes from strictly below
    // q to on-or-above it (or back), with the side decided exactly.
    bool inside = false;
    for (size_t i = 0; i < loop.size(); ++i) {
        const Vec2& a = points[static_cast<size_t>(loop[i])];
        const Vec2& b = points[static_cast<size_t>(next_in(loop, i))];
        const int o = orient2d(a, b, q);
        if (o == 0 && within(a, b, q))
            return false;  // on the loop
        if ((a.y() > q.y()) != (b.y() > q.y())) {
            // The edge crosses the ray's line; it is right of q iff q is left of the upward edge.
            const bool upward = b.y() > a.y();
            if ((o > 0) == upward)
                inside = !inside;
        }
    }
    return inside;
}

PolygonTriangulation triangulate_polygon(const std::vector<Eigen::Vector2d>& points,
                                         const PolygonWithHoles& polygon) {
    const auto check = [&](const std::vector<int>& loop) {
        for (int i : loop)
            if (i < 0 || static_cast<size_t>(i) >= points.size())
                throw std::invalid_argument(
                    "triangulate_polygon: a loop index is outside the points");
    };
    check(polygon.outer);
    for (const std::vector<int>& hole : polygon.holes)
        check(hole);
    PolygonTriangulation result;
    if (polygon.outer.size() < 3 || loop_signed_area(points, polygon.outer) <= 0.0) {
        result.failure = "the outer loop has fewer than 3 vertices or is not counter-clockwise";
        return result;
    }
    for (const std::vector<int>& hole : polygon.holes)
        if (hole.size() < 3 || loop_signed_area(points, hole) >= 0.0) {
            result.failure = "a hole has fewer than 3 vertices or is not clockwise";
            return result;
        }
    // Rightmost hole first, so that each bridge sees the holes to its right already joined.
    std::vector<const std::vector<int>*> holes;
    for (const std::vector<int>& hole : polygon.holes)
        holes.push_back(&hole);
    const auto rightmost = [&](const std::vector<int>* loop) {
        double x = -std::numeric_limits<double>::infinity();
        for (int i : *loop)
            x = std::max(x, points[static_cast<size_t>(i)].x());
        return x;
    };
    std::stable_sort(holes.begin(), holes.end(),
                     [&](const auto* a, const auto* b) { return rightmost(a) > rightmost(b); });
    std::vector<int> ring = polygon.outer;
    for (size_t h = 0; h < holes.size(); ++h) {
        const std::vector<const std::vector<int>*> others(holes.begin() + static_cast<long>(h) + 1,
                                                          holes.end());
        if (!join_hole(points, ring, *holes[h], others)) {
            result.failure = "no bridge from a hole to the outer boundary";
            return result;
        }
    }
    if (!clip_ears(points, ring, result.triangles)) {
        result.triangles.clear();
        result.failure = "no ear left to clip (a loop that is not simple, or collinear runs)";
        return result;
    }
    result.ok = true;
    return result;
}

}  // namespace meniscus::tracker
