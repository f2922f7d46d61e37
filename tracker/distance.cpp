#include "tracker/distance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace meniscus::tracker {
namespace {

/// A distance below this fraction of the query's length scale is not trusted to give a
/// direction (rounding in p - q is ~1e-16 of the scale).
constexpr double RESOLVABLE_DISTANCE_FRACTION = 1e-10;
/// Triangles (edge pairs) whose squared sine of angle is below this are treated as degenerate
/// (parallel): sine below 1e-10.
constexpr double DEGENERATE_SINE_SQUARED = 1e-20;

double clamp01(double x) {
    return std::min(1.0, std::max(0.0, x));
}

/// Parameter of the closest point of segment [a, b] to p (0 for a zero-length segment).
double closest_segment_parameter(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                 const Eigen::Vector3d& b) {
    const Eigen::Vector3d e = b - a;
    const double ee = e.squaredNorm();
    return ee > 0.0 ? clamp01((p - a).dot(e) / ee) : 0.0;
}

/// Unit vector orthogonal to `axis` (unit): `preferred` projected out of `axis` when that
/// leaves something, else an arbitrary orthogonal vector.
Eigen::Vector3d orthogonal_direction(const Eigen::Vector3d& axis,
                                     const Eigen::Vector3d& preferred) {
    const Eigen::Vector3d projected = preferred - preferred.dot(axis) * axis;
    if (projected.squaredNorm() > DEGENERATE_SINE_SQUARED * preferred.squaredNorm() &&
        projected.squaredNorm() > 0.0) {
        return projected.normalized();
    }
    int smallest = 0;
    for (int k = 1; k < 3; ++k) {
        if (std::abs(axis[k]) < std::abs(axis[smallest])) {
            smallest = k;
        }
    }
    return axis.cross(Eigen::Vector3d::Unit(smallest)).normalized();
}

/// Normal when the primitives' own geometry gives no direction: `fallback` orthogonal to
/// `longest` (if nonzero), else `fallback`, else +x.
Eigen::Vector3d degenerate_normal(const Eigen::Vector3d& longest, const Eigen::Vector3d& fallback) {
    if (longest.squaredNorm() > 0.0) {
        return orthogonal_direction(longest.normalized(), fallback);
    }
    if (fallback.squaredNorm() > 0.0) {
        return fallback.normalized();
    }
    return Eigen::Vector3d::UnitX();
}

/// `unit_normal` flipped to have a non-negative component along `gap`, else along `fallback`.
Eigen::Vector3d oriented(const Eigen::Vector3d& unit_normal, const Eigen::Vector3d& gap,
                         const Eigen::Vector3d& fallback) {
    const double along_gap = unit_normal.dot(gap);
    if (along_gap != 0.0) {
        return along_gap > 0.0 ? unit_normal : Eigen::Vector3d(-unit_normal);
    }
    return unit_normal.dot(fallback) < 0.0 ? Eigen::Vector3d(-unit_normal) : unit_normal;
}

const Eigen::Vector3d& longest_of(const Eigen::Vector3d& x, const Eigen::Vector3d& y,
                                  const Eigen::Vector3d& z) {
    const Eigen::Vector3d* best = &x;
    if (y.squaredNorm() > best->squaredNorm()) {
        best = &y;
    }
    if (z.squaredNorm() > best->squaredNorm()) {
        best = &z;
    }
    return *best;
}

}  // namespace

PointTriangleProximity point_triangle_proximity(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                                const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                                const Eigen::Vector3d& fallback_direction) {
    const Eigen::Vector3d e0 = b - a;
    const Eigen::Vector3d e1 = c - a;
    const Eigen::Vector3d e2 = c - b;
    const Eigen::Vector3d n = e0.cross(e1);
    const double nn = n.squaredNorm();
    const bool degenerate =
        !(nn > DEGENERATE_SINE_SQUARED * e0.squaredNorm() * e1.squaredNorm()) || nn == 0.0;

    PointTriangleProximity out;
    bool interior = false;
    if (!degenerate) {
        const Eigen::Vector3d w = p - a;
        const double beta = w.cross(e1).dot(n) / nn;
        const double gamma = e0.cross(w).dot(n) / nn;
        if (beta >= 0.0 && gamma >= 0.0 && beta + gamma <= 1.0) {
            out.barycentric = {1.0 - beta - gamma, beta, gamma};
            interior = true;
        }
    }
    if (!interior) {
        // The closest point lies on the boundary: best of the three edges.
        const double t_ab = closest_segment_parameter(p, a, b);
        const double t_bc = closest_segment_parameter(p, b, c);
        const double t_ca = closest_segment_parameter(p, c, a);
        const std::array<std::array<double, 3>, 3> candidates{
            {{1.0 - t_ab, t_ab, 0.0}, {0.0, 1.0 - t_bc, t_bc}, {t_ca, 0.0, 1.0 - t_ca}}};
        double best = std::numeric_limits<double>::infinity();
        for (const auto& bary : candidates) {
            const double d2 = (p - (bary[0] * a + bary[1] * b + bary[2] * c)).squaredNorm();
            if (d2 < best) {
                best = d2;
                out.barycentric = bary;
            }
        }
    }
    const auto& bary = out.barycentric;
    const Eigen::Vector3d gap = p - (bary[0] * a + bary[1] * b + bary[2] * c);
    out.distance = gap.norm();
    out.weights = {1.0, -bary[0], -bary[1], -bary[2]};

    const double scale = std::max({e0.norm(), e1.norm(), e2.norm(), (p - a).norm()});
    if (out.distance > RESOLVABLE_DISTANCE_FRACTION * scale) {
        out.normal = gap / out.distance;
    } else if (!degenerate) {
        out.normal = oriented(n / std::sqrt(nn), gap, fallback_direction);
    } else if (out.distance > 0.0) {
        out.normal = gap / out.distance;
    } else {
        out.normal = degenerate_normal(longest_of(e0, e1, e2), fallback_direction);
    }
    return out;
}

