#pragma once
/// \file Pressure projection with the ghost fluid method (Liu, Fedkiw & Kang 2000; Gibou et al.
/// 2002 for the free-surface Dirichlet condition).
///
/// Solves ∇·(1/ρ ∇p) = ∇·u*/Δt on the cells of the MacGrid and sets u = u* − Δt/ρ ∇p on every face
/// between two unknowns, so that the discrete divergence of each unknown cell vanishes.
/// Scaled symmetric positive (semi-)definite system, per unknown cell c:
///   Σ_faces f β_f (p_c − p_nb) = −(dx/Δt) Σ_f (outward u*_f) − Σ_f (±β_f J_f),
/// with β_f = 1/ρ_f (ρ_f from the liquid fraction θ of the face, see face_density()) and J_f the
/// jump p(hi side) − p(lo side) of face_pressure_jump() (p_liquid − p_gas = σκ).
/// Wall and inflow faces of the box are not unknowns: their stored normal velocity is kept (a
/// Neumann condition). An outflow face (boundary.h) is a Dirichlet face with p = its pressure on
/// the face, half a cell from its cell's centre: it adds 2/ρ of the cell's phase to the diagonal
/// and its velocity takes the gradient like an interior face — where its cell holds the face's
/// ambient phase (that of most of the face's cells); where a drop or a bubble is on its way out,
/// the face keeps its zero-gradient velocity (Neumann), so the Laplace pressure inside it is not
/// pinned to the ambient pressure. Across a periodic pair of faces cell n−1 and cell 0 are
/// neighbours through the min face, whose velocity takes the gradient like an interior face's and
/// is copied to the max face (PoissonMatrix::periodic). In free_surface mode only liquid cells
/// are unknowns; a face to a gas cell uses the ghost value that puts p = σκ at the θ-weighted
/// interface position, adding β/θ to the diagonal (θ clamped below by min_liquid_fraction).
/// Pressure in Pa.

#include <memory>
#include <vector>

#include "common/phase_clock.h"
#include "fluid/array3.h"
#include "fluid/boundary.h"
#include "fluid/grid_block.h"
#include "fluid/hypre_struct_solver.h"
#include "fluid/interface_input.h"
#include "fluid/mac_grid.h"
#include "fluid/mic0.h"
#include "fluid/multigrid.h"
#include "fluid/phases.h"
#include "fluid/poisson_matrix.h"
#include "fluid/solve_result.h"

namespace meniscus::fluid {

/// Linear solver used for the pressure Poisson system.
enum class PressureSolver {
    mic0_pcg,       ///< PCG with the MIC(0) preconditioner (sequential preconditioner)
    multigrid_pcg,  ///< PCG with a multigrid V-cycle preconditioner (TBB-parallel)
    eigen_ic_cg,    ///< reference: Eigen ConjugateGradient + IncompleteCholesky on a CSR copy
    /// hypre (libhypre-dev): HYPRE_StructPCG preconditioned by one HYPRE_StructPFMG V-cycle
    /// (fluid/hypre_struct_solver.h; initialises MPI on first use). Always used on several ranks.
    hypre_pfmg_pcg
};

/// Options of the pressure projection.
struct PressureOptions {
    PressureSolver solver = PressureSolver::multigrid_pcg;
    IterativeSolverOptions iteration;     ///< relative residual tolerance and iteration cap
    /// Lower clamp of θ for free-surface ghost faces, (0, 1] (the viscous solve uses the same).
    double min_liquid_fraction = DEFAULT_MIN_LIQUID_FRACTION;
    Mic0Options mic0;
    MultigridOptions multigrid;

