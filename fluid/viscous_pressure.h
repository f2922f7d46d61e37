#pragma once
/// \file How the implicit viscosity and the pressure projection are coupled within one step.
///
/// The backward-Euler step of the momentum equation with viscosity, gravity and the ghost-fluid
/// pressure is the saddle-point (Stokes-like) problem
///   ρ (u − u_a)/Δt = L u − G_J p + ρ g,   D u = 0,
/// with u_a the advected velocity, L u = ∇·(2μ ε(u)) the variable-μ viscous operator of
/// viscosity.h, G_J the ghost-fluid pressure gradient with the jump [p] = σκ (pressure.h) and D
/// the MAC divergence. Three ways of solving it:
///
/// - `split` (first-order operator splitting): viscosity on u_a alone, then gravity, then the
///   projection. Its steady states are those of L for the *intermediate* velocity, so they move
///   with Δt: u differs from the Stokes solution by (Δt/ρ) L u, a relative error of order the
///   viscous diffusion number μΔt/(ρΔx²) times (Δx/ℓ)², ℓ the flow's length scale; at the
///   capillary Δt of a viscous bubble (μΔt/(ρΔx²) ≈ 3) that made a creeping rise 2.7× too fast.
/// - `incremental` (pressure-increment projection, Goda 1979 / van Kan 1986): gravity and the
///   previous step's pressure gradient G_J p⁽ⁿ⁾ enter the viscous solve; the projection then
///   solves for the increment δ (no jump: it is already in G_J p⁽ⁿ⁾) and p⁽ⁿ⁺¹⁾ = p⁽ⁿ⁾ + δ. A
///   steady state has δ = 0, so it satisfies the discrete Stokes equations exactly, at any Δt.
/// - `coupled`: the incremental step followed by preconditioned conjugate gradients on the
///   pressure Schur complement T = Gᵀ A⁻¹ G (A = ρ/Δt − L, the viscous solve) until the velocity
///   that the viscous solve returns for the current pressure is divergence-free (Uzawa–PCG);
///   the preconditioner is Cahouet & Chabard's T⁻¹ ≈ (Δt Gᵀ ρ⁻¹ G)⁻¹ + 2μ (the pressure Poisson
///   solve plus 2μ_c per cell; 2μ, not μ, for the stress form of L, since L G = 2μ G D G for
///   constant μ), exact for constant coefficients without walls, so few iterations are needed.
///   Each iteration is one viscous and one pressure solve; a last projection makes u
///   divergence-free to the pressure solver's tolerance. The fixed point is the backward-Euler
///   step of viscosity and pressure together. (The rotational correction p ← p + δ − 2μ D u*
///   iterated as a fixed point diverges at the interface of a 1000:1 density and viscosity jump,
///   which is why the coupled scheme is a Krylov method.)
///   The passes' viscous solves stop at a tenth of pass_tolerance (inexact Uzawa). Where the
///   liquid's diffusion number is small (water and air at millimetres), A⁻¹ is ρ/Δt there and the
///   final projection alone gives the coupled step: the passes matter only at the interface and
///   in the gas. With local_passes they run on the box of the cells whose own estimate says so
///   (pass_region()), grown by pass_margin cells, their increments vanishing at its cut faces
///   (box_boundaries()): δ = 0 on the cut face itself, half a cell out, where the whole grid's
///   cell outside keeps its pressure at its centre — the increment at the cut faces is that of a
///   pressure difference 2δ_c instead of δ_c, a mismatch the margin keeps where δ has decayed
///   (δ vanishes at the cut) and that the next step's projection absorbs; the final projection
///   then takes the whole grid. On the bench's bubble
///   pair at 128³ that box holds 14 % of the cells and the step costs half as much.
///
/// Cells that changed phase since the previous step hold the other phase's pressure (off by
/// σκ, and by the void's zero in free_surface mode). Before G_J p⁽ⁿ⁾ is formed they take the
/// mean of their face neighbours that are, and were, in their new phase
/// (carry_pressure_to_new_phase()).

#include <array>
#include <cstddef>
#include <vector>

