/// Coupled runs sampled every step, measurements on the mesh (volume moments, Fourier modes of
/// a column's radius and of a surface's height), least-squares fits of damped oscillations and
/// of exponential growth, and the analytic references of docs/validation.md part B.

#include "app/fluid_measures.h"

#include "app/errors.h"
#include "tracker/mesh_measures.h"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace meniscus::app {

namespace {

using Clock = std::chrono::steady_clock;
using Eigen::Vector3d;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Golden-section minimum of f on [a, b] (f unimodal there).
template <class F>
double golden_minimum(F&& f, double a, double b, int iterations) {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double c = b - g * (b - a), d = a + g * (b - a);
    double fc = f(c), fd = f(d);
    for (int i = 0; i < iterations; ++i) {
        if (fc < fd) {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    return 0.5 * (a + b);
}

/// Least squares y ≈ X·c; returns c and writes the residual sum of squares.
Eigen::VectorXd least_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, double* rss) {
    const Eigen::VectorXd c = x.colPivHouseholderQr().solve(y);
    if (rss)
        *rss = (x * c - y).squaredNorm();
    return c;
}

/// Fits y = m + a cos(k(s − s0)) + b sin(k(s − s0)) over the given samples.
ModeFit fit_mode(const std::vector<double>& s, const std::vector<double>& h, double s0, double k) {
    if (s.size() < 3)
        return {};
    Eigen::MatrixXd x(static_cast<Eigen::Index>(s.size()), 3);
    Eigen::VectorXd y(static_cast<Eigen::Index>(s.size()));
    for (size_t i = 0; i < s.size(); ++i) {
        const auto r = static_cast<Eigen::Index>(i);
        x(r, 0) = 1.0;
        x(r, 1) = std::cos(k * (s[i] - s0));
        x(r, 2) = std::sin(k * (s[i] - s0));
        y(r) = h[i];
    }
    const Eigen::VectorXd c = least_squares(x, y, nullptr);
    return {c(0), c(1), c(2)};
}

}  // namespace

// ---- Running ----------------------------------------------------------------------------------

FluidRunRecord run_sampled(coupling::Simulation& sim, double end_time,
                           const std::function<void(const coupling::Simulation&)>& sample,
                           long long max_steps) {
    const auto start = Clock::now();
    FluidRunRecord r;
    const auto record = [&](int intersecting) {
        const tracker::SurfaceMesh& mesh = sim.tracker().mesh();
        r.t.push_back(sim.time());
        r.components.push_back(tracker::triangle_components(mesh).count);
        r.enclosed_volume.push_back(tracker::enclosed_volume(mesh));
        r.intersecting_pairs.push_back(intersecting);
        r.max_speed.push_back(sim.fluid().grid().max_abs_velocity().maxCoeff());
        if (sample)
            sample(sim);
    };
    record(-1);
    while (sim.time() < end_time * (1.0 - 1e-12)) {
        if (max_steps > 0 && r.steps >= max_steps) {
            r.wall_seconds = seconds_since(start);
            return r;
        }
        const coupling::SimulationStepReport s = sim.step(end_time - sim.time());
        ++r.steps;
        r.pressure_converged = r.pressure_converged && s.fluid.pressure.converged;
        r.viscosity_converged = r.viscosity_converged && s.fluid.viscosity.converged;
        r.max_passes = std::max(r.max_passes, s.fluid.passes);
        if (r.steps == 1)
            r.first_dt = s.dt;
        r.max_intersecting_pairs = std::max(r.max_intersecting_pairs, s.integrate.intersecting_pairs);
        r.merges += s.volume.merges;
        r.splits += s.volume.splits;
        record(s.integrate.intersecting_pairs);
        if (!(s.integrate.time_advanced > 0.0))
            break;  // a stalled step: reported as not completed
    }
    r.completed = sim.time() >= end_time * (1.0 - 1e-12);
    r.wall_seconds = seconds_since(start);
    return r;
}

// ---- Measurements -----------------------------------------------------------------------------

VolumeMoments volume_moments(const tracker::SurfaceMesh& mesh) {
    // Signed tetrahedra (0, p0, p1, p2): volume V_t = p0·(p1×p2)/6, ∫x dV = V_t Σp/4,
    // ∫x_d² dV = V_t/10 (Σ p_d² + Σ_{i<j} p_i,d p_j,d) (the origin vertex adds nothing).
    // Computed about a reference point near the mesh to limit cancellation.
    Vector3d ref = Vector3d::Zero();
    int n = 0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi)) {
            ref += mesh.position(vi);
            ++n;
        }
    if (n == 0)
        return {};
    ref /= n;
    double volume = 0.0;
    Vector3d first = Vector3d::Zero(), second = Vector3d::Zero();
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const tracker::Triangle& tri = mesh.triangle(ti);
        const Vector3d p0 = mesh.position(tri[0]) - ref, p1 = mesh.position(tri[1]) - ref,
                       p2 = mesh.position(tri[2]) - ref;
        const double v = p0.dot(p1.cross(p2)) / 6.0;
        volume += v;
        first += v * (p0 + p1 + p2) / 4.0;
        second += v / 10.0 *
                  (p0.cwiseProduct(p0) + p1.cwiseProduct(p1) + p2.cwiseProduct(p2) +
                   p0.cwiseProduct(p1) + p0.cwiseProduct(p2) + p1.cwiseProduct(p2));
    }
    VolumeMoments m;
    m.volume = volume;
    const Vector3d c = first / volume;
    m.centroid = ref + c;
    const Vector3d central = second / volume - c.cwiseProduct(c);
    m.semi_axes = (5.0 * central.cwiseMax(0.0)).cwiseSqrt();
    return m;
}

