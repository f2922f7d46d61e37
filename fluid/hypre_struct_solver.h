#pragma once
/// \file A symmetric 7-point system (PoissonMatrix: the pressure Poisson system, or one velocity
/// component's block of the viscous operator) solved by hypre (Debian libhypre-dev) through its
/// structured-grid interface: PCG (HYPRE_StructPCG) preconditioned by one PFMG V-cycle
/// (HYPRE_StructPFMG), on one process (MPI_COMM_SELF) or on the ranks of a distributed run, each
/// holding its slab of z-layers (slab_decomposition.h) as one box of a HYPRE_StructGrid on
/// MPI_COMM_WORLD.
///
/// The PoissonMatrix becomes a 7-point variable-coefficient HYPRE_StructMatrix with the same
/// entries (hypre stores matrix coefficients as they are: the positive diagonal, the off-diagonals
/// ≤ 0 of poisson_matrix.h); inactive cells (diagonal 0) become identity rows with zero couplings
/// and a zero right-hand side; a `periodic` axis is a periodic axis of the HYPRE_StructGrid
/// (period = the cell count), so the last cell's +1 stencil entry couples it to cell 0.
/// A singular (pure Neumann) system: the right-hand side is projected to zero mean over the
/// active cells before the solve and the solution's mean over them removed after, as solve_pcg
/// does (hypre's PCG itself does not project its residuals; the projected right-hand side lies in
/// the range of A, so it converges to a solution, which may carry a constant, removed after).
///
/// Distributed, each rank passes the matrix it assembled on its block of the grid (its slab and
/// ghost layers, on which the rows of its own cells are exactly the global system's) and hypre
/// takes the rows of the owned layers; vectors are the block's, of which only the owned layers are
/// read and written.
///
/// Neither MPI nor hypre appears in this header: both are private to meniscus::fluid.

#include <memory>
#include <vector>

#include "fluid/pcg.h"
#include "fluid/poisson_matrix.h"
#include "fluid/rank_communicator.h"
#include "fluid/slab_decomposition.h"
#include "fluid/solve_result.h"

namespace meniscus::fluid {

/// Initialises MPI (ensure_mpi_initialized()) and hypre (HYPRE_Init) once per process, and
/// registers HYPRE_Finalize with std::atexit (it runs before MPI_Finalize). Called by
/// HypreStructSolver; callable directly. Throws std::runtime_error when MPI or hypre fails.
void ensure_hypre_initialized();

/// A PoissonMatrix set up once in hypre (grid, matrix, PFMG hierarchy), then solved for any
/// number of right-hand sides. Keeps no reference to the matrix. All calls into hypre are
/// serialised by one process-wide lock (hypre keeps global state), so objects may be used from
/// any thread, one solve at a time per process.
///
/// As a Preconditioner, apply() is one PFMG V-cycle from a zero guess (symmetric red–black
/// Gauss–Seidel, one sweep before and after, Galerkin coarse operators).
class HypreStructSolver final : public Preconditioner {
public:
    /// One process. `singular`: A is pure Neumann (null space = the constant over active cells).
    /// Throws std::invalid_argument for an empty matrix, std::runtime_error when hypre fails.
    HypreStructSolver(const PoissonMatrix& matrix, bool singular);
    /// Collective over `ranks` (every rank constructs its own, with the same `decomposition` of
    /// the grid's z-layers over ranks.size() ranks): `block` is this rank's block of the system,
    /// decomposition.local_layers(rank) z-layers, non-periodic along z when the decomposition is
    /// distributed (the decomposition wraps instead), with at least one ghost layer. `singular`
    /// as above, for the global system. Throws std::invalid_argument when the sizes do not fit.
    HypreStructSolver(const PoissonMatrix& block, bool singular,
                      const SlabDecomposition& decomposition, const RankCommunicator& ranks);
    ~HypreStructSolver() override;
    HypreStructSolver(const HypreStructSolver&) = delete;
    HypreStructSolver& operator=(const HypreStructSolver&) = delete;

    /// Solves A x = b with hypre's PCG + PFMG from x = 0 to the relative residual
    /// ‖b − A x‖₂ / ‖b‖₂ ≤ options.tolerance (hypre's two-norm criterion on its recursively
    /// updated residual, as solve_pcg), at most options.max_iterations. Same conventions as
    /// solve_pcg: b's inactive entries are ignored, x (resized) is zero on inactive cells, the
    /// returned residual is relative to the (projected) b. options.cancel is checked before and
    /// after the solve only (hypre's iterations cannot be interrupted). Distributed: collective;
    /// b and x are the block's, x zero outside the owned layers (halo_exchange.h fills them).
    SolveResult solve(const std::vector<double>& b, const IterativeSolverOptions& options,
                      std::vector<double>& x) const;

    /// Subtracts from `v` (a block vector) its mean over the active owned cells of every rank
    /// (collective; the projection onto the complement of a singular system's null space).
    void remove_mean(std::vector<double>& v) const;

    /// z = one PFMG V-cycle applied to r (z resized; inactive entries zero). No mean projection:
    /// callers of a singular system project r and z (as PressureSystemSolver::precondition does).
    void apply(const std::vector<double>& r, std::vector<double>& z) const override;

private:
    struct State;
    std::unique_ptr<State> m_state;
};

/// One-shot convenience: builds a HypreStructSolver and solves (see its solve()).
SolveResult solve_hypre_pfmg_pcg(const PoissonMatrix& matrix, const std::vector<double>& b,
                                 const IterativeSolverOptions& options, bool singular,
                                 std::vector<double>& x);

}  // namespace meniscus::fluid
