#pragma once
/// \file Geometric multigrid V-cycle used as a PCG preconditioner for the variable-coefficient
/// pressure Poisson matrix (in the spirit of McAdams, Sifakis & Teran 2010).
///
/// Cell-centred coarsening by 2 in each direction (ceil(n/2) cells); coarse face coefficients are
/// the fine ones rediscretised on the coarse grid (for each of the 2×2 fine lines through a coarse
/// face, the (½, 1, ½)-weighted average of the three fine faces between the two coarse centres;
/// ½ · the sum over the lines), the Dirichlet (free-surface) part of the diagonal is summed and
/// scaled by ½ the same way; transfers are cell-centred
/// trilinear prolongation P and restriction Pᵀ (wrapping around periodic axes, see
/// PoissonMatrix::periodic); smoothing is red–black Gauss–Seidel, red→black
/// before and black→red after the coarse correction so the cycle is a symmetric operator (the
/// smoother multiplies by the inverse diagonal, kept per level).
///
/// By default the cycle runs in single precision (the matrices and vectors of every level in
/// float: half the memory traffic of its sweeps and transfers) while the Krylov solve around it
/// stays in double: the cycle's rounding, about 1e-7 of the correction, lies far
/// below its own approximation error, so the outer iterations and the solution's accuracy are
/// those of the double cycle (the residual is computed in double). The residual passed in is
/// scaled by a power of two into float's range and the result scaled back (both exact).

#include <array>
#include <memory>
#include <vector>

#include "fluid/pcg.h"
#include "fluid/poisson_matrix.h"

namespace meniscus::fluid {

/// Shape of the V-cycle.
struct MultigridOptions {
    int smoothing_sweeps = 2;      ///< red–black Gauss–Seidel sweeps before and after (≥ 1)
    int coarsest_sweeps = 40;      ///< symmetric sweeps on the coarsest level (≥ 1)
    int coarsest_max_cells = 512;  ///< stop coarsening at or below this many cells (≥ 1)
    /// Without periodic axes, run a red and a black half sweep in one pass over memory (plane
    /// k's first colour, then plane k−1's second): the same result, bit for bit.
    bool pipelined_sweeps = true;
    /// Run the cycles in float (see file comment); false: in double. A matrix whose diagonal
    /// spans more than float's range (2^100 between its largest and smallest positive entry) is
    /// cycled in double either way.
    bool single_precision = true;

    /// Throws std::invalid_argument naming the field when out of range.
    void validate() const;
};

/// One V-cycle from a zero initial guess, as a symmetric preconditioner. The hierarchy is built in
/// the constructor. apply() uses internal scratch vectors: one object must not be applied from
/// two threads at once (the cycle itself is TBB-parallel).
class MultigridPreconditioner final : public Preconditioner {
public:
    /// Builds the coarse levels of `matrix` (which must outlive this object).
    /// Throws std::invalid_argument when `options` are invalid.
    MultigridPreconditioner(const PoissonMatrix& matrix, const MultigridOptions& options = {});
    ~MultigridPreconditioner() override;
    MultigridPreconditioner(const MultigridPreconditioner&) = delete;
    MultigridPreconditioner& operator=(const MultigridPreconditioner&) = delete;
    void apply(const std::vector<double>& r, std::vector<double>& z) const override;
    /// Number of levels including the finest.
    int levels() const;
    /// True when the cycles run in float (options.single_precision and a matrix that fits).
    bool single_precision() const;

    /// 1D transfer weights between a fine axis of n cells and its coarse axis of (n+1)/2 cells.
    struct AxisTransfer {
        /// For each fine cell: the two coarse cells it interpolates from and their weights.
        std::vector<int> prolong_cell[2];
        std::vector<double> prolong_weight[2];
        /// For each coarse cell: up to 4 fine cells whose prolongation uses it (Pᵀ).
        std::vector<int> restrict_count;
        std::vector<int> restrict_cell;  ///< 4 per coarse cell
        std::vector<double> restrict_weight;
    };
    /// The hierarchy and its V-cycle in one precision (multigrid.cpp).
    class Cycle;

private:
    std::unique_ptr<const Cycle> m_cycle;
};

}  // namespace meniscus::fluid
