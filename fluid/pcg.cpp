#include "fluid/pcg.h"

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
    std::vector<double> z(n, 0.0), search(n, 0.0), q(n, 0.0);
    preconditioner.apply(r, z);
    if (singular) {
        remove_active_mean(matrix, z);
    }
    search = z;
    double rz = dot(r, z);
    result.residual = 1.0;
    for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
        options.cancel.throw_if_requested("the PCG solve");
        matrix.apply(search, q);
        const double curvature = dot(search, q);
        if (!(curvature > 0.0)) {
            break;  // breakdown: search direction in the null space or A not SPD
        }
        const double alpha = rz / curvature;
        axpy(alpha, search, x);
        axpy(-alpha, q, r);
        if (singular) {
            remove_active_mean(matrix, r);
        }
        result.iterations = iteration;
        result.residual = std::sqrt(dot(r, r)) / b_norm;
        if (result.residual <= options.tolerance) {
            result.converged = true;
            break;
        }
        preconditioner.apply(r, z);
        if (singular) {
            remove_active_mean(matrix, z);
        }
        const double rz_new = dot(r, z);
        const double beta = rz_new / rz;
        rz = rz_new;
        xpby(z, beta, search);
    }
    if (singular) {
        remove_active_mean(matrix, x);
    }
    return result;
}

}  // namespace meniscus::fluid