Eigen::Vector3d centroid_velocity(const tracker::SurfaceMesh& mesh,
                                  const std::vector<tracker::Vec3>& velocities) {
    if (velocities.size() != static_cast<size_t>(mesh.num_vertices()))
        throw std::invalid_argument("centroid_velocity: one velocity per vertex slot expected");
    const VolumeMoments m = volume_moments(mesh);
    if (!(m.volume > 0.0))
        throw std::invalid_argument("centroid_velocity: the mesh encloses no positive volume");
    // ∫_T f g dA = A/12 (Σ f_i g_i + Σ f_i Σ g_i) for f, g linear over a triangle of area A.
    Vector3d sum = Vector3d::Zero();
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const auto& tri = mesh.triangle(ti);
        const Vector3d& p0 = mesh.position(tri[0]);
        const Vector3d area_normal = 0.5 * (mesh.position(tri[1]) - p0).cross(mesh.position(tri[2]) - p0);
        Vector3d sum_w = Vector3d::Zero(), sum_wg = Vector3d::Zero();
        double sum_g = 0.0;
        for (int c = 0; c < 3; ++c) {
            const Vector3d w = mesh.position(tri[c]) - m.centroid;
            const double g = velocities[static_cast<size_t>(tri[c])].dot(area_normal);
            sum_w += w;
            sum_g += g;
            sum_wg += g * w;
        }
        sum += (sum_wg + sum_g * sum_w) / 12.0;
    }
    return sum / m.volume;
}

ModeFit column_radius_mode(const tracker::SurfaceMesh& mesh, const Eigen::Vector2d& axis_yz,
                           double x0, double wavelength, double x_lo, double x_hi) {
    std::vector<double> s, r;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        const Vector3d& p = mesh.position(vi);
        if (p.x() < x_lo || p.x() > x_hi)
            continue;
        s.push_back(p.x());
        r.push_back(std::hypot(p.y() - axis_yz.x(), p.z() - axis_yz.y()));
    }
    return fit_mode(s, r, x0, 2.0 * M_PI / wavelength);
}

ModeFit surface_height_mode(const tracker::SurfaceMesh& mesh, const Vector3d& lo,
                            const Vector3d& hi, double z_min, double x0, double wavelength) {
    std::vector<double> s, z;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        const Vector3d& p = mesh.position(vi);
        if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any() || p.z() < z_min)
            continue;
        s.push_back(p.x());
        z.push_back(p.z());
    }
    return fit_mode(s, z, x0, 2.0 * M_PI / wavelength);
}

// ---- Fits -------------------------------------------------------------------------------------

