#include "fluid/pcg.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <cmath>
#include <stdexcept>

namespace meniscus::fluid {

void IterativeSolverOptions::validate() const {
    if (!(tolerance > 0.0 && tolerance < 1.0)) {
        throw std::invalid_argument(
            "IterativeSolverOptions.tolerance must be a relative residual in (0, 1)");
    }
    if (max_iterations < 1) {
        throw std::invalid_argument("IterativeSolverOptions.max_iterations must be at least 1");
    }
}

namespace {

/// Elements per task of the fused vector passes (a fixed split: sums independent of threads).
constexpr std::size_t VECTOR_GRAIN = 16384;

struct UpdateSums {
    double rr = 0.0;     ///< r·r
    double r_sum = 0.0;  ///< Σ r
};

/// x += alpha p and r −= alpha q in one pass, returning r·r and Σ r of the new r.
UpdateSums update_solution(double alpha, const std::vector<double>& p, const std::vector<double>& q,
                           std::vector<double>& x, std::vector<double>& r) {
    const double* pv = p.data();
    const double* qv = q.data();
    double* xv = x.data();
    double* rv = r.data();
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, r.size(), VECTOR_GRAIN), UpdateSums{},
        [&](const tbb::blocked_range<std::size_t>& range, UpdateSums sums) {
            for (std::size_t c = range.begin(); c != range.end(); ++c) {
                xv[c] += alpha * pv[c];
                rv[c] -= alpha * qv[c];
                sums.rr += rv[c] * rv[c];
                sums.r_sum += rv[c];
            }
            return sums;
        },
        [](const UpdateSums& a, const UpdateSums& b) {
            return UpdateSums{a.rr + b.rr, a.r_sum + b.r_sum};
        });
}

struct PreconditionedSums {
    double rz = 0.0;     ///< r·z
    double z_sum = 0.0;  ///< Σ z
};

PreconditionedSums preconditioned_sums(const std::vector<double>& r, const std::vector<double>& z) {
    const double* rv = r.data();
    const double* zv = z.data();
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, r.size(), VECTOR_GRAIN), PreconditionedSums{},
        [&](const tbb::blocked_range<std::size_t>& range, PreconditionedSums sums) {
            for (std::size_t c = range.begin(); c != range.end(); ++c) {
                sums.rz += rv[c] * zv[c];
                sums.z_sum += zv[c];
            }
            return sums;
        },
        [](const PreconditionedSums& a, const PreconditionedSums& b) {
            return PreconditionedSums{a.rz + b.rz, a.z_sum + b.z_sum};
        });
}

/// p = (z − mean) + beta p on active cells (diag > 0), 0 on the others.
void update_direction(const std::vector<double>& z, double mean, double beta,
                      const std::vector<double>& diag, std::vector<double>& p) {
    const double* zv = z.data();
    const double* dv = diag.data();
    double* pv = p.data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, p.size(), VECTOR_GRAIN),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t c = range.begin(); c != range.end(); ++c)
                              pv[c] = dv[c] > 0.0 ? (zv[c] - mean) + beta * pv[c] : 0.0;
                      });
}

}  // namespace

// The textbook PCG with its vector work fused into four passes per iteration: q = A p with p·q,
// the x and r updates with r·r and Σ r, r·z with Σ z, and the new direction. A singular system's
// mean is removed from z through those sums (z − m, m = Σ z / active cells, r·(z − m) = r·z −
// m Σ r; a preconditioner's z is zero off the active cells) rather than by two more passes,
// and r, whose mean A keeps at zero up to rounding, is projected once at the start.
SolveResult solve_pcg(const PoissonMatrix& matrix, const std::vector<double>& b,
                      const Preconditioner& preconditioner, const IterativeSolverOptions& options,
                      bool singular, std::vector<double>& x) {
    const std::size_t n = matrix.size();
    x.assign(n, 0.0);
    std::vector<double> r = b;
    for (std::size_t c = 0; c < n; ++c) {
        if (matrix.diag[c] <= 0.0) {
            r[c] = 0.0;
        }
    }
    if (singular) {
        remove_active_mean(matrix, r);
    }
    SolveResult result;
    const double b_norm = std::sqrt(dot(r, r));
    if (b_norm == 0.0) {
        result.converged = true;
        return result;
    }
    const double active = singular ? static_cast<double>(matrix.active_count()) : 0.0;
    const std::vector<double>& diag = matrix.diag.storage();
    std::vector<double> z(n, 0.0), search(n, 0.0), q(n, 0.0);
    // r·(z − m) with m the mean of z over the active cells (0 when not singular); Σ r starts
    // at 0 (projected above) and is then the update's.
    double r_sum = 0.0;
    const auto precondition = [&](double& mean) {
        preconditioner.apply(r, z);
        const PreconditionedSums sums = preconditioned_sums(r, z);
        mean = singular && active > 0.0 ? sums.z_sum / active : 0.0;
        return sums.rz - mean * r_sum;
    };
    double mean = 0.0;
    double rz = precondition(mean);
    update_direction(z, mean, 0.0, diag, search);
    result.residual = 1.0;
    for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
        options.cancel.throw_if_requested("the PCG solve");
        const double curvature = matrix.apply_dot(search, q);
        if (!(curvature > 0.0)) {
            break;  // breakdown: search direction in the null space or A not SPD
        }
        const double alpha = rz / curvature;
        const UpdateSums updated = update_solution(alpha, search, q, x, r);
        r_sum = updated.r_sum;
        result.iterations = iteration;
        result.residual = std::sqrt(updated.rr) / b_norm;
        if (result.residual <= options.tolerance) {
            result.converged = true;
            break;
        }
        const double rz_new = precondition(mean);
        const double beta = rz_new / rz;
        rz = rz_new;
        update_direction(z, mean, beta, diag, search);
    }
    if (singular) {
        remove_active_mean(matrix, x);
    }
    return result;
}

}  // namespace meniscus::fluid
