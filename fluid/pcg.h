#pragma once
/// \file Preconditioned conjugate gradient on the compact Poisson matrix.

#include <vector>

#include "fluid/poisson_matrix.h"
#include "fluid/solve_result.h"

namespace meniscus::fluid {

/// A symmetric positive (semi-)definite approximation M⁻¹ of A⁻¹ applied to whole vectors.
class Preconditioner {
public:
    virtual ~Preconditioner() = default;
    /// z = M⁻¹ r. Vectors use the PoissonMatrix layout; z is resized if needed and its inactive
    /// entries are zero.
    virtual void apply(const std::vector<double>& r, std::vector<double>& z) const = 0;
};

/// Solves A x = b by PCG starting from x = 0 (x is overwritten, size A.size()).
///
/// When `singular` is true A is taken to be a pure-Neumann operator whose null space is the
/// constant over active cells: b, every residual and every preconditioned residual are projected
/// to zero mean, and the returned x has zero mean. The residual is relative to the (projected) b.
/// Returns {converged, iterations, residual}; never throws on non-convergence. Throws
/// meniscus::Cancelled when options.cancel is requested (checked every iteration).
SolveResult solve_pcg(const PoissonMatrix& matrix, const std::vector<double>& b,
                      const Preconditioner& preconditioner, const IterativeSolverOptions& options,
                      bool singular, std::vector<double>& x);

}  // namespace meniscus::fluid