    /// Throws std::invalid_argument naming the field when out of range.
    void validate() const;
};

/// The assembled system: matrix over all nx·ny·nz cells (inactive rows zero), right-hand side and
/// whether A is singular (pure Neumann: two_phase in a box without outflow, or free_surface
/// without gas nor outflow).
struct PressureSystem {
    PoissonMatrix matrix;
    std::vector<double> rhs;
    bool singular = false;
};

/// Assembles the pressure system for the current face velocities u* of `grid` (see file comment)
/// in a box with `boundaries` (default: closed by free-slip walls; only the outflow faces matter).
/// `dt` in seconds (> 0). Throws std::invalid_argument if `interface` is not sized for `grid`.
PressureSystem build_pressure_system(const MacGrid& grid, const InterfaceInput& interface,
                                     const PhaseOptions& phases, FluidMode mode, double dt,
                                     const PressureOptions& options,
                                     const BoundaryOptions& boundaries = {});

/// Solves `system` with options.solver; writes the pressure (Pa) to `pressure` (nx × ny × nz,
/// zero in cells that are not unknowns; mean zero when the system is singular).
SolveResult solve_pressure_system(const PressureSystem& system, const PressureOptions& options,
                                  Array3<double>& pressure);

/// Solves one assembled system for several right-hand sides, building its preconditioner once
/// (the coupled scheme's Uzawa passes solve the same system every pass). Keeps a reference to
/// `system`, which must outlive it; same results as solve_pressure_system().
class PressureSystemSolver {
public:
    /// Throws std::invalid_argument naming the field when `options` are out of range.
    PressureSystemSolver(const PressureSystem& system, const PressureOptions& options);
    /// Collective: `system` is this rank's block of the whole system (assembled on its block of
    /// the grid; `singular` as the whole system's) and the solves run over every rank through
    /// hypre (hypre_pfmg_pcg whatever options.solver says); results hold the owned cells, zero in
    /// the ghost layers (BlockContext::exchange() fills them). One process: as above.
    PressureSystemSolver(const PressureSystem& system, const PressureOptions& options,
                         const BlockContext& blocks);
    ~PressureSystemSolver();
    PressureSystemSolver(const PressureSystemSolver&) = delete;
    PressureSystemSolver& operator=(const PressureSystemSolver&) = delete;

    /// Solves A p = rhs (`rhs` sized like the system; its own right-hand side is not used).
    SolveResult solve(const std::vector<double>& rhs, Array3<double>& pressure) const;
    /// p = M⁻¹ rhs, one application of the preconditioner (rhs projected to zero mean first
    /// when the system is singular, p then too): a MIC(0) or multigrid application, one PFMG
    /// V-cycle for hypre_pfmg_pcg (hypre's own preconditioner); a full solve() for eigen_ic_cg,
    /// which has none.
    SolveResult precondition(const std::vector<double>& rhs, Array3<double>& pressure) const;

private:
    const PressureSystem& m_system;
    PressureOptions m_options;
    /// null for eigen_ic_cg; for hypre_pfmg_pcg the HypreStructSolver (one PFMG V-cycle)
    std::unique_ptr<Preconditioner> m_preconditioner;
    const HypreStructSolver* m_hypre = nullptr;    ///< m_preconditioner's, for hypre_pfmg_pcg
    bool m_distributed = false;                    ///< over several ranks (hypre)
};

/// u ← u − Δt/ρ_f ∇p on every face adjacent to an unknown cell (ghost-fluid gradients with the σκ
/// jump; free-surface faces use the interface Dirichlet value σκ, outflow faces their pressure).
/// Wall and inflow faces are untouched.
void apply_pressure_gradient(MacGrid& grid, const InterfaceInput& interface,
                             const PhaseOptions& phases, FluidMode mode, double dt,
                             const PressureOptions& options, const Array3<double>& pressure,
                             const BoundaryOptions& boundaries = {});

/// Largest |∇·u| (1/s) over the unknown cells of the pressure system (all cells in two_phase,
/// liquid cells in free_surface).
double max_fluid_divergence(const MacGrid& grid, const InterfaceInput& interface, FluidMode mode);

/// Result of project().
struct ProjectionResult {
    SolveResult solve;            ///< linear solve outcome
    double max_divergence = 0.0;  ///< max |∇·u| over unknown cells after projection, 1/s
    bool singular = false;        ///< the system was pure Neumann (p only up to a constant)
    PhaseSeconds build_time;      ///< assembling the system
    PhaseSeconds solve_time;      ///< the linear solve and applying the gradient
};

/// Full projection: build, solve, apply the gradient. `pressure` receives p (Pa).
ProjectionResult project(MacGrid& grid, const InterfaceInput& interface, const PhaseOptions& phases,
                         FluidMode mode, double dt, const PressureOptions& options,
                         Array3<double>& pressure, const BoundaryOptions& boundaries = {});

}  // namespace meniscus::fluid
