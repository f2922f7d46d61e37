#include "tracker/predicates.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

// This file relies on every floating-point operation being rounded separately: the error-free
// transformations below are wrong if the compiler contracts a*b+c into a fused multiply-add.
// tracker/CMakeLists.txt compiles it with -ffp-contract=off; FMA is used only explicitly.

namespace meniscus::tracker {
namespace {

/// Unit roundoff of IEEE double (half an ulp of 1).
constexpr double UNIT_ROUNDOFF = 0x1p-53;
/// Veltkamp/Dekker splitter 2^ceil(53/2) + 1.
constexpr double SPLITTER = 0x1p27 + 1.0;
/// Certified relative error bounds of the filters, as multiples of the computed permanent.
/// orient3d: each term x*y*z passes through 3 differences, 2 products, 1 subtraction and at most
/// 2 additions, i.e. (1+u)^8 - 1 <= 8u + 29u^2; the slack covers rounding of the permanent and
/// of the bound itself. orient2d: (1+u)^4 - 1 <= 4u + 7u^2, same slack argument.
constexpr double ORIENT3D_FILTER_BOUND = (8.0 + 128.0 * UNIT_ROUNDOFF) * UNIT_ROUNDOFF;
constexpr double ORIENT2D_FILTER_BOUND = (4.0 + 64.0 * UNIT_ROUNDOFF) * UNIT_ROUNDOFF;
/// Inputs whose nonzero magnitudes lie in [EXPANSION_MIN_MAGNITUDE, EXPANSION_MAX_MAGNITUDE] are
/// multiples of 2^-352 and at most 2^300: every product of three difference components is then a
/// multiple of 2^-1056 (>= the subnormal spacing 2^-1074) and below 2^906, so the expansion
/// arithmetic neither underflows inexactly nor overflows. Other inputs use big integers.
constexpr double EXPANSION_MIN_MAGNITUDE = 0x1p-300;
constexpr double EXPANSION_MAX_MAGNITUDE = 0x1p300;

/// The filters' relative bounds assume no product underflows or overflows (an underflowed
/// product later multiplied by a huge factor would void them). Nonzero computed differences
/// inside [FILTER_MIN_DIFFERENCE, FILTER_MAX_DIFFERENCE] guarantee that every product of up to
/// three of them is a normal number; otherwise the exact path decides.
constexpr double FILTER_MIN_DIFFERENCE = 0x1p-300;
constexpr double FILTER_MAX_DIFFERENCE = 0x1p300;

/// True when every value is zero or has a magnitude inside the filter's safe range (false for
/// non-finite values).
template <typename... Values>
bool filter_safe(Values... values) {
    auto safe = [](double x) {
        const double m = std::abs(x);
        return x == 0.0 || (m >= FILTER_MIN_DIFFERENCE && m <= FILTER_MAX_DIFFERENCE);
    };
    return (safe(values) && ...);
}

// ---------------------------------------------------------------------------------------------
// Error-free transformations.

inline void two_sum(double a, double b, double& sum, double& err) {
    sum = a + b;
    const double b_virtual = sum - a;
    const double a_virtual = sum - b_virtual;
    err = (a - a_virtual) + (b - b_virtual);
}

inline void two_diff(double a, double b, double& diff, double& err) {
    diff = a - b;
    const double b_virtual = a - diff;
    const double a_virtual = diff + b_virtual;
    err = (a - a_virtual) + (b_virtual - b);
}

inline void split(double a, double& hi, double& lo) {
    const double c = SPLITTER * a;
    const double a_big = c - a;
    hi = c - a_big;
    lo = a - hi;
}

inline void two_product(double a, double b, double& prod, double& err) {
    prod = a * b;
#if defined(__FMA__)
    err = std::fma(a, b, -prod);
#else
    double a_hi, a_lo, b_hi, b_lo;
    split(a, a_hi, a_lo);
    split(b, b_hi, b_lo);
    err = ((a_hi * b_hi - prod) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo;
#endif
}

// ---------------------------------------------------------------------------------------------
// Nonoverlapping expansions of fixed capacity, built only by growing (Shewchuk's GROW-EXPANSION
// with zero elimination), which keeps components nonoverlapping and sorted by increasing
// magnitude; the sign of the exact sum is then the sign of the last component.

template <int N>
struct Expansion {
    std::array<double, N> c{};
    int n = 0;

    /// Adds the double b exactly.
    void add(double b) {
        double q = b;
        int m = 0;
        for (int i = 0; i < n; ++i) {
            double hi, lo;
            two_sum(q, c[i], hi, lo);
            if (lo != 0.0) {
                c[m++] = lo;
            }
            q = hi;
        }
        if (q != 0.0) {
            c[m++] = q;
        }
        n = m;
    }

    int sign() const { return n == 0 ? 0 : (c[n - 1] > 0.0 ? 1 : -1); }
};

template <int N>
Expansion<N> exact_difference(double a, double b) {
    Expansion<N> e;
    double d, err;
    two_diff(a, b, d, err);
    e.add(err);
    e.add(d);
    return e;
}

template <int N1, int N2>
Expansion<2 * N1 * N2> product(const Expansion<N1>& x, const Expansion<N2>& y) {
    Expansion<2 * N1 * N2> e;
    for (int i = 0; i < x.n; ++i) {
        for (int j = 0; j < y.n; ++j) {
            double p, err;
            two_product(x.c[i], y.c[j], p, err);
            e.add(err);
            e.add(p);
        }
    }
    return e;
}

template <int N1, int N2>
Expansion<N1 + N2> difference(const Expansion<N1>& x, const Expansion<N2>& y) {
    Expansion<N1 + N2> e;
    for (int i = 0; i < x.n; ++i) {
        e.add(x.c[i]);
    }
    for (int j = 0; j < y.n; ++j) {
        e.add(-y.c[j]);
    }
    return e;
}

template <int N>
Expansion<3 * N> sum3(const Expansion<N>& x, const Expansion<N>& y, const Expansion<N>& z) {
    Expansion<3 * N> e;
    for (const Expansion<N>* part : {&x, &y, &z}) {
        for (int i = 0; i < part->n; ++i) {
            e.add(part->c[i]);
        }
    }
    return e;
}

// ---------------------------------------------------------------------------------------------
// Exact signed big integers (sign-magnitude, 32-bit limbs), for inputs outside the expansion
// range. Slow but simple; every finite double is an integer multiple of 2^-1074.

class BigInt {
public:
    BigInt() = default;
    /// The integer |m| * 2^shift with the sign of m.
    BigInt(std::int64_t m, int shift) {
        if (m == 0) {
            return;
        }
        m_negative = m < 0;
        std::uint64_t mag = m < 0 ? static_cast<std::uint64_t>(-m) : static_cast<std::uint64_t>(m);
        const int limb_shift = shift / 32;
        const int bit_shift = shift % 32;
        m_limbs.assign(static_cast<std::size_t>(limb_shift), 0u);
        // mag < 2^53, so mag << bit_shift fits in 85 bits: split across three limbs.
        const std::uint64_t low = mag << bit_shift;
        const std::uint64_t high = bit_shift == 0 ? 0 : (mag >> (64 - bit_shift));
        m_limbs.push_back(static_cast<std::uint32_t>(low));
        m_limbs.push_back(static_cast<std::uint32_t>(low >> 32));
        m_limbs.push_back(static_cast<std::uint32_t>(high));
        trim();
    }

    int sign() const { return m_limbs.empty() ? 0 : (m_negative ? -1 : 1); }

    friend BigInt operator-(const BigInt& a, const BigInt& b) {
        BigInt nb = b;
        nb.m_negative = !nb.m_negative;
        return a + nb;
    }

    friend BigInt operator+(const BigInt& a, const BigInt& b) {
        if (a.m_limbs.empty()) {
            return b;
        }
        if (b.m_limbs.empty()) {
            return a;
        }
        BigInt r;
        if (a.m_negative == b.m_negative) {
            r.m_limbs = add_magnitudes(a.m_limbs, b.m_limbs);
            r.m_negative = a.m_negative;
        } else if (compare_magnitudes(a.m_limbs, b.m_limbs) >= 0) {
            r.m_limbs = subtract_magnitudes(a.m_limbs, b.m_limbs);
            r.m_negative = a.m_negative;
        } else {
            r.m_limbs = subtract_magnitudes(b.m_limbs, a.m_limbs);
            r.m_negative = b.m_negative;
        }
        r.trim();
        return r;
    }

    friend BigInt operator*(const BigInt& a, const BigInt& b) {
        BigInt r;
        if (a.m_limbs.empty() || b.m_limbs.empty()) {
            return r;
        }
        r.m_limbs.assign(a.m_limbs.size() + b.m_limbs.size(), 0u);
        for (std::size_t i = 0; i < a.m_limbs.size(); ++i) {
            std::uint64_t carry = 0;
            for (std::size_t j = 0; j < b.m_limbs.size(); ++j) {
                const std::uint64_t cur = static_cast<std::uint64_t>(a.m_limbs[i]) * b.m_limbs[j] +
                                          r.m_limbs[i + j] + carry;
                r.m_limbs[i + j] = static_cast<std::uint32_t>(cur);
                carry = cur >> 32;
            }
            std::size_t k = i + b.m_limbs.size();
            while (carry != 0) {
                const std::uint64_t cur = static_cast<std::uint64_t>(r.m_limbs[k]) + carry;
                r.m_limbs[k] = static_cast<std::uint32_t>(cur);
                carry = cur >> 32;
                ++k;
            }
        }
        r.m_negative = a.m_negative != b.m_negative;
        r.trim();
        return r;
    }

private:
    using Limbs = std::vector<std::uint32_t>;

    void trim() {
        while (!m_limbs.empty() && m_limbs.back() == 0u) {
            m_limbs.pop_back();
        }
        if (m_limbs.empty()) {
            m_negative = false;
        }
    }

    static int compare_magnitudes(const Limbs& a, const Limbs& b) {
        if (a.size() != b.size()) {
            return a.size() < b.size() ? -1 : 1;
        }
        for (std::size_t i = a.size(); i-- > 0;) {
            if (a[i] != b[i]) {
                return a[i] < b[i] ? -1 : 1;
            }
        }
        return 0;
    }

    static Limbs add_magnitudes(const Limbs& a, const Limbs& b) {
        Limbs r(std::max(a.size(), b.size()) + 1, 0u);
        std::uint64_t carry = 0;
        for (std::size_t i = 0; i < r.size(); ++i) {
            const std::uint64_t cur =
                carry + (i < a.size() ? a[i] : 0u) + (i < b.size() ? b[i] : 0u);
            r[i] = static_cast<std::uint32_t>(cur);
            carry = cur >> 32;
        }
        return r;
    }

    /// |a| - |b| for |a| >= |b|.
    static Limbs subtract_magnitudes(const Limbs& a, const Limbs& b) {
        Limbs r(a.size(), 0u);
        std::int64_t borrow = 0;
        for (std::size_t i = 0; i < a.size(); ++i) {
            std::int64_t cur = static_cast<std::int64_t>(a[i]) - borrow -
                               static_cast<std::int64_t>(i < b.size() ? b[i] : 0u);
            borrow = cur < 0 ? 1 : 0;
            if (cur < 0) {
                cur += static_cast<std::int64_t>(1) << 32;
            }
            r[i] = static_cast<std::uint32_t>(cur);
        }
        return r;
    }

    bool m_negative = false;
    Limbs m_limbs;
};

/// Writes x = m * 2^e exactly with |m| < 2^53 (x finite, nonzero).
void decompose(double x, std::int64_t& m, int& e) {
    int k = 0;
    const double f = std::frexp(x, &k);
    constexpr int MANTISSA_BITS = 53;
    m = static_cast<std::int64_t>(std::ldexp(f, MANTISSA_BITS));
    e = k - MANTISSA_BITS;
}

/// Converts doubles to big integers sharing the scale 2^-E, E the smallest exponent among them.
template <std::size_t N>
std::array<BigInt, N> to_common_scale(const std::array<double, N>& values) {
    std::array<std::int64_t, N> mantissa{};
    std::array<int, N> exponent{};
    int min_exponent = 0;
    bool any = false;
    for (std::size_t i = 0; i < N; ++i) {
        if (values[i] != 0.0) {
            decompose(values[i], mantissa[i], exponent[i]);
            if (!any || exponent[i] < min_exponent) {
                min_exponent = exponent[i];
            }
            any = true;
        }
    }
    std::array<BigInt, N> out;
    for (std::size_t i = 0; i < N; ++i) {
        if (values[i] != 0.0) {
            out[i] = BigInt(mantissa[i], exponent[i] - min_exponent);
        }
    }
    return out;
}

// ---------------------------------------------------------------------------------------------

template <std::size_t N>
void require_finite(const std::array<double, N>& values, const char* predicate) {
    // v · 0 is 0 for finite v and NaN for ±∞ and NaN: one branch instead of N (this runs on
    // every predicate call).
    double zero = 0.0;
    for (double v : values)
        zero += v * 0.0;
    if (zero != 0.0)
        throw std::invalid_argument(std::string(predicate) +
                                    ": non-finite coordinate; pass finite points");
}

template <std::size_t N>
bool in_expansion_range(const std::array<double, N>& values) {
    for (double v : values) {
        const double m = std::abs(v);
        if (v != 0.0 && (m < EXPANSION_MIN_MAGNITUDE || m > EXPANSION_MAX_MAGNITUDE)) {
            return false;
        }
    }
    return true;
}

int orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy) {
    const std::array<double, 6> v{ax, ay, bx, by, cx, cy};
    require_finite(v, "orient2d");
    if (in_expansion_range(v)) {
        const auto bax = exact_difference<2>(bx, ax);
        const auto bay = exact_difference<2>(by, ay);
        const auto cax = exact_difference<2>(cx, ax);
        const auto cay = exact_difference<2>(cy, ay);
        return difference(product(bax, cay), product(bay, cax)).sign();
    }
    const auto b = to_common_scale(v);
    return ((b[2] - b[0]) * (b[5] - b[1]) - (b[3] - b[1]) * (b[4] - b[0])).sign();
}

int orient2d_impl(double ax, double ay, double bx, double by, double cx, double cy) {
    const double bax = bx - ax;
    const double bay = by - ay;
    const double cax = cx - ax;
    const double cay = cy - ay;
    const double left = bax * cay;
    const double right = bay * cax;
    const double det = left - right;
    const double permanent = std::abs(left) + std::abs(right);
    const double bound = ORIENT2D_FILTER_BOUND * permanent;
    if ((det > bound || -det > bound) && filter_safe(bax, bay, cax, cay)) {
        return det > 0.0 ? 1 : -1;
    }
    return orient2d_exact(ax, ay, bx, by, cx, cy);
}

int orient3d_exact_impl(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                        const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
    const std::array<double, 12> v{a.x(), a.y(), a.z(), b.x(), b.y(), b.z(),
                                   c.x(), c.y(), c.z(), d.x(), d.y(), d.z()};
    require_finite(v, "orient3d");
    if (in_expansion_range(v)) {
        const auto bax = exact_difference<2>(b.x(), a.x());
        const auto bay = exact_difference<2>(b.y(), a.y());
        const auto baz = exact_difference<2>(b.z(), a.z());
        const auto cax = exact_difference<2>(c.x(), a.x());
        const auto cay = exact_difference<2>(c.y(), a.y());
        const auto caz = exact_difference<2>(c.z(), a.z());
        const auto dax = exact_difference<2>(d.x(), a.x());
        const auto day = exact_difference<2>(d.y(), a.y());
        const auto daz = exact_difference<2>(d.z(), a.z());
        const auto term_x = product(bax, difference(product(cay, daz), product(caz, day)));
        const auto term_y = product(bay, difference(product(caz, dax), product(cax, daz)));
        const auto term_z = product(baz, difference(product(cax, day), product(cay, dax)));
        return sum3(term_x, term_y, term_z).sign();
    }
    const auto n = to_common_scale(v);
    const BigInt bax = n[3] - n[0], bay = n[4] - n[1], baz = n[5] - n[2];
    const BigInt cax = n[6] - n[0], cay = n[7] - n[1], caz = n[8] - n[2];
    const BigInt dax = n[9] - n[0], day = n[10] - n[1], daz = n[11] - n[2];
    return (bax * (cay * daz - caz * day) + bay * (caz * dax - cax * daz) +
            baz * (cax * day - cay * dax))
        .sign();
}

}  // namespace

int orient2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return orient2d_impl(a.x(), a.y(), b.x(), b.y(), c.x(), c.y());
}

