#pragma once
/// \file Implicit (backward Euler) viscosity with variable μ, variational form after Batty &
/// Bridson 2008.
///
/// The new face velocities minimise
///   Σ_faces ½ ρ_f (u_f − u*_f)² + Δt Σ_cells μ_c (ε_xx² + ε_yy² + ε_zz²)
///                                 + Δt Σ_edges μ_e · 2 (ε_xy² | ε_xz² | ε_yz²),
/// (all multiplied by the cell volume), i.e. ρ (u − u*)/Δt = ∇·(2 μ ε(u)), ε = ½(∇u + ∇uᵀ). The
/// diagonal strain rates live at cell centres, the shear strain rates on cell edges (ε_xy on
/// z-parallel edges at (i·dx, j·dx, (k+½)·dx), etc.). μ_c is the viscosity of the cell's phase
/// and μ_e that of the phase at the edge's midpoint (ViscosityWeights::pointwise, the default;
/// the other weights below), ρ_f the face density of face_density(). The system is symmetric positive definite and solved matrix-free by conjugate
/// gradients, preconditioned by multigrid V-cycles on each velocity component's own block or by
/// its diagonal (ViscosityOptions::preconditioner), starting from u* (TBB-parallel operator).
///
/// Boundaries: the normal faces of walls and inflows keep their stored value; those of an outflow
/// are unknowns with no strain beyond them (zero normal gradient); across a periodic pair the face
/// at 0 is an unknown between cells n−1 and 0 (the face at n is set to it), and the strain rates
/// at the seam's cells and edges reach across it. On a no-slip wall or an
/// inflow the tangential velocity is mirrored with opposite sign (zero at the face, or the
/// velocity of a moving wall) and the edge terms on that face are weighted by the half of their
/// dual cell inside the box; on a free-slip wall or an outflow (zero normal gradient) the shear
/// stress vanishes, so the edge terms lying on that face are dropped. In free_surface mode only
/// faces next to a liquid cell are unknowns, the gas has μ = 0, and μ_c and μ_e are μ_liquid
/// times the liquid fraction of their control volume (a cube of edge Δx around the cell centre
/// or edge midpoint, clamp(½ − φ/Δx, 0, 1) with φ there; Batty & Bridson 2008), so the surface
/// is traction-free where φ = 0 rather than on the faces of the last liquid cells; other faces
/// these terms touch keep their (extrapolated) velocity. A face the surface crosses has the
/// inertia ρ_l θ (θ its liquid fraction, clamped below by `min_liquid_fraction`), as the
/// pressure's ghost-fluid coefficient 1/(ρ_l θ): the projection's velocity impulse and the
/// viscous solve then see the same face mass, which keeps the coupled step symmetric.

#include <memory>

#include "fluid/boundary.h"
#include "fluid/halo_exchange.h"
#include "fluid/interface_input.h"
#include "fluid/mac_grid.h"
#include "fluid/multigrid.h"
#include "fluid/phases.h"
#include "fluid/solve_result.h"

