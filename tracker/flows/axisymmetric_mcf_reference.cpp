#include "tracker/flows/axisymmetric_mcf_reference.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

namespace {

/// Largest stable Δt is about 0.286 Δx² (see the header); Δt = cfl · Δx² / STABILITY_DIVISOR.
constexpr double STABILITY_DIVISOR = 4.0;
/// Eikonal pseudo-time step as a fraction of Δx (2-D Godunov forward Euler is stable to ½).
constexpr double EIKONAL_STEP_FRACTION = 0.5;
/// Below this |∇φ|² the meridian term is taken as ½(φ_aa + φ_rr) (see the header).
constexpr double DEGENERATE_GRADIENT_SQUARED = 1e-12;
/// Curvature steps update band cells with |φ| below the band half width minus this many Δx
/// (their stencils then read no saturated values); the outer cells follow by reinitialization.
constexpr double CURVATURE_BAND_MARGIN_VOXELS = 2.0;
/// Initialization projects every cell whose shape value is below the band half width plus the
/// larger of twice that width and this fraction of the grid's radial extent: blended and CSG
/// shapes' values are only bounds on the distance.
constexpr double CANDIDATE_MARGIN_FRACTION = 0.05;
/// Closest-point projection (projected_signed_distance): the tangential residual (fraction of
/// Δx) that ends it.
constexpr double PROJECTION_TOLERANCE_FRACTION = 1e-9;
/// Grain size (cells) of the parallel loops.
constexpr size_t GRAIN = 512;
/// Largest grid (cells) accepted.
constexpr double MAX_CELLS = 4e8;

/// Reinitialization: cells nearer the surface than SEED_DISTANCE_VOXELS without a previous
/// closest point start the search from their own gradient; the others from a neighbour's
/// closest point, over at most MAX_PASSES layers.
constexpr double SEED_DISTANCE_VOXELS = 1.5;
constexpr int MAX_PASSES = 250;
/// The interpolant's corner derivatives are computed on cells nearer the surface than this
/// (voxels): Newton iterates stay within about √2 voxels of the zero set.
constexpr double DERIVATIVE_WIDTH_VOXELS = 3.0;
/// Newton: iterations, step tolerance (index units), and how far beyond the band half width a
/// closest point may lie (voxels).
constexpr int NEWTON_ITERATIONS = 30;
constexpr double NEWTON_TOLERANCE = 1e-7;
constexpr double PROJECTION_REACH_VOXELS = 2.0;
/// The band list is sorted into memory order every this many reinitializations.
constexpr long SORT_INTERVAL = 64;
/// Cell flags during a reinitialization.
constexpr std::uint8_t IN_BAND = 1;
constexpr std::uint8_t IN_DOMAIN = 2;
constexpr std::uint8_t FROZEN = 4;
constexpr std::uint8_t HAS_DERIVATIVES = 8;

using Clock = std::chrono::steady_clock;

void require(bool ok, const std::string& field, const std::string& what) {
    if (!ok)
        throw std::invalid_argument("AxisymmetricMcfOptions." + field + " must be " + what);
}

/// Mirror an index into [0, n): −1 → 0, −2 → 1, n → n − 1, n + 1 → n − 2.
inline int mirror(int k, int n) {
    if (k < 0)
        return -1 - k;
    if (k >= n)
        return 2 * n - 1 - k;
    return k;
}

inline double minmod(double x, double y) {
    if (x * y <= 0.0)
        return 0.0;
    return std::abs(x) < std::abs(y) ? x : y;
}

/// The meridian grid and its narrow band while the flow runs.
class MeridianSolver {
public:
    MeridianSolver(int na, int nr, double dx, double band_half_width, double projection_width,
                   std::vector<double> phi)
        : m_na(na),
          m_nr(nr),
          m_dx(dx),
          m_w(band_half_width),
          m_phi(std::move(phi)),
          m_next(m_phi.size(), 0.0),
          m_flags(m_phi.size(), 0),
          m_da(m_phi.size(), 0.0),
          m_dr(m_phi.size(), 0.0),
          m_dar(m_phi.size(), 0.0),
          m_cpu(m_phi.size(), 0.0),
          m_cpv(m_phi.size(), 0.0),
          m_resolved(m_phi.size(), 0),
          m_has_closest_point(m_phi.size(), 0),
          m_projection_width(projection_width) {
        for (size_t c = 0; c < m_phi.size(); ++c)
            if (std::abs(m_phi[c]) < m_w)
                m_band.push_back(static_cast<int>(c));
    }