OscillationFit fit_damped_oscillation(const std::vector<double>& t, const std::vector<double>& y,
                                      double omega_min, double omega_max) {
    if (t.size() != y.size() || t.size() < 6)
        throw std::invalid_argument("fit_damped_oscillation: need ≥ 6 samples of t and y");
    if (!(omega_min > 0.0 && omega_max > omega_min))
        throw std::invalid_argument("fit_damped_oscillation: need 0 < omega_min < omega_max");
    const auto n = static_cast<Eigen::Index>(t.size());
    const Eigen::VectorXd yv = Eigen::Map<const Eigen::VectorXd>(y.data(), n);
    const auto solve = [&](double omega, double gamma, double* rss) {
        Eigen::MatrixXd x(n, 3);
        for (Eigen::Index i = 0; i < n; ++i) {
            const double ti = t[static_cast<size_t>(i)], e = std::exp(-gamma * ti);
            x(i, 0) = 1.0;
            x(i, 1) = e * std::cos(omega * ti);
            x(i, 2) = e * std::sin(omega * ti);
        }
        return least_squares(x, yv, rss);
    };
    constexpr int GOLDEN_ITERATIONS = 60;
    const double gamma_bound = omega_min;
    const auto best_gamma = [&](double omega) {
        return golden_minimum(
            [&](double gamma) {
                double rss = 0.0;
                solve(omega, gamma, &rss);
                return rss;
            },
            -gamma_bound, gamma_bound, GOLDEN_ITERATIONS);
    };
    const auto rss_at = [&](double omega) {
        double rss = 0.0;
        solve(omega, best_gamma(omega), &rss);
        return rss;
    };
    // Coarse scan (the residual has side minima), then golden section around the best.
    constexpr int SCAN = 200;
    const double step = (omega_max - omega_min) / SCAN;
    double best = omega_min, best_rss = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= SCAN; ++i) {
        const double omega = omega_min + i * step;
        const double rss = rss_at(omega);
        if (rss < best_rss) {
            best_rss = rss;
            best = omega;
        }
    }
    OscillationFit fit;
    fit.omega = golden_minimum(rss_at, std::max(omega_min, best - step),
                               std::min(omega_max, best + step), GOLDEN_ITERATIONS);
    fit.decay_rate = best_gamma(fit.omega);
    double rss = 0.0;
    const Eigen::VectorXd c = solve(fit.omega, fit.decay_rate, &rss);
    fit.offset = c(0);
    fit.cos_coefficient = c(1);
    fit.sin_coefficient = c(2);
    fit.amplitude = std::hypot(c(1), c(2));
    fit.rms_residual = std::sqrt(rss / static_cast<double>(n));
    return fit;
}

GrowthFit fit_growth_from_rest(const std::vector<double>& t, const std::vector<double>& y,
                               double rate_min, double rate_max) {
    if (t.size() != y.size() || t.size() < 4)
        throw std::invalid_argument("fit_growth_from_rest: need ≥ 4 samples of t and y");
    if (!(rate_min > 0.0 && rate_max > rate_min))
        throw std::invalid_argument("fit_growth_from_rest: need 0 < rate_min < rate_max");
    const auto n = static_cast<Eigen::Index>(t.size());
    const auto solve = [&](double s, double* rss) {
        Eigen::MatrixXd x(n, 2);
        Eigen::VectorXd rhs(n);
        for (Eigen::Index i = 0; i < n; ++i) {
            const double ti = t[static_cast<size_t>(i)], w = 1.0 / y[static_cast<size_t>(i)];
            x(i, 0) = w * std::exp(s * ti);
            x(i, 1) = w * std::exp(-s * ti);
            rhs(i) = 1.0;
        }
        return least_squares(x, rhs, rss);
    };
    const auto rss_at = [&](double s) {
        double rss = 0.0;
        solve(s, &rss);
        return rss;
    };
    constexpr int SCAN = 200;
    constexpr int GOLDEN_ITERATIONS = 60;
    const double step = (rate_max - rate_min) / SCAN;
    double best = rate_min, best_rss = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= SCAN; ++i) {
        const double rss = rss_at(rate_min + i * step);
        if (rss < best_rss) {
            best_rss = rss;
            best = rate_min + i * step;
        }
    }
    GrowthFit fit;
    fit.rate = golden_minimum(rss_at, std::max(rate_min, best - step),
                              std::min(rate_max, best + step), GOLDEN_ITERATIONS);
    double rss = 0.0;
    const Eigen::VectorXd c = solve(fit.rate, &rss);
    fit.a_plus = c(0);
    fit.a_minus = c(1);
    fit.rms_relative_residual = std::sqrt(rss / static_cast<double>(n));
    return fit;
}

// ---- References -------------------------------------------------------------------------------

}  // namespace meniscus::app