#include "fluid/array3.h"
#include "fluid/boundary.h"
#include "fluid/interface_input.h"
#include "fluid/mac_grid.h"
#include "fluid/phases.h"
#include "fluid/pressure.h"

namespace meniscus::fluid {

/// Which scheme couples viscosity and pressure (see the file comment).
enum class ViscousPressureCoupling { split, incremental, coupled };

/// Options of the viscosity–pressure coupling.
/// How the coupled scheme's Cahouet–Chabard preconditioner applies the inverse pressure
/// Laplacian A_p⁻¹.
enum class SchurPreconditioner {
    poisson_solve,  ///< a full PCG solve to the pressure tolerance
    /// one multigrid V-cycle (a fixed symmetric operator, so the Uzawa–PCG stays a plain PCG;
    /// other pressure backends fall back to poisson_solve). The default: the passes converge to
    /// the same coupled step in more, much cheaper passes — `validate` B6 and B7 quick give the
    /// same ω, γ and rise speed to 4 digits in 13 s instead of 42 s (B6 at Δt); at 128³ (bubble
    /// pair, 1 thread) the pressure solve costs 2.8 instead of 7.1 µs per cell per step.
    v_cycle
};

struct ViscousPressureOptions {
    ViscousPressureCoupling coupling = ViscousPressureCoupling::coupled;
    SchurPreconditioner preconditioner = SchurPreconditioner::v_cycle;
    /// coupled: the most Uzawa–PCG iterations per step (each one viscous and one pressure
    /// solve; ≥ 1).
    int max_passes = 8;
    /// coupled: stop once the final projection's expected deviation from the coupled velocity —
    /// D/(1 + D) times the largest |D u|·Δx of the viscous solve's velocity, D = νΔt/Δx² of the
    /// more diffusive phase — is at most this fraction of the velocity scale (the largest face
    /// speed, at least |g|Δt) (> 0, < 1). At small D a step needs no pass: the projection
    /// alone is then the coupled step.
    double pass_tolerance = 1.0e-3;
    /// coupled: run the passes on the box of the cells whose own estimate exceeds
    /// pass_tolerance (pass_region()), grown by pass_margin cells, when that box is at most
    /// half the grid (one process, no periodic axis, no inflow or outflow face, explicit
    /// tension); else on the whole grid.
    bool local_passes = true;
    /// cells (0 … 1000). `validate` B6 quick (viscous drop) is within 0.15 % of the whole grid's ω and
    /// γ with 8, 0.55 % off with 4; 0 cuts the flow apart (the step blows up).
    int pass_margin = 8;

    /// Throws std::invalid_argument naming the field when out of range.
    void validate() const;
};

/// A box of cells: indices lo[a] ≤ i < hi[a] on each axis a.
struct CellBox {
    std::array<int, 3> lo{};
    std::array<int, 3> hi{};