EdgeEdgeProximity edge_edge_proximity(const Eigen::Vector3d& ea0, const Eigen::Vector3d& ea1,
                                      const Eigen::Vector3d& eb0, const Eigen::Vector3d& eb1,
                                      const Eigen::Vector3d& fallback_direction) {
    const Eigen::Vector3d da = ea1 - ea0;
    const Eigen::Vector3d db = eb1 - eb0;
    const Eigen::Vector3d r = ea0 - eb0;
    const double aa = da.squaredNorm();
    const double bb = db.squaredNorm();
    const double ab = da.dot(db);
    const double ar = da.dot(r);
    const double br = db.dot(r);
    const Eigen::Vector3d cross = da.cross(db);
    const double cc = cross.squaredNorm();
    const bool parallel = !(cc > DEGENERATE_SINE_SQUARED * aa * bb) || cc == 0.0;

    double s = 0.0;
    double u = 0.0;
    if (aa == 0.0 && bb == 0.0) {
        s = 0.0;
        u = 0.0;
    } else if (aa == 0.0) {
        u = closest_segment_parameter(ea0, eb0, eb1);
    } else if (bb == 0.0) {
        s = closest_segment_parameter(eb0, ea0, ea1);
    } else if (parallel) {
        // Projections of edge b's endpoints on edge a's line; middle of the overlap if any.
        const double s_b0 = -ar / aa;
        const double s_b1 = (ab - ar) / aa;
        const double lo = std::max(0.0, std::min(s_b0, s_b1));
        const double hi = std::min(1.0, std::max(s_b0, s_b1));
        if (lo <= hi) {
            s = 0.5 * (lo + hi);
            u = closest_segment_parameter(ea0 + s * da, eb0, eb1);
        } else {
            // Disjoint projections: the nearest endpoints.
            const double u0 = closest_segment_parameter(ea0, eb0, eb1);
            const double u1 = closest_segment_parameter(ea1, eb0, eb1);
            const double d0 = (ea0 - (eb0 + u0 * db)).squaredNorm();
            const double d1 = (ea1 - (eb0 + u1 * db)).squaredNorm();
            s = d0 <= d1 ? 0.0 : 1.0;
            u = d0 <= d1 ? u0 : u1;
        }
    } else {
        const double denom = aa * bb - ab * ab;
        s = denom > 0.0 ? clamp01((ab * br - ar * bb) / denom) : 0.0;
        u = (ab * s + br) / bb;
        if (u < 0.0) {
            u = 0.0;
            s = clamp01(-ar / aa);
        } else if (u > 1.0) {
            u = 1.0;
            s = clamp01((ab - ar) / aa);
        }
    }

    EdgeEdgeProximity out;
    out.s = s;
    out.u = u;
    const Eigen::Vector3d gap = (ea0 + s * da) - (eb0 + u * db);
    out.distance = gap.norm();
    out.weights = {1.0 - s, s, -(1.0 - u), -u};

    const double scale = std::max({da.norm(), db.norm(), r.norm(), (ea0 - eb1).norm()});
    if (out.distance > RESOLVABLE_DISTANCE_FRACTION * scale) {
        out.normal = gap / out.distance;
    } else if (!parallel) {
        out.normal = oriented(cross / std::sqrt(cc), gap, fallback_direction);
    } else if (out.distance > 0.0) {
        out.normal = gap / out.distance;
    } else {
        out.normal = degenerate_normal(aa >= bb ? da : db, fallback_direction);
    }
    return out;
}

}  // namespace meniscus::tracker
