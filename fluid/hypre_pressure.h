#pragma once
/// \file The pressure Poisson system solved by hypre (Debian libhypre-dev) through its
/// structured-grid interface: PCG (HYPRE_StructPCG) preconditioned by one PFMG V-cycle
/// (HYPRE_StructPFMG), on one MPI process (MPI_COMM_SELF: no domain decomposition yet).
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
/// Neither MPI nor hypre appears in this header: both are private to meniscus::fluid.

#include <memory>
#include <vector>

#include "fluid/pcg.h"
#include "fluid/poisson_matrix.h"
#include "fluid/solve_result.h"

namespace meniscus::fluid {

/// Initialises MPI (once per process, thread-safe) if nobody has, for a plain run without mpirun,
/// and hypre (HYPRE_Init); registers MPI_Finalize (after HYPRE_Finalize) with std::atexit. When
/// MPI was initialised by someone else it is left to them. Called by HyprePressureSolver; callable
/// directly. Throws std::runtime_error if MPI was already finalised or MPI_Init_thread fails.
/// See hypre_pressure.cpp for what it sets up for a plain run as root and why.
void ensure_mpi_initialized();

/// A PoissonMatrix set up once in hypre (grid, matrix, PFMG hierarchy), then solved for any
/// number of right-hand sides. Keeps no reference to the matrix. All calls into hypre are
/// serialised by one process-wide lock (hypre keeps global state), so objects may be used from
/// any thread, one solve at a time per process.
///
/// As a Preconditioner, apply() is one PFMG V-cycle from a zero guess (symmetric red–black
/// Gauss–Seidel, one sweep before and after, Galerkin coarse operators).
class HyprePressureSolver final : public Preconditioner {
public:
    /// `singular`: A is pure Neumann (null space = the constant over active cells).
    /// Throws std::invalid_argument for an empty matrix, std::runtime_error when hypre fails.
    HyprePressureSolver(const PoissonMatrix& matrix, bool singular);
    ~HyprePressureSolver() override;
    HyprePressureSolver(const HyprePressureSolver&) = delete;
    HyprePressureSolver& operator=(const HyprePressureSolver&) = delete;

    /// Solves A x = b with hypre's PCG + PFMG from x = 0 to the relative residual
    /// ‖b − A x‖₂ / ‖b‖₂ ≤ options.tolerance (hypre's two-norm criterion on its recursively
    /// updated residual, as solve_pcg), at most options.max_iterations. Same conventions as
    /// solve_pcg: b's inactive entries are ignored, x (resized) is zero on inactive cells, the
    /// returned residual is relative to the (projected) b. options.cancel is checked before and
    /// after the solve only (hypre's iterations cannot be interrupted).
    SolveResult solve(const std::vector<double>& b, const IterativeSolverOptions& options,
                      std::vector<double>& x) const;

    /// z = one PFMG V-cycle applied to r (z resized; inactive entries zero). No mean projection:
    /// callers of a singular system project r and z (as PressureSystemSolver::precondition does).
    void apply(const std::vector<double>& r, std::vector<double>& z) const override;

private:
    struct State;
    std::unique_ptr<State> m_state;
};

/// One-shot convenience: builds a HyprePressureSolver and solves (see its solve()).
SolveResult solve_hypre_pfmg_pcg(const PoissonMatrix& matrix, const std::vector<double>& b,
                                 const IterativeSolverOptions& options, bool singular,
                                 std::vector<double>& x);

}  // namespace meniscus::fluid
