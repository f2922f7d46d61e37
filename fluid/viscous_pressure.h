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
///
/// Cells that changed phase since the previous step hold the other phase's pressure (off by
/// σκ, and by the void's zero in free_surface mode). Before G_J p⁽ⁿ⁾ is formed they take the
/// mean of their face neighbours that are, and were, in their new phase
/// (carry_pressure_to_new_phase()).

#include <vector>

#include "fluid/array3.h"
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

    /// Throws std::invalid_argument naming the field when out of range.
    void validate() const;
};

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