namespace meniscus::fluid {

/// How μ is weighted next to the two_phase interface.
enum class ViscosityWeights {
    /// μ_c of the cell's phase; μ_e the harmonic mean of the (up to 4) cells around the edge
    /// (zero next to a cell with μ = 0): exact for the shear stress across a layer interface
    /// through the edge, but it gives every edge next to a gas cell the gas's μ, so a bubble in
    /// a viscous liquid is half a cell larger to the liquid (+17 % rise speed at 8 cells per
    /// diameter, +11 % at 12; validate B7).
    sharp,
    /// μ_c and μ_e blended by the liquid fraction V of their control volume (a cube of edge Δx,
    /// V = clamp(½ − φ/Δx, 0, 1) with φ at its centre): μ_g + (μ_l − μ_g) V (Batty & Bridson
    /// 2008's volume-weighted energy).
    volume_fraction,
    /// μ_c and μ_e each the viscosity of the phase at the control volume's centre (φ at an edge:
    /// the mean of its cells). A sharp jump, like `sharp`, but placed where φ changes sign to
    /// within half a cell on either side, with no bias to either phase (B7: +1.3 % at 8 cells
    /// per diameter).
    pointwise
};

/// Preconditioner of the viscous conjugate gradients.
enum class ViscousPreconditioner {
    jacobi,  ///< the operator's diagonal
    /// with semi-implicit tension's surface term: the diagonal plus that term, inverted exactly
    /// (surface_preconditioner.h; without the term, jacobi). Its iterations drop with the
    /// step: bubble_merge at 30 cells and 10× the capillary limit takes 12–15 per solve instead
    /// of 40 (10–20 % less time in the viscous solves: its sparse LU costs most of the rest). At
    /// 3.5× the limit and 128 cells it saves a quarter (10.3 against 13.8), but the LU costs 2.1 s
    /// of CPU a step, more than that saves: not the default.
    jacobi_surface,
    /// one multigrid V-cycle (multigrid.h) on each velocity component's own block of the
    /// operator (its couplings to the other components left out). Pays where the viscous
    /// diffusion number νΔt/Δx² is large, since an iteration costs about 3.5 Jacobi ones: a
    /// bubble in a liquid of μ = 2 Pa·s (νΔt/Δx² = 14 in the liquid, 14000 in the gas) at 48³
    /// takes 187 instead of 988 iterations per step, 1.4× less CPU in the viscous solves (24³:
    /// 138 against 660, the same CPU); an air bubble in water (νΔt/Δx² ≈ 0.1) 12.5 instead of
    /// 17.2 and 2.3× the CPU. Not the default for that reason.
    multigrid,
    /// one hypre PFMG V-cycle (hypre_struct_solver.h: a HYPRE_StructMatrix, symmetric red–black
    /// Gauss–Seidel, Galerkin coarsening) on each velocity component's block, as `multigrid`
    /// but through hypre's Struct interface; the CG around it stays ours, since the whole
    /// operator couples the three components through the shear terms, which hypre's Struct
    /// interface (one variable per grid) cannot hold. The one preconditioner besides jacobi that
    /// runs on several ranks (collective, on each rank's block).
    hypre_pfmg
};

/// Options of the implicit viscosity step.
struct ViscosityOptions {
    bool enabled = true;               ///< false skips the step (inviscid flow)
    IterativeSolverOptions iteration;  ///< CG tolerance and iteration cap
    /// two_phase weights at the interface (free_surface always uses the liquid fraction).
    ViscosityWeights weights = ViscosityWeights::pointwise;
    ViscousPreconditioner preconditioner = ViscousPreconditioner::jacobi;
    MultigridOptions multigrid;  ///< the V-cycle of ViscousPreconditioner::multigrid

    /// Throws std::invalid_argument naming the field when out of range.
    void validate() const;
};

/// Replaces the face velocities of `grid` (u*) by the backward-Euler viscous update over `dt`
/// seconds. Returns the CG outcome (converged with 0 iterations when there is nothing to solve:
/// disabled, or μ = 0 everywhere). Throws std::invalid_argument when `interface` does not fit the
/// grid or dt ≤ 0. Allocates its work arrays on every call; see ViscositySolver to reuse them.
SolveResult apply_viscosity(MacGrid& grid, const InterfaceInput& interface,
                            const PhaseOptions& phases, FluidMode mode, const BoundaryOptions& walls,
                            double dt, const ViscosityOptions& options,
                            double min_liquid_fraction = DEFAULT_MIN_LIQUID_FRACTION);

/// The same solve as apply_viscosity(), keeping its work arrays (operator coefficients, CG
/// vectors) between calls so repeated steps on one grid do not reallocate. Movable, not copyable;
/// one object must not be used from two threads at once.
class ViscositySolver {
public:
    ViscositySolver();
    ~ViscositySolver();
    ViscositySolver(ViscositySolver&&) noexcept;
    ViscositySolver& operator=(ViscositySolver&&) noexcept;

    /// Makes every later solve() collective over `ranks`: the grid it is given is then this
    /// rank's block of a grid split by `decomposition` (grid_block.h; at least 2 ghost layers,
    /// current before the call, filled again after it) and the conjugate gradients run over the
    /// whole grid, each rank owning its slab's faces (jacobi or hypre_pfmg preconditioner, no
    /// surface viscosity). One rank: solve() as without. Throws std::invalid_argument when the
    /// sizes do not fit.
    void distribute(const SlabDecomposition& decomposition, const RankCommunicator& ranks);

    /// See apply_viscosity().
    SolveResult solve(MacGrid& grid, const InterfaceInput& interface, const PhaseOptions& phases,
                      FluidMode mode, const BoundaryOptions& walls, double dt,
                      const ViscosityOptions& options,
                      double min_liquid_fraction = DEFAULT_MIN_LIQUID_FRACTION);

private:
    struct Workspace;
    std::unique_ptr<Workspace> m_workspace;
};

}  // namespace meniscus::fluid
