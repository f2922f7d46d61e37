#pragma once
/// \file The coarse levels of the multigrid V-cycle (multigrid.h), built in double: per level the
/// cell-centred transfers along each axis and the coarse matrix, its face coefficients the fine
/// ones rediscretised (for each of the 2×2 fine lines through a coarse face, the (½, 1, ½)-weighted
/// average of the three fine faces between the two coarse centres; ½ · the sum over the lines)
/// and its Dirichlet part the fine cells' summed and halved.

#include <array>
#include <vector>

#include "fluid/multigrid.h"
#include "fluid/poisson_matrix.h"

namespace meniscus::fluid {

/// Fine cells a coarse cell's restriction gathers along one axis (AxisTransfer's slots).
constexpr int AXIS_TRANSFER_SLOTS = 4;

/// The coarse levels of a matrix and the transfers between them.
struct MultigridHierarchy {
    std::vector<PoissonMatrix> coarse;  ///< levels 1, 2, …
    /// transfers[l]: from level l to level l + 1
    std::vector<std::array<MultigridPreconditioner::AxisTransfer, 3>> transfers;
};

/// Coarsens `fine` by 2 along each axis (ceil(n/2) cells) until a level has at most
/// `coarsest_max_cells` cells or no axis longer than 2.
MultigridHierarchy build_multigrid_hierarchy(const PoissonMatrix& fine, int coarsest_max_cells);

}  // namespace meniscus::fluid