    /// One forward-Euler curvature step of length dt on the band.
    void curvature_step(double dt) {
        const double limit = m_w - CURVATURE_BAND_MARGIN_VOXELS * m_dx;
        parallel_over(m_band, [&](int c) {
            const double phi = m_phi[static_cast<size_t>(c)];
            m_next[static_cast<size_t>(c)] =
                std::abs(phi) < limit ? phi + dt * curvature_speed(c) : phi;
        });
        parallel_over(m_band, [&](int c) { m_phi[static_cast<size_t>(c)] = m_next[static_cast<size_t>(c)]; });
    }

    /// Reinitialization (see the header): every domain cell (band and ring) whose closest point
    /// on the zero set of the C¹ bicubic Hermite interpolant of φ can be found gets its distance
    /// to it; the rest take `iterations` Eikonal iterations with those cells fixed. Then the band
    /// is rebuilt from the old band and its ring.
    void reinitialize(int iterations) {
        std::vector<int> domain = m_band;
        for (int c : m_band)
            m_flags[static_cast<size_t>(c)] = IN_BAND | IN_DOMAIN;
        for (int c : m_band) {
            const int i = c / m_nr, j = c % m_nr;
            const int nb[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
            for (const auto& n : nb) {
                if (n[0] < 0 || n[0] >= m_na || n[1] < 0 || n[1] >= m_nr)
                    continue;
                const size_t cn = static_cast<size_t>(n[0]) * m_nr + n[1];
                if (!m_flags[cn]) {
                    m_flags[cn] = IN_DOMAIN;
                    domain.push_back(static_cast<int>(cn));
                }
            }
        }
        std::vector<int> targets;  // cells that get their distance by projection
        for (int c : domain)
            if (std::abs(m_phi[static_cast<size_t>(c)]) < m_projection_width)
                targets.push_back(c);
        parallel_over(targets, [&](int c) {
            const size_t cs = static_cast<size_t>(c);
            if (std::abs(m_phi[cs]) < DERIVATIVE_WIDTH_VOXELS * m_dx) {
                compute_derivatives(c);
                m_flags[cs] |= HAS_DERIVATIVES;
            }
        });
        // Closest points: from the cell's previous closest point (the surface moves a small
        // fraction of a cell per step), else from its own gradient near the surface, else (in
        // later passes, layer by layer) from a neighbour's closest point.
        std::vector<ClosestPoint> found(targets.size());
        parallel_index(targets.size(), [&](size_t k) {
            const int c = targets[k];
            const size_t cs = static_cast<size_t>(c);
            if (m_has_closest_point[cs]) {
                found[k] = project(c, m_cpu[cs], m_cpv[cs]);
                if (found[k].ok)
                    return;
            }
            if (!(m_flags[cs] & HAS_DERIVATIVES) ||
                !(std::abs(m_phi[cs]) < SEED_DISTANCE_VOXELS * m_dx))
                return;
            const double fu = m_da[cs] / m_dx, fv = m_dr[cs] / m_dx;  // of f = φ/Δx
            const double g2 = fu * fu + fv * fv;
            if (g2 > DEGENERATE_GRADIENT_SQUARED) {
                const double f = m_phi[cs] / m_dx;
                found[k] = project(c, c / m_nr - f * fu / g2, c % m_nr - f * fv / g2);
            }
        });
        std::vector<int> pending;
        for (size_t k = 0; k < targets.size(); ++k)
            if (!found[k].ok)
                pending.push_back(targets[k]);
        commit(targets, found, 1);
        for (int pass = 2; pass < MAX_PASSES && !pending.empty(); ++pass) {
            found.assign(pending.size(), ClosestPoint{});
            parallel_index(pending.size(), [&](size_t k) {
                const int c = pending[k];
                const int i = c / m_nr, j = c % m_nr;
                double best = std::numeric_limits<double>::infinity();
                double gu = 0.0, gv = 0.0;
                for (int di = -1; di <= 1; ++di)
                    for (int dj = -1; dj <= 1; ++dj) {
                        const int ni = i + di, nj = j + dj;
                        if (ni < 0 || ni >= m_na || nj < 0 || nj >= m_nr)
                            continue;
                        const size_t cn = static_cast<size_t>(ni) * m_nr + nj;
                        const int rp = m_resolved[cn];
                        if (rp == 0 || rp >= pass)
                            continue;
                        const double du = m_cpu[cn] - i, dv = m_cpv[cn] - j;
                        const double d2 = du * du + dv * dv;
                        if (d2 < best) {
                            best = d2;
                            gu = m_cpu[cn];
                            gv = m_cpv[cn];
                        }
                    }
                found[k].ok = false;
                if (best < std::numeric_limits<double>::infinity())
                    found[k] = project(c, gu, gv);
            });
            std::vector<int> still;
            for (size_t k = 0; k < pending.size(); ++k)
                if (!found[k].ok)
                    still.push_back(pending[k]);
            commit(pending, found, pass);
            if (still.size() == pending.size())
                break;
            pending.swap(still);
        }
        // New values: distances where a closest point was found, Eikonal iterations elsewhere.
        parallel_over(domain, [&](int c) {
            const size_t cs = static_cast<size_t>(c);
            if (m_resolved[cs] == 0)
                return;
            const double du = m_cpu[cs] - c / m_nr, dv = m_cpv[cs] - c % m_nr;
            const double d = std::min(std::sqrt(du * du + dv * dv) * m_dx, m_w);
            m_next[cs] = m_phi[cs] < 0.0 ? -d : d;
            m_flags[cs] |= FROZEN;
        });
        parallel_over(domain, [&](int c) {
            const size_t cs = static_cast<size_t>(c);
            if (m_flags[cs] & FROZEN)
                m_phi[cs] = m_next[cs];
        });
        const double dtau = EIKONAL_STEP_FRACTION * m_dx;
        for (int it = 0; it < iterations; ++it) {
            parallel_over(domain, [&](int c) {
                const size_t cs = static_cast<size_t>(c);
                if (m_flags[cs] & FROZEN)
                    return;
                const double phi = m_phi[cs];
                const double sign = phi < 0.0 ? -1.0 : 1.0;
                const double updated = phi - dtau * sign * (godunov_gradient(c, sign) - 1.0);
                m_next[cs] = std::clamp(updated, -m_w, m_w);
            });
            parallel_over(domain, [&](int c) {
                const size_t cs = static_cast<size_t>(c);
                if (!(m_flags[cs] & FROZEN))
                    m_phi[cs] = m_next[cs];
            });
        }
        m_band.clear();
        for (int c : domain) {
            const size_t cs = static_cast<size_t>(c);
            m_has_closest_point[cs] = m_resolved[cs] != 0;
            m_flags[cs] = 0;
            m_resolved[cs] = 0;
            if (std::abs(m_phi[cs]) < m_w)
                m_band.push_back(c);
            else
                m_phi[cs] = std::copysign(m_w, m_phi[cs]);
        }
        if (++m_reinitializations % SORT_INTERVAL == 0)
            std::sort(m_band.begin(), m_band.end());  // memory order for the stencils
    }

    size_t band_size() const { return m_band.size(); }
    std::vector<double> take_field() { return std::move(m_phi); }

private:
    struct ClosestPoint {
        double u = 0.0, v = 0.0;  ///< index coordinates (a: i, r: j; the axis is v = −½)
        bool ok = false;
    };

    template <class F>
    static void parallel_index(size_t n, const F& f) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, GRAIN),
                          [&](const tbb::blocked_range<size_t>& range) {
                              for (size_t k = range.begin(); k != range.end(); ++k)
                                  f(k);
                          });
    }

    void commit(const std::vector<int>& cells, const std::vector<ClosestPoint>& found, int pass) {
        for (size_t k = 0; k < cells.size(); ++k)
            if (found[k].ok) {
                const size_t cs = static_cast<size_t>(cells[k]);
                m_cpu[cs] = found[k].u;
                m_cpv[cs] = found[k].v;
                m_resolved[cs] = static_cast<std::uint8_t>(pass);
            }
    }

    /// Fourth-order central φ_a, φ_r, φ_ar (per index unit) at cell c.
    void compute_derivatives(int c) {
        const int i = c / m_nr, j = c % m_nr;
        const double w[4] = {1.0 / 12.0, -8.0 / 12.0, 8.0 / 12.0, -1.0 / 12.0};
        const int o[4] = {-2, -1, 1, 2};
        double da = 0.0, dr = 0.0, dar = 0.0;
        for (int k = 0; k < 4; ++k) {
            da += w[k] * at(i + o[k], j);
            dr += w[k] * at(i, j + o[k]);
            for (int l = 0; l < 4; ++l)
                dar += w[k] * w[l] * at(i + o[k], j + o[l]);
        }
        const size_t cs = static_cast<size_t>(c);
        m_da[cs] = da;
        m_dr[cs] = dr;
        m_dar[cs] = dar;
    }

    /// The C¹ bicubic Hermite interpolant of φ/Δx and its gradient at index coordinates (u, v);
    /// false where a corner of the square lies outside the reinitialization domain.
    bool hermite(double u, double v, double& f, double& fu, double& fv) const {
        const double mirror_sign = v < -0.5 ? -1.0 : 1.0;
        if (v < -0.5)
            v = -1.0 - v;
        const int i0 = static_cast<int>(std::floor(u)), j0 = static_cast<int>(std::floor(v));
        if (i0 < 0 || i0 + 1 >= m_na || j0 < -1 || j0 + 1 >= m_nr)
            return false;
        const double s = u - i0, t = v - j0;
        const double hs[2] = {(2.0 * s - 3.0) * s * s + 1.0, (3.0 - 2.0 * s) * s * s};
        const double gs[2] = {((s - 2.0) * s + 1.0) * s, (s - 1.0) * s * s};
        const double hs_d[2] = {6.0 * s * (s - 1.0), 6.0 * s * (1.0 - s)};
        const double gs_d[2] = {(3.0 * s - 4.0) * s + 1.0, (3.0 * s - 2.0) * s};
        const double ht[2] = {(2.0 * t - 3.0) * t * t + 1.0, (3.0 - 2.0 * t) * t * t};
        const double gt[2] = {((t - 2.0) * t + 1.0) * t, (t - 1.0) * t * t};
        const double ht_d[2] = {6.0 * t * (t - 1.0), 6.0 * t * (1.0 - t)};
        const double gt_d[2] = {(3.0 * t - 4.0) * t + 1.0, (3.0 * t - 2.0) * t};
        f = fu = fv = 0.0;
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) {
                const int ci = i0 + a, cj = j0 + b;
                const double odd = cj < 0 ? -1.0 : 1.0;  // φ is even in r: φ_r, φ_ar are odd
                const size_t cs = static_cast<size_t>(ci) * m_nr + (cj < 0 ? 0 : cj);
                if (!(m_flags[cs] & HAS_DERIVATIVES))
                    return false;
                const double p = m_phi[cs] / m_dx, pa = m_da[cs] / m_dx,
                             pr = odd * m_dr[cs] / m_dx, par = odd * m_dar[cs] / m_dx;
                f += p * hs[a] * ht[b] + pa * gs[a] * ht[b] + pr * hs[a] * gt[b] +
                     par * gs[a] * gt[b];
                fu += p * hs_d[a] * ht[b] + pa * gs_d[a] * ht[b] + pr * hs_d[a] * gt[b] +
                      par * gs_d[a] * gt[b];
                fv += p * hs[a] * ht_d[b] + pa * gs[a] * ht_d[b] + pr * hs[a] * gt_d[b] +
                      par * gs[a] * gt_d[b];
            }
        fv *= mirror_sign;
        return true;
    }

    /// Chopp's Newton iteration for the closest point to cell c on the interpolant's zero set,
    /// from (u, v): each step moves onto the zero set along ∇f and removes the tangential part
    /// of x − p.
    ClosestPoint project(int c, double u, double v) const {
        const double xu = c / m_nr, xv = c % m_nr;
        const double reach = m_w / m_dx + PROJECTION_REACH_VOXELS;
        for (int it = 0; it < NEWTON_ITERATIONS; ++it) {
            double f, fu, fv;
            if (!hermite(u, v, f, fu, fv))
                return {};
            const double g2 = fu * fu + fv * fv;
            if (!(g2 > DEGENERATE_GRADIENT_SQUARED))
                return {};
            const double qu = xu - u, qv = xv - v;
            const double along = (qu * fu + qv * fv) / g2;
            const double du = -f * fu / g2 + qu - along * fu;
            const double dv = -f * fv / g2 + qv - along * fv;
            u += du;
            v += dv;
            if ((u - xu) * (u - xu) + (v - xv) * (v - xv) > reach * reach)
                return {};
            if (du * du + dv * dv < NEWTON_TOLERANCE * NEWTON_TOLERANCE)
                return {u, v, true};  // the step held −f∇f/|∇f|², so |f| is as small
        }
        return {};
    }

    template <class F>
    static void parallel_over(const std::vector<int>& cells, const F& f) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, cells.size(), GRAIN),
                          [&](const tbb::blocked_range<size_t>& range) {
                              for (size_t k = range.begin(); k != range.end(); ++k)
                                  f(cells[k]);
                          });
    }

    double at(int i, int j) const {
        return m_phi[static_cast<size_t>(mirror(i, m_na)) * m_nr + mirror(j, m_nr)];
    }

    /// |∇φ|(κ₁ + κ₂) at cell c by second-order central differences (see the header).
    double curvature_speed(int c) const {
        const int i = c / m_nr, j = c % m_nr;
        const double inv_dx = 1.0 / m_dx;
        const double p = at(i, j);
        const double pam = at(i - 1, j), pap = at(i + 1, j);
        const double prm = at(i, j - 1), prp = at(i, j + 1);
        const double pa = 0.5 * (pap - pam) * inv_dx;
        const double pr = 0.5 * (prp - prm) * inv_dx;
        const double paa = (pap - 2.0 * p + pam) * inv_dx * inv_dx;
        const double prr = (prp - 2.0 * p + prm) * inv_dx * inv_dx;
        const double par =
            0.25 * (at(i + 1, j + 1) - at(i + 1, j - 1) - at(i - 1, j + 1) + at(i - 1, j - 1)) *
            inv_dx * inv_dx;
        const double g2 = pa * pa + pr * pr;
        const double meridian = g2 > DEGENERATE_GRADIENT_SQUARED
                                    ? (paa * pr * pr - 2.0 * pa * pr * par + prr * pa * pa) / g2
                                    : 0.5 * (paa + prr);
        const double r = (j + 0.5) * m_dx;
        return meridian + pr / r;
    }

    /// Godunov upwind |∇φ| with second-order ENO one-sided differences, for a cell of `sign`.
    double godunov_gradient(int c, double sign) const {
        const int i = c / m_nr, j = c % m_nr;
        const double inv_dx = 1.0 / m_dx;
        const auto axis_squared = [&](double m2, double m1, double p0, double p1, double p2) {
            const double d2m = m2 - 2.0 * m1 + p0, d20 = m1 - 2.0 * p0 + p1,
                         d2p = p0 - 2.0 * p1 + p2;
            const double minus = (p0 - m1 + 0.5 * minmod(d2m, d20)) * inv_dx;
            const double plus = (p1 - p0 - 0.5 * minmod(d20, d2p)) * inv_dx;
            if (sign > 0.0) {
                const double a = std::max(minus, 0.0), b = std::min(plus, 0.0);
                return std::max(a * a, b * b);
            }
            const double a = std::min(minus, 0.0), b = std::max(plus, 0.0);
            return std::max(a * a, b * b);
        };
        const double p0 = at(i, j);
        const double ga = axis_squared(at(i - 2, j), at(i - 1, j), p0, at(i + 1, j), at(i + 2, j));
        const double gr = axis_squared(at(i, j - 2), at(i, j - 1), p0, at(i, j + 1), at(i, j + 2));
        return std::sqrt(ga + gr);
    }

    int m_na, m_nr;
    double m_dx, m_w;
    std::vector<double> m_phi, m_next;
    std::vector<std::uint8_t> m_flags;
    std::vector<double> m_da, m_dr, m_dar;  ///< derivatives (per index unit) in a reinitialization
    std::vector<double> m_cpu, m_cpv;       ///< closest points (index coordinates)
    std::vector<std::uint8_t> m_resolved;   ///< pass that found the closest point, 0: none
    std::vector<std::uint8_t> m_has_closest_point;  ///< m_cpu, m_cpv hold the last one
    std::vector<int> m_band;
    double m_projection_width = 0.0;
    long m_reinitializations = 0;
};

}  // namespace

