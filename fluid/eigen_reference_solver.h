#pragma once
/// \file Reference backend: Eigen's ConjugateGradient with an IncompleteCholesky preconditioner,
/// on the same system as the in-house solvers, for comparison.

#include <vector>

#include "fluid/poisson_matrix.h"
#include "fluid/solve_result.h"

namespace meniscus::fluid {

/// Solves A x = b with Eigen::ConjugateGradient<SparseMatrix, Lower|Upper,
/// IncompleteCholesky<double>> on the active cells of `matrix` (assembled to CSR first).
/// Same conventions as solve_pcg: x starts at 0 and is overwritten; `singular` projects b and x
/// to zero mean over active cells; the residual is Eigen's ‖b − A x‖₂ / ‖b‖₂.
SolveResult solve_eigen_ic_cg(const PoissonMatrix& matrix, const std::vector<double>& b,
                              const IterativeSolverOptions& options, bool singular,
                              std::vector<double>& x);

}  // namespace meniscus::fluid