int orient2d_projected(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                       int drop_axis) {
    if (drop_axis < 0 || drop_axis > 2) {
        throw std::invalid_argument("orient2d_projected: drop_axis must be 0, 1 or 2");
    }
    const int i = (drop_axis + 1) % 3;
    const int j = (drop_axis + 2) % 3;
    return orient2d_impl(a[i], a[j], b[i], b[j], c[i], c[j]);
}

int orient3d_filtered(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      const Eigen::Vector3d& d) {
    const double bax = b.x() - a.x(), bay = b.y() - a.y(), baz = b.z() - a.z();
    const double cax = c.x() - a.x(), cay = c.y() - a.y(), caz = c.z() - a.z();
    const double dax = d.x() - a.x(), day = d.y() - a.y(), daz = d.z() - a.z();
    const double cay_daz = cay * daz, caz_day = caz * day;
    const double caz_dax = caz * dax, cax_daz = cax * daz;
    const double cax_day = cax * day, cay_dax = cay * dax;
    const double det =
        bax * (cay_daz - caz_day) + bay * (caz_dax - cax_daz) + baz * (cax_day - cay_dax);
    const double permanent = std::abs(bax) * (std::abs(cay_daz) + std::abs(caz_day)) +
                             std::abs(bay) * (std::abs(caz_dax) + std::abs(cax_daz)) +
                             std::abs(baz) * (std::abs(cax_day) + std::abs(cay_dax));
    const double bound = ORIENT3D_FILTER_BOUND * permanent;
    if ((det > bound || -det > bound) && filter_safe(bax, bay, baz, cax, cay, caz, dax, day, daz)) {
        return det > 0.0 ? 1 : -1;
    }
    return SIGN_UNCERTAIN;
}

int orient3d(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
             const Eigen::Vector3d& d) {
    const int s = orient3d_filtered(a, b, c, d);
    return s != SIGN_UNCERTAIN ? s : orient3d_exact_impl(a, b, c, d);
}

int orient3d_exact(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const Eigen::Vector3d& d) {
    return orient3d_exact_impl(a, b, c, d);
}

bool collinear3d(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    return orient2d_projected(a, b, c, 0) == 0 && orient2d_projected(a, b, c, 1) == 0 &&
           orient2d_projected(a, b, c, 2) == 0;
}

}  // namespace meniscus::tracker
