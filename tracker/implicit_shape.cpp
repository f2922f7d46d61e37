#include "tracker/implicit_shape.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

using Eigen::Vector3d;

namespace {

/// Finite-difference step as a fraction of the shape's bounding-box diagonal.
constexpr double GRADIENT_STEP_FRACTION = 1e-7;

void require_positive(double v, const char* what) {
    if (!(v > 0.0) || !std::isfinite(v)) {
        std::ostringstream s;
        s << what << " must be a finite number > 0, got " << v;
        throw std::invalid_argument(s.str());
    }
}

Vector3d normalized_axis(const Vector3d& axis) {
    const double n = axis.norm();
    if (!(n > 0.0) || !std::isfinite(n))
        throw std::invalid_argument("axis must be a non-zero finite vector");
    return axis / n;
}

/// Surface area of a box (m²); +∞ for an unbounded one, 0 for an empty one.
double box_surface_area(const Box3& box) {
    if (box.isEmpty())
        return 0.0;
    const Vector3d s = box.sizes();
    return 2.0 * (s.x() * s.y() + s.y() * s.z() + s.z() * s.x());
}

/// Polynomial smooth minimum (C¹) with blend radius k ≥ 0; equals min(a, b) when |a−b| ≥ k.
double smooth_min(double a, double b, double k) {
    if (k <= 0.0)
        return std::min(a, b);
    const double h = std::max(k - std::abs(a - b), 0.0) / k;
    return std::min(a, b) - h * h * k * 0.25;
}

class Sphere final : public ImplicitShape {
public:
    Sphere(const Vector3d& c, double r) : m_c(c), m_r(r) { require_positive(r, "sphere radius"); }
    double value(const Vector3d& x) const override { return (x - m_c).norm() - m_r; }
    Vector3d gradient(const Vector3d& x) const override {
        const Vector3d d = x - m_c;
        const double n = d.norm();
        return n > 0.0 ? Vector3d(d / n) : Vector3d::UnitX();
    }
    Box3 bounds() const override {
        return Box3(m_c - Vector3d::Constant(m_r), m_c + Vector3d::Constant(m_r));
    }
    double surface_area(const Box3&) const override { return 4.0 * M_PI * m_r * m_r; }

private:
    Vector3d m_c;
    double m_r;
};

class Ellipsoid final : public ImplicitShape {
public:
    Ellipsoid(const Vector3d& c, const Vector3d& r) : m_c(c), m_r(r) {
        for (int i = 0; i < 3; ++i)
            require_positive(r[i], "ellipsoid radii");
    }
    // (|x/r| − 1)·min(r): exact zero set, correct sign, a lower bound on distance scale.
    double value(const Vector3d& x) const override {
        return ((x - m_c).cwiseQuotient(m_r).norm() - 1.0) * m_r.minCoeff();
    }
    Box3 bounds() const override { return Box3(m_c - m_r, m_c + m_r); }
    double surface_area(const Box3&) const override {
        // Knud Thomsen's approximation (relative error ≤ 1.1 %).
        constexpr double P = 1.6075;
        const double ab = std::pow(m_r.x() * m_r.y(), P), ac = std::pow(m_r.x() * m_r.z(), P),
                     bc = std::pow(m_r.y() * m_r.z(), P);
        return 4.0 * M_PI * std::pow((ab + ac + bc) / 3.0, 1.0 / P);
    }

private:
    Vector3d m_c, m_r;
};

class Box final : public ImplicitShape {
public:
    Box(const Vector3d& lo, const Vector3d& hi) : m_lo(lo), m_hi(hi) {
        for (int i = 0; i < 3; ++i)
            require_positive(hi[i] - lo[i], "box size (max - min)");
    }
    double value(const Vector3d& x) const override {
        const Vector3d c = 0.5 * (m_lo + m_hi), h = 0.5 * (m_hi - m_lo);
        const Vector3d q = (x - c).cwiseAbs() - h;
        return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    }
    Box3 bounds() const override { return Box3(m_lo, m_hi); }
    double surface_area(const Box3&) const override { return box_surface_area(bounds()); }

private:
    Vector3d m_lo, m_hi;
};

class Cylinder final : public ImplicitShape {
public:
    Cylinder(const Vector3d& c, const Vector3d& axis, double r, double height)
        : m_c(c), m_a(normalized_axis(axis)), m_r(r), m_half(0.5 * height) {
        require_positive(r, "cylinder radius");
        require_positive(height, "cylinder height");
    }
    double value(const Vector3d& x) const override {
        const Vector3d d = x - m_c;
        const double along = d.dot(m_a);
        const double radial = (d - along * m_a).norm();
        const double qx = radial - m_r, qy = std::abs(along) - m_half;
        return std::hypot(std::max(qx, 0.0), std::max(qy, 0.0)) + std::min(std::max(qx, qy), 0.0);
    }
    Box3 bounds() const override {
        const Vector3d ext = m_a.cwiseAbs() * m_half +
                             m_r * (Vector3d::Ones() - m_a.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
        return Box3(m_c - ext, m_c + ext);
    }
    double surface_area(const Box3&) const override {
        return 2.0 * M_PI * m_r * (2.0 * m_half) + 2.0 * M_PI * m_r * m_r;
    }

private:
    Vector3d m_c, m_a;
    double m_r, m_half;
};

class PerturbedCylinder final : public ImplicitShape {
public:
    PerturbedCylinder(const Vector3d& c, const Vector3d& axis, double r, double height,
                      double amplitude, double wavelength)
        : m_c(c),
          m_a(normalized_axis(axis)),
          m_r(r),
          m_half(0.5 * height),
          m_eps(amplitude),
          m_k(2.0 * M_PI / wavelength) {
        require_positive(r, "perturbed cylinder radius");
        require_positive(height, "perturbed cylinder height");
        require_positive(wavelength, "perturbed cylinder wavelength");
        if (!(amplitude >= 0.0 && amplitude < 1.0))
            throw std::invalid_argument("perturbed cylinder amplitude must be in [0, 1)");
    }
    double value(const Vector3d& x) const override {
        const Vector3d d = x - m_c;
        const double along = d.dot(m_a);
        const double radial = (d - along * m_a).norm();
        const double qx = radial - m_r * (1.0 + m_eps * std::cos(m_k * along));
        const double qy = std::abs(along) - m_half;
        return std::hypot(std::max(qx, 0.0), std::max(qy, 0.0)) + std::min(std::max(qx, qy), 0.0);
    }
    Box3 bounds() const override {
        const double r = m_r * (1.0 + m_eps);
        const Vector3d ext = m_a.cwiseAbs() * m_half +
                             r * (Vector3d::Ones() - m_a.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
        return Box3(m_c - ext, m_c + ext);
    }
    /// The side: mean circumference 2πR times the length of the profile, whose slope
    /// R ε k sin(ks) has mean square (R ε k)²/2; the caps at most π (R(1 + ε))² each.
    double surface_area(const Box3&) const override {
        const double slope = m_r * m_eps * m_k, cap = m_r * (1.0 + m_eps);
        return 2.0 * M_PI * m_r * (2.0 * m_half) * std::sqrt(1.0 + 0.5 * slope * slope) +
               2.0 * M_PI * cap * cap;
    }

private:
    Vector3d m_c, m_a;
    double m_r, m_half, m_eps, m_k;
};

class Torus final : public ImplicitShape {
public:
    Torus(const Vector3d& c, const Vector3d& axis, double major, double minor)
        : m_c(c), m_a(normalized_axis(axis)), m_R(major), m_r(minor) {
        require_positive(minor, "torus minor_radius");
        require_positive(major - minor, "torus major_radius - minor_radius");
    }
    double value(const Vector3d& x) const override {
        const Vector3d d = x - m_c;
        const double along = d.dot(m_a);
        const double radial = (d - along * m_a).norm();
        return std::hypot(radial - m_R, along) - m_r;
    }
    Box3 bounds() const override {
        const double e = m_R + m_r;
        return Box3(m_c - Vector3d::Constant(e), m_c + Vector3d::Constant(e));
    }
    double surface_area(const Box3&) const override { return 4.0 * M_PI * M_PI * m_R * m_r; }

private:
    Vector3d m_c, m_a;
    double m_R, m_r;
};

class Dumbbell final : public ImplicitShape {
public:
    Dumbbell(const Vector3d& c, double bulb, double separation, double handle, double blend)
        : m_c(c), m_bulb(bulb), m_half(0.5 * separation), m_handle(handle), m_blend(blend) {
        require_positive(bulb, "dumbbell bulb_radius");
        require_positive(separation, "dumbbell separation");
        require_positive(handle, "dumbbell handle_radius");
        require_positive(bulb - handle, "dumbbell bulb_radius - handle_radius");
        if (!(blend >= 0.0))
            throw std::invalid_argument("dumbbell blend_radius must be >= 0");
    }
    double value(const Vector3d& x) const override {
        const Vector3d d = x - m_c;
        const double left = (d - Vector3d(-m_half, 0, 0)).norm() - m_bulb;
        const double right = (d - Vector3d(m_half, 0, 0)).norm() - m_bulb;
        const double radial = std::hypot(d.y(), d.z()) - m_handle;
        const double cap = std::abs(d.x()) - m_half;  // handle runs between the bulb centres
        const double handle = std::hypot(std::max(radial, 0.0), std::max(cap, 0.0)) +
                              std::min(std::max(radial, cap), 0.0);
        return smooth_min(std::min(left, right), handle, m_blend);
    }
    Box3 bounds() const override {
        const Vector3d e(m_half + m_bulb, m_bulb, m_bulb);
        return Box3(m_c - e, m_c + e);
    }
    double surface_area(const Box3&) const override {
        return 8.0 * M_PI * m_bulb * m_bulb + 2.0 * M_PI * m_handle * (2.0 * m_half);
    }

private:
    Vector3d m_c;
    double m_bulb, m_half, m_handle, m_blend;
};

class WavyHalfSpace final : public ImplicitShape {
public:
    WavyHalfSpace(const Vector3d& origin, const Vector3d& up, const Vector3d& direction,
                  double amplitude, double wavelength)
        : m_o(origin), m_n(normalized_axis(up)), m_A(amplitude) {
        require_positive(wavelength, "wavy half-space wavelength");
        if (!(amplitude >= 0.0) || !std::isfinite(amplitude))
            throw std::invalid_argument("wavy half-space amplitude must be a finite number >= 0");
        const Vector3d tangential = direction - direction.dot(m_n) * m_n;
        if (!(tangential.norm() > PARALLEL_TOLERANCE * direction.norm()))
            throw std::invalid_argument(
                "wavy half-space direction must be a non-zero vector not parallel to up");
        m_d = tangential.normalized();
        m_k = 2.0 * M_PI / wavelength;
        m_scale = 1.0 / std::sqrt(1.0 + (m_A * m_k) * (m_A * m_k));
    }
    double value(const Vector3d& x) const override {
        const Vector3d r = x - m_o;
        return (r.dot(m_n) - m_A * std::cos(m_k * r.dot(m_d))) * m_scale;
    }
    Vector3d gradient(const Vector3d& x) const override {
        const double t = (x - m_o).dot(m_d);
        return (m_n + m_A * m_k * std::sin(m_k * t) * m_d) * m_scale;
    }
    Box3 bounds() const override {
        constexpr double INF = std::numeric_limits<double>::infinity();
        Vector3d lo = Vector3d::Constant(-INF), hi = Vector3d::Constant(INF);
        for (int i = 0; i < 3; ++i) {
            if (m_n[i] == 1.0)
                hi[i] = m_o[i] + m_A;
            if (m_n[i] == -1.0)
                lo[i] = m_o[i] - m_A;
        }
        return Box3(lo, hi);
    }
    /// A plane section of a box has at most half the box's surface area; the cosine stretches
    /// it by at most sqrt(1 + (2πA/λ)²).
    double surface_area(const Box3& within) const override {
        const Box3 box = within.intersection(bounds());
        if (box.isEmpty())
            return 0.0;
        const double slope = m_A * m_k;
        return 0.5 * box_surface_area(box) * std::sqrt(1.0 + slope * slope);
    }

private:
    /// `direction` counts as parallel to `up` below this relative tangential length.
    static constexpr double PARALLEL_TOLERANCE = 1e-9;
    Vector3d m_o, m_n, m_d;
    double m_A, m_k = 0.0, m_scale = 1.0;
};

class Combination final : public ImplicitShape {
public:
    enum class Op { Union, Intersection };
    Combination(std::vector<ShapePtr> shapes, Op op) : m_shapes(std::move(shapes)), m_op(op) {
        if (m_shapes.empty())
            throw std::invalid_argument("a union/intersection needs shapes");
        for (const auto& s : m_shapes)
            if (!s)
                throw std::invalid_argument("a union/intersection got a null shape");
    }
    double value(const Vector3d& x) const override {
        double v = m_shapes.front()->value(x);
        for (size_t i = 1; i < m_shapes.size(); ++i) {
            const double vi = m_shapes[i]->value(x);
            v = m_op == Op::Union ? std::min(v, vi) : std::max(v, vi);
        }
        return v;
    }
    Vector3d gradient(const Vector3d& x) const override { return active(x).gradient(x); }
    double surface_area(const Box3& within) const override {
        const Box3 box = within.intersection(bounds());
        double area = 0.0;
        for (const auto& s : m_shapes)
            area += s->surface_area(box);
        return area;
    }
    Box3 bounds() const override {
        Box3 b = m_shapes.front()->bounds();
        for (size_t i = 1; i < m_shapes.size(); ++i)
            b = m_op == Op::Union ? b.merged(m_shapes[i]->bounds())
                                  : b.intersection(m_shapes[i]->bounds());
        return b;
    }

private:
    const ImplicitShape& active(const Vector3d& x) const {
        size_t best = 0;
        double v = m_shapes.front()->value(x);
        for (size_t i = 1; i < m_shapes.size(); ++i) {
            const double vi = m_shapes[i]->value(x);
            if (m_op == Op::Union ? vi < v : vi > v) {
                v = vi;
                best = i;
            }
        }
        return *m_shapes[best];
    }
    std::vector<ShapePtr> m_shapes;
    Op m_op;
};

class Difference final : public ImplicitShape {
public:
    Difference(ShapePtr a, ShapePtr b) : m_a(std::move(a)), m_b(std::move(b)) {
        if (!m_a || !m_b)
            throw std::invalid_argument("a difference got a null shape");
    }
    double value(const Vector3d& x) const override {
        return std::max(m_a->value(x), -m_b->value(x));
    }
    Vector3d gradient(const Vector3d& x) const override {
        return m_a->value(x) >= -m_b->value(x) ? m_a->gradient(x) : Vector3d(-m_b->gradient(x));
    }
    Box3 bounds() const override { return m_a->bounds(); }
    double surface_area(const Box3& within) const override {
        const Box3 box = within.intersection(bounds());
        return m_a->surface_area(box) + m_b->surface_area(box);
    }

private:
    ShapePtr m_a, m_b;
};

}  // namespace

Vector3d ImplicitShape::gradient(const Vector3d& x) const {
    const double h = std::max(bounds().diagonal().norm(), 1e-300) * GRADIENT_STEP_FRACTION;
    Vector3d g;
    for (int i = 0; i < 3; ++i) {
        Vector3d e = Vector3d::Zero();
        e[i] = h;
        g[i] = (value(x + e) - value(x - e)) / (2.0 * h);
    }
    return g;
}

ShapePtr make_sphere(const Vector3d& center, double radius) {
    return std::make_shared<Sphere>(center, radius);
}
ShapePtr make_ellipsoid(const Vector3d& center, const Vector3d& radii) {
    return std::make_shared<Ellipsoid>(center, radii);
}
ShapePtr make_box(const Vector3d& min_corner, const Vector3d& max_corner) {
    return std::make_shared<Box>(min_corner, max_corner);
}
ShapePtr make_cylinder(const Vector3d& center, const Vector3d& axis, double radius, double height) {
    return std::make_shared<Cylinder>(center, axis, radius, height);
}
ShapePtr make_perturbed_cylinder(const Vector3d& center, const Vector3d& axis, double radius,
                                 double height, double amplitude, double wavelength) {
    return std::make_shared<PerturbedCylinder>(center, axis, radius, height, amplitude, wavelength);
}
ShapePtr make_torus(const Vector3d& center, const Vector3d& axis, double major_radius,
                    double minor_radius) {
    return std::make_shared<Torus>(center, axis, major_radius, minor_radius);
}
ShapePtr make_dumbbell(const Vector3d& center, double bulb_radius, double separation,
                       double handle_radius, double blend_radius) {
    return std::make_shared<Dumbbell>(center, bulb_radius, separation, handle_radius, blend_radius);
}
ShapePtr make_wavy_half_space(const Vector3d& origin, const Vector3d& up, const Vector3d& direction,
                              double amplitude, double wavelength) {
    return std::make_shared<WavyHalfSpace>(origin, up, direction, amplitude, wavelength);
}
ShapePtr make_union(std::vector<ShapePtr> shapes) {
    return std::make_shared<Combination>(std::move(shapes), Combination::Op::Union);
}
ShapePtr make_intersection(std::vector<ShapePtr> shapes) {
    return std::make_shared<Combination>(std::move(shapes), Combination::Op::Intersection);
}
ShapePtr make_difference(ShapePtr a, ShapePtr b) {
    return std::make_shared<Difference>(std::move(a), std::move(b));
}

double projected_signed_distance(const ImplicitShape& shape, const Eigen::Vector3d& x,
                                 double tolerance) {
    constexpr int PROJECTION_ROUNDS = 50;
    constexpr int NEWTON_STEPS = 3;
    const double value = shape.value(x);
    Eigen::Vector3d p = x;
    for (int it = 0; it < PROJECTION_ROUNDS; ++it) {
        for (int k = 0; k < NEWTON_STEPS; ++k) {
            const Eigen::Vector3d g = shape.gradient(p);
            const double g2 = g.squaredNorm();
            if (!(g2 > 0.0))
                break;
            p -= shape.value(p) * g / g2;
        }
        const Eigen::Vector3d g = shape.gradient(p);
        if (!(g.squaredNorm() > 0.0))
            break;
        const Eigen::Vector3d n = g.normalized();
        const Eigen::Vector3d r = x - p;
        const Eigen::Vector3d tangential = r - r.dot(n) * n;
        if (tangential.norm() <= tolerance)
            break;
        p += tangential;
    }
    return std::copysign((x - p).norm(), value);
}

}  // namespace meniscus::tracker
