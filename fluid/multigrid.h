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
/// before and black→red after the coarse correction so the cycle is a symmetric operator.

#include <array>
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

    /// Throws std::invalid_argument naming the field when out of range.
    void validate() const;
};

/// x on the first and the last plane of each periodic axis of a level, taken before each half
/// sweep of the smoother: neighbours across the seam are read from here, so where an odd cell
/// count puts one colour on both sides of the seam the half sweep is still a Jacobi update of its
/// colour (the cycle stays symmetric, and independent of the order and the threads).
struct SeamPlanes {
    std::array<std::vector<double>, 3> first;
    std::array<std::vector<double>, 3> last;
};

/// One V-cycle from a zero initial guess, as a symmetric preconditioner. The hierarchy is built in
/// the constructor. apply() uses internal scratch vectors: one object must not be applied from
/// two threads at once (the cycle itself is TBB-parallel).
class MultigridPreconditioner final : public Preconditioner {
public:
    /// Builds the coarse levels of `matrix` (which must outlive this object).
    /// Throws std::invalid_argument when `options` are invalid.
    MultigridPreconditioner(const PoissonMatrix& matrix, const MultigridOptions& options = {});
    void apply(const std::vector<double>& r, std::vector<double>& z) const override;
    /// Number of levels including the finest.
    int levels() const { return static_cast<int>(m_levels.size()); }

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

private:
    struct Level {
        PoissonMatrix matrix;           ///< unused for level 0 (the caller's matrix)
        mutable std::vector<double> x;  ///< correction on this level (coarse levels only)
        mutable std::vector<double> b;  ///< right-hand side on this level (coarse levels only)
        mutable std::vector<double> r;  ///< residual scratch
        /// the transfers' scratch: after their x pass and after their x and y passes
        mutable std::vector<double> along_x, along_xy;
        AxisTransfer transfer[3];       ///< to the next coarser level
        /// x on the seam planes of periodic axes during a half sweep (smoother scratch)
        mutable SeamPlanes seams;
    };
    const PoissonMatrix& level_matrix(std::size_t level) const;
    /// One V-cycle from x = 0 on `level` for right-hand side b (x is overwritten).
    void cycle(std::size_t level, const std::vector<double>& b, std::vector<double>& x) const;

    const PoissonMatrix& m_fine;
    MultigridOptions m_options;
    std::vector<Level> m_levels;
};

}  // namespace meniscus::fluid