    int cells(int axis) const {
        return hi[static_cast<std::size_t>(axis)] - lo[static_cast<std::size_t>(axis)];
    }
    std::size_t size() const;
    bool empty() const { return size() == 0; }
    bool operator==(const CellBox& other) const { return lo == other.lo && hi == other.hi; }
    /// The box of every cell of `cells`.
    static CellBox whole(const Array3<double>& cells);
};

/// The ni × nj × nk values of `whole` from index `lo` on (a box of cells, or of the faces of
/// one axis). Throws std::invalid_argument when they are not inside `whole`.
Array3<double> part_at(const Array3<double>& whole, const std::array<int, 3>& lo, int ni, int nj,
                       int nk);

/// whole(lo + (i, j, k)) += alpha · part(i, j, k) over `part`. Throws std::invalid_argument when
/// `part` does not fit inside `whole` from `lo`.
void add_part_at(Array3<double>& whole, const std::array<int, 3>& lo, double alpha,
                 const Array3<double>& part);

/// Where the coupled scheme's passes are needed (pass_region()).
struct PassRegion {
    CellBox box;  ///< empty when no cell needs passes
    /// The largest own estimate among the cells that do not need them (≤ the tolerance).
    double settled = 0.0;
};

/// Where the coupled scheme's passes are needed: the bounding box, grown by `margin` cells and
/// clipped to the grid, of the unknown cells whose own estimate of how far the projection alone
/// would leave the coupled velocity, D_c/(1 + D_c) |r_c| Δx / speed, exceeds `tolerance` —
/// D_c = ν_c Δt/Δx² with ν_c the largest kinematic viscosity μ/ρ of the phases of the cell and
/// its face neighbours (free_surface: the liquid's), r the negative divergence of the velocity
/// the viscous solve returned (1/s). In a liquid of small diffusion number that is the interface
/// and the gas, not the bulk. Throws std::invalid_argument when the sizes differ, speed or
/// tolerance is not > 0 or margin is negative.
PassRegion pass_region(const std::vector<double>& r, const Array3<double>& phi,
                       const PhaseOptions& phases, FluidMode mode, double dt, double dx,
                       double speed, double tolerance, int margin);

/// The interface on the cells of `box` (its φ and the κ of its faces), for a grid of the box's
/// cells. Throws std::invalid_argument when the box is empty or not inside the arrays.
InterfaceInput interface_in_box(const InterfaceInput& interface, const CellBox& box);

/// The boundaries of a sub-box of a grid of `cells` cells per axis: where the box reaches the
/// grid's own face it keeps `whole`'s condition there, and every face that cuts through the fluid
/// is an outflow at zero pressure (an increment solved in the box vanishes at its edge and the
/// velocity there is free).
BoundaryOptions box_boundaries(const BoundaryOptions& whole, const CellBox& box,
                               const std::array<int, 3>& cells);

/// Liquid flags (1 where φ < 0) of every cell, in the Array3 layout of `phi`.
std::vector<char> liquid_cells(const Array3<double>& phi);

/// Gives every cell whose phase differs between `was_liquid` and the level set of `interface`
/// the mean pressure of its face neighbours that are in its new phase and were in it before.
/// Without such a neighbour: two_phase adds ±σκ (κ of a crossed face of the cell) to its old
/// value; free_surface gives a new liquid cell σκ of a crossed face (0 without one) and a new gas
/// cell 0. Does nothing when `was_liquid` is empty (the first step). Throws
/// std::invalid_argument when the sizes do not match.
void carry_pressure_to_new_phase(const std::vector<char>& was_liquid,
                                 const InterfaceInput& interface, const PhaseOptions& phases,
                                 FluidMode mode, Array3<double>& pressure);

/// Cahouet–Chabard's preconditioner of the coupled scheme for a residual r (the negative
/// velocity divergence per cell, 1/s): z = A_p⁻¹ (Δx²/Δt) r + 2 μ_c r on the unknown cells,
/// with A_p the pressure system's matrix (build_pressure_system()) for the same interface and
/// time step, applied by `solver` (built on `system`) as `how` says; z has zero mean over the
/// unknowns when the system is singular. Pa. Returns the Poisson solve's outcome (a V-cycle:
/// converged, 1 iteration, residual 0). Distributed (`blocks`; `solver` built with them): the
/// mean is taken over every rank's owned cells, and z is valid on the owned cells only.
SolveResult apply_cahouet_chabard(const PressureSystem& system, const PressureSystemSolver& solver,
                                  SchurPreconditioner how, const InterfaceInput& interface,
                                  const PhaseOptions& phases, FluidMode mode, double dt, double dx,
                                  const std::vector<double>& r, std::vector<double>& z,
                                  const BlockContext& blocks = {});

/// The divergence (1/s) of every unknown cell of the pressure system (all cells in two_phase,
/// liquid cells in free_surface), 0 elsewhere, in the Array3 layout of the cells.
std::vector<double> unknown_divergence(const MacGrid& grid, const InterfaceInput& interface,
                                       FluidMode mode);

/// Largest |a − b| over the face velocities of two grids of the same size (m/s).
double max_velocity_difference(const MacGrid& a, const MacGrid& b);

}  // namespace meniscus::fluid