void AxisymmetricMcfOptions::validate() const {
    require(voxel_size > 0.0 && std::isfinite(voxel_size), "voxel_size", "a finite number > 0");
    require(end_time >= 0.0 && std::isfinite(end_time), "end_time", "a finite number >= 0");
    require(cfl > 0.0 && cfl <= 1.0, "cfl", "in (0, 1]");
    require(reinit_interval >= 1, "reinit_interval", ">= 1");
    require(reinit_iterations >= 1, "reinit_iterations", ">= 1");
    require(band_half_width_voxels >= 4, "band_half_width_voxels", ">= 4");
    require(projection_width_voxels >= 2.0 && projection_width_voxels <= band_half_width_voxels,
            "projection_width_voxels", "in [2, band_half_width_voxels]");
    require(padding_voxels >= 2, "padding_voxels", ">= 2");
    require(final_reinit_iterations >= 0, "final_reinit_iterations", ">= 0");
}

AxisymmetricMcfReference::AxisymmetricMcfReference(const ImplicitShape& shape,
                                                   const Vec3& axis_point,
                                                   const Vec3& axis_direction,
                                                   const AxisymmetricMcfOptions& options) {
    const auto start = Clock::now();
    options.validate();
    const double axis_norm = axis_direction.norm();
    if (!(axis_norm > 0.0) || !std::isfinite(axis_norm) || !axis_point.allFinite())
        throw std::invalid_argument(
            "AxisymmetricMcfReference: axis_point must be finite and axis_direction a non-zero "
            "finite vector");
    m_axis_point = axis_point;
    m_axis = axis_direction / axis_norm;
    m_dx = options.voxel_size;
    m_band_half_width = options.band_half_width_voxels * m_dx;

    const Box3 bounds = shape.bounds();
    if (!bounds.min().allFinite() || !bounds.max().allFinite() || bounds.isEmpty())
        throw std::invalid_argument(
            "AxisymmetricMcfReference: the shape's bounds must be finite and non-empty");
    double a_min = std::numeric_limits<double>::infinity(), a_max = -a_min, r_max = 0.0;
    for (int k = 0; k < 8; ++k) {
        const Vec3 d = bounds.corner(static_cast<Box3::CornerType>(k)) - m_axis_point;
        const double a = d.dot(m_axis);
        a_min = std::min(a_min, a);
        a_max = std::max(a_max, a);
        r_max = std::max(r_max, (d - a * m_axis).norm());
    }
    const int pad = options.band_half_width_voxels + options.padding_voxels;
    const double na = std::ceil((a_max - a_min) / m_dx) + 2.0 * pad;
    const double nr = std::ceil(r_max / m_dx) + pad;
    if (!(na * nr <= MAX_CELLS))
        throw std::invalid_argument(
            "AxisymmetricMcfReference: the shape needs more than 4e8 cells at this voxel_size");
    m_na = static_cast<int>(na);
    m_nr = static_cast<int>(nr);
    m_a0 = a_min - pad * m_dx;
    m_stats.axial_cells = m_na;
    m_stats.radial_cells = m_nr;

    // Initial φ: exact signed distance in the band, ±band half width beyond.
    const Vec3 radial = m_axis.unitOrthogonal();
    const double candidate = m_band_half_width +
                             std::max(2.0 * m_band_half_width, CANDIDATE_MARGIN_FRACTION * r_max);
    const double tolerance = PROJECTION_TOLERANCE_FRACTION * m_dx;
    std::vector<double> phi(static_cast<size_t>(m_na) * m_nr);
    tbb::parallel_for(tbb::blocked_range<int>(0, m_na), [&](const tbb::blocked_range<int>& rows) {
        for (int i = rows.begin(); i != rows.end(); ++i)
            for (int j = 0; j < m_nr; ++j) {
                const Vec3 x = m_axis_point + (m_a0 + (i + 0.5) * m_dx) * m_axis +
                               ((j + 0.5) * m_dx) * radial;
                const double v = shape.value(x);
                double d = std::copysign(m_band_half_width, v);
                if (std::abs(v) < candidate)
                    d = std::clamp(projected_signed_distance(shape, x, tolerance),
                                   -m_band_half_width, m_band_half_width);
                phi[static_cast<size_t>(i) * m_nr + j] = d;
            }
    });

    MeridianSolver solver(m_na, m_nr, m_dx, m_band_half_width,
                          options.projection_width_voxels * m_dx, std::move(phi));
    m_stats.initial_band_cells = static_cast<long long>(solver.band_size());
    const double dt_max = options.cfl * m_dx * m_dx / STABILITY_DIVISOR;
    m_stats.steps = options.end_time > 0.0 ? static_cast<long>(std::ceil(options.end_time / dt_max))
                                           : 0;
    m_stats.time_step = m_stats.steps > 0 ? options.end_time / m_stats.steps : 0.0;
    for (long step = 1; step <= m_stats.steps; ++step) {
        solver.curvature_step(m_stats.time_step);
        if (step % options.reinit_interval == 0 || step == m_stats.steps) {
            solver.reinitialize(options.reinit_iterations);
            ++m_stats.reinitializations;
        }
    }
    if (options.final_reinit_iterations > 0) {
        solver.reinitialize(options.final_reinit_iterations);
        ++m_stats.reinitializations;
    }
    m_stats.final_band_cells = static_cast<long long>(solver.band_size());
    m_phi = solver.take_field();
    m_stats.seconds = std::chrono::duration<double>(Clock::now() - start).count();
}

