#pragma once
/// \file Modified incomplete Cholesky MIC(0) preconditioner for the 7-point Poisson matrix.

#include <memory>
#include <vector>

#include "fluid/pcg.h"
#include "fluid/poisson_matrix.h"

namespace meniscus::fluid {

/// Parameters of the MIC(0) factorisation (Bridson, "Fluid Simulation for Computer Graphics").
struct Mic0Options {
    double tuning = 0.97;  ///< τ ∈ [0, 1]: 0 is plain IC(0), 1 full modified IC (row sums kept)
    double safety = 0.25;  ///< σ ∈ (0, 1): a pivot below σ·A_ii falls back to A_ii

    /// Throws std::invalid_argument naming the field when out of range.
    void validate() const;
};

/// MIC(0) preconditioner: A ≈ L Lᵀ with L having A's sparsity, built once per matrix. The
/// factorisation and the two triangular solves are sequential (lexicographic order). Couplings
/// across periodic seams are left out of L (it factorises PoissonMatrix::without_wrap(), whose
/// seam rows are diagonally dominant): a symmetric positive definite approximation still.
class Mic0Preconditioner final : public Preconditioner {
public:
    /// Factorises `matrix`; keeps a reference to it (the matrix must outlive this object).
    /// Throws std::invalid_argument when `options` are invalid.
    Mic0Preconditioner(const PoissonMatrix& matrix, const Mic0Options& options = {});
    void apply(const std::vector<double>& r, std::vector<double>& z) const override;

private:
    std::unique_ptr<PoissonMatrix> m_unwrapped;  ///< without_wrap() of a periodic matrix, or null
    const PoissonMatrix& m_matrix;               ///< the caller's matrix, or *m_unwrapped
    std::vector<double> m_inverse_pivot;         ///< 1/L_ii per cell, 0 on inactive cells
};

}  // namespace meniscus::fluid
