#pragma once
/// \file Independent slow exact oracles in GMP rational arithmetic, for tests only.
///
/// Every finite double converts exactly to mpq_class, so these give ground truth for the
/// predicates and certificates (not mere estimates) for continuous collision queries.

#include "tracker/distance.h"

#include <gmpxx.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <random>
#include <vector>

namespace meniscus::tracker::oracle {

using Q3 = std::array<mpq_class, 3>;

inline Q3 to_q(const Eigen::Vector3d& x) {
    return {mpq_class(x.x()), mpq_class(x.y()), mpq_class(x.z())};
}

inline int sign_of(const mpq_class& v) {
    return sgn(v);
}

inline mpq_class orient3d_q(const Q3& a, const Q3& b, const Q3& c, const Q3& d) {
    // (d - a) . ((b - a) x (c - a))
    const mpq_class bx = b[0] - a[0], by = b[1] - a[1], bz = b[2] - a[2];
    const mpq_class cx = c[0] - a[0], cy = c[1] - a[1], cz = c[2] - a[2];
    const mpq_class dx = d[0] - a[0], dy = d[1] - a[1], dz = d[2] - a[2];
    const mpq_class nx = by * cz - bz * cy, ny = bz * cx - bx * cz, nz = bx * cy - by * cx;
    return dx * nx + dy * ny + dz * nz;
}

inline int orient3d_sign(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
    return sign_of(orient3d_q(to_q(a), to_q(b), to_q(c), to_q(d)));
}

inline int orient2d_sign(double ax, double ay, double bx, double by, double cx, double cy) {
    const mpq_class det =
        (mpq_class(bx) - ax) * (mpq_class(cy) - ay) - (mpq_class(by) - ay) * (mpq_class(cx) - ax);
    return sign_of(det);
}

inline Q3 lerp_q(const Q3& x0, const Q3& x1, const mpq_class& t) {
    return {x0[0] + t * (x1[0] - x0[0]), x0[1] + t * (x1[1] - x0[1]), x0[2] + t * (x1[2] - x0[2])};
}

inline mpq_class dot_q(const Q3& a, const Eigen::Vector3d& n) {
    return a[0] * mpq_class(n.x()) + a[1] * mpq_class(n.y()) + a[2] * mpq_class(n.z());
}

/// Result of a no-collision certificate search.
enum class Certificate { no_collision, unknown };

/// Tries to prove that two moving point sets (the convex hulls of `first` and `second` vertex
/// trajectories) never meet for t in [0, 1]: splits [0, 1] into dyadic intervals; on each, the
/// hull of all vertex positions at both interval ends contains every configuration of the
/// interval, and a plane strictly separating the two hulls — checked exactly — proves there is
/// no contact. Candidate plane normals come from floating-point proximity queries at the
/// interval middle (soundness depends only on the exact check). `gap_direction(t)` returns
/// candidate normals for time t.
template <typename Directions>
Certificate certify_separated(const std::vector<std::array<Eigen::Vector3d, 2>>& first,
                              const std::vector<std::array<Eigen::Vector3d, 2>>& second,
                              Directions directions, int max_depth) {
    struct Interval {
        mpq_class lo, hi;
        int depth;
    };
    std::vector<Interval> stack{{mpq_class(0), mpq_class(1), 0}};
    auto positions = [](const std::vector<std::array<Eigen::Vector3d, 2>>& traj,
                        const mpq_class& lo, const mpq_class& hi) {
        std::vector<Q3> out;
        for (const auto& x : traj) {
            const Q3 x0 = to_q(x[0]);
            const Q3 x1 = to_q(x[1]);
            out.push_back(lerp_q(x0, x1, lo));
            out.push_back(lerp_q(x0, x1, hi));
        }
        return out;
    };
    int budget = 20000;
    while (!stack.empty()) {
        if (--budget < 0) {
            return Certificate::unknown;
        }
        const Interval iv = stack.back();
        stack.pop_back();
        const std::vector<Q3> pa = positions(first, iv.lo, iv.hi);
        const std::vector<Q3> pb = positions(second, iv.lo, iv.hi);
        const double mid = mpq_class((iv.lo + iv.hi) / 2).get_d();
        bool separated = false;
        for (const Eigen::Vector3d& n : directions(mid)) {
            if (!n.allFinite() || n.squaredNorm() == 0.0) {
                continue;
            }
            mpq_class max_a = dot_q(pa[0], n), min_a = max_a;
            for (const Q3& x : pa) {
                const mpq_class v = dot_q(x, n);
                max_a = std::max(max_a, v);
                min_a = std::min(min_a, v);
            }
            mpq_class max_b = dot_q(pb[0], n), min_b = max_b;
            for (const Q3& x : pb) {
                const mpq_class v = dot_q(x, n);
                max_b = std::max(max_b, v);
                min_b = std::min(min_b, v);
            }
            if (max_a < min_b || max_b < min_a) {
                separated = true;
                break;
            }
        }
        if (separated) {
            continue;
        }
        if (iv.depth >= max_depth) {
            return Certificate::unknown;
        }
        const mpq_class m = (iv.lo + iv.hi) / 2;
        stack.push_back({m, iv.hi, iv.depth + 1});
        stack.push_back({iv.lo, m, iv.depth + 1});
    }
    return Certificate::no_collision;
}

inline Eigen::Vector3d lerp(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, double t) {
    return x0 + t * (x1 - x0);
}

/// No-collision certificate for a point–triangle CCD query (exact).
inline Certificate certify_point_triangle_miss(const std::array<Eigen::Vector3d, 4>& x0,
                                               const std::array<Eigen::Vector3d, 4>& x1,
                                               int max_depth = 48) {
    auto directions = [&](double t) {
        std::array<Eigen::Vector3d, 4> x;
        for (int i = 0; i < 4; ++i) {
            x[i] = lerp(x0[i], x1[i], t);
        }
        const auto prox = point_triangle_proximity(x[0], x[1], x[2], x[3]);
        const Eigen::Vector3d gap = prox.weights[0] * x[0] + prox.weights[1] * x[1] +
                                    prox.weights[2] * x[2] + prox.weights[3] * x[3];
        const Eigen::Vector3d n = (x[2] - x[1]).cross(x[3] - x[1]);
        return std::vector<Eigen::Vector3d>{gap,
                                            prox.normal,
                                            n,
                                            Eigen::Vector3d::UnitX(),
                                            Eigen::Vector3d::UnitY(),
                                            Eigen::Vector3d::UnitZ()};
    };
    return certify_separated({{x0[0], x1[0]}}, {{x0[1], x1[1]}, {x0[2], x1[2]}, {x0[3], x1[3]}},
                             directions, max_depth);
}

/// No-collision certificate for an edge–edge CCD query (exact).
inline Certificate certify_edge_edge_miss(const std::array<Eigen::Vector3d, 4>& x0,
                                          const std::array<Eigen::Vector3d, 4>& x1,
                                          int max_depth = 48) {
    auto directions = [&](double t) {
        std::array<Eigen::Vector3d, 4> x;
        for (int i = 0; i < 4; ++i) {
            x[i] = lerp(x0[i], x1[i], t);
        }
        const auto prox = edge_edge_proximity(x[0], x[1], x[2], x[3]);
        const Eigen::Vector3d gap = prox.weights[0] * x[0] + prox.weights[1] * x[1] +
                                    prox.weights[2] * x[2] + prox.weights[3] * x[3];
        const Eigen::Vector3d n = (x[1] - x[0]).cross(x[3] - x[2]);
        return std::vector<Eigen::Vector3d>{gap,
                                            prox.normal,
                                            n,
                                            Eigen::Vector3d::UnitX(),
                                            Eigen::Vector3d::UnitY(),
                                            Eigen::Vector3d::UnitZ()};
    };
    return certify_separated({{x0[0], x1[0]}, {x0[1], x1[1]}}, {{x0[2], x1[2]}, {x0[3], x1[3]}},
                             directions, max_depth);
}

}  // namespace meniscus::tracker::oracle