double AxisymmetricMcfReference::value(int i, int j) const {
    return m_phi[static_cast<size_t>(mirror(i, m_na)) * m_nr + mirror(j, m_nr)];
}

double AxisymmetricMcfReference::meridian_distance(double a, double r) const {
    const double u = (a - m_a0) / m_dx - 0.5;
    const double v = std::abs(r) / m_dx - 0.5;
    if (!(u >= -1.0 && u <= m_na && v <= m_nr))
        return m_band_half_width;  // beyond the grid, which pads the shape's bounds
    const int i = static_cast<int>(std::floor(u)), j = static_cast<int>(std::floor(v));
    const double s = u - i, t = v - j;
    // Catmull–Rom weights of the nodes −1, 0, 1, 2.
    const auto weights = [](double x, double w[4]) {
        const double x2 = x * x, x3 = x2 * x;
        w[0] = 0.5 * (-x3 + 2.0 * x2 - x);
        w[1] = 0.5 * (3.0 * x3 - 5.0 * x2 + 2.0);
        w[2] = 0.5 * (-3.0 * x3 + 4.0 * x2 + x);
        w[3] = 0.5 * (x3 - x2);
    };
    double wa[4], wr[4];
    weights(s, wa);
    weights(t, wr);
    double sum = 0.0;
    for (int p = 0; p < 4; ++p) {
        double row = 0.0;
        for (int q = 0; q < 4; ++q)
            row += wr[q] * value(i - 1 + p, j - 1 + q);
        sum += wa[p] * row;
    }
    return sum;
}

double AxisymmetricMcfReference::distance(const Vec3& x) const {
    const Vec3 d = x - m_axis_point;
    const double a = d.dot(m_axis);
    return meridian_distance(a, (d - a * m_axis).norm());
}

}  // namespace meniscus::tracker
