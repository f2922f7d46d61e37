#pragma once
/// \file Outcome of an iterative linear solve.

#include "common/cancellation.h"

namespace meniscus::fluid {

/// What an iterative solve achieved. Non-convergence is an expected numerical outcome, not an
/// error: the caller decides what it means.
struct SolveResult {
    bool converged = false;  ///< residual ≤ requested tolerance
    int iterations = 0;      ///< iterations performed
    double residual = 0.0;  ///< final relative residual ‖b − A x‖₂ / ‖b‖₂ (0 when b = 0)
};

}  // namespace meniscus::fluid

namespace meniscus::fluid {

/// Stopping rule of an iterative linear solve.
struct IterativeSolverOptions {
    double tolerance = 1.0e-6;  ///< stop when ‖b − A x‖₂ / ‖b‖₂ ≤ tolerance (> 0, < 1)
    int max_iterations = 1000;  ///< give up (converged = false) after this many iterations (≥ 1)
    /// Checked every iteration: throws meniscus::Cancelled once requested (never by default).
    CancellationToken cancel;

    /// Throws std::invalid_argument naming the field when out of range.
    void validate() const;
};

}  // namespace meniscus::fluid
