#include "fluid/eigen_reference_solver.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>

#include <cstdint>

namespace meniscus::fluid {

namespace {

constexpr int STENCIL_SIZE = 7;

}  // namespace

SolveResult solve_eigen_ic_cg(const PoissonMatrix& matrix, const std::vector<double>& b,
                              const IterativeSolverOptions& options, bool singular,
                              std::vector<double>& x) {
    const int ni = matrix.ni(), nj = matrix.nj(), nk = matrix.nk();
    const std::size_t n = matrix.size();
    std::vector<std::int64_t> unknown(n, -1);
    std::int64_t count = 0;
    for (std::size_t c = 0; c < n; ++c) {
        if (matrix.diag[c] > 0.0) {
            unknown[c] = count++;
        }
    }
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(static_cast<std::size_t>(count) * STENCIL_SIZE);
    Eigen::VectorXd rhs(count);
    for (int k = 0; k < nk; ++k) {
        for (int j = 0; j < nj; ++j) {
            for (int i = 0; i < ni; ++i) {
                const std::size_t c = matrix.diag.index(i, j, k);
                const std::int64_t row = unknown[c];
                if (row < 0) {
                    continue;
                }
                rhs[row] = b[c];
                triplets.emplace_back(row, row, matrix.diag[c]);
                const auto couple = [&](std::size_t other, double value) {
                    if (value != 0.0 && unknown[other] >= 0) {
                        triplets.emplace_back(row, unknown[other], value);
                        triplets.emplace_back(unknown[other], row, value);
                    }
                };
                // The last cell of a periodic axis couples to the first (the seam).
                if (i + 1 < ni || matrix.periodic[0])
                    couple(matrix.diag.index((i + 1) % ni, j, k), matrix.off_x[c]);
                if (j + 1 < nj || matrix.periodic[1])
                    couple(matrix.diag.index(i, (j + 1) % nj, k), matrix.off_y[c]);
                if (k + 1 < nk || matrix.periodic[2])
                    couple(matrix.diag.index(i, j, (k + 1) % nk), matrix.off_z[c]);
            }
        }
    }
    Eigen::SparseMatrix<double> a(count, count);
    a.setFromTriplets(triplets.begin(), triplets.end());
    if (singular && count > 0) {
        rhs.array() -= rhs.mean();
    }
    x.assign(n, 0.0);
    SolveResult result;
    if (count == 0 || rhs.norm() == 0.0) {
        result.converged = true;
        return result;
    }
    Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                             Eigen::IncompleteCholesky<double>>
        solver;
    solver.setTolerance(options.tolerance);
    solver.setMaxIterations(options.max_iterations);
    solver.compute(a);
    Eigen::VectorXd solution = solver.solve(rhs);
    if (singular) {
        solution.array() -= solution.mean();
    }
    for (std::size_t c = 0; c < n; ++c) {
        if (unknown[c] >= 0) {
            x[c] = solution[unknown[c]];
        }
    }
    result.iterations = static_cast<int>(solver.iterations());
    result.residual = solver.error();
    result.converged = solver.info() == Eigen::Success && result.residual <= options.tolerance;
    return result;
}

}  // namespace meniscus::fluid
