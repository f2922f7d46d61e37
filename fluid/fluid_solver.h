#pragma once
/// \file One Navier–Stokes step on the MAC grid: advection, gravity, implicit viscosity,
/// ghost-fluid pressure projection (and velocity extrapolation into the void in free-surface mode).
///
/// The solver never sees the interface mesh: each step receives an InterfaceInput (φ at cell
/// centres, negative in the liquid; κ on the faces it crosses; see interface_input.h). All
/// quantities are SI. Each face of the box is a wall (no-slip walls may slide along themselves),
/// an inflow or an outflow (FluidOptions::boundaries, boundary.h).

#include <Eigen/Core>

#include <array>
#include <utility>

#include "common/phase_clock.h"

#include "fluid/advection.h"
#include "fluid/array3.h"
#include "fluid/boundary.h"
#include "fluid/grid_block.h"
#include "fluid/interface_input.h"
#include "fluid/mac_grid.h"
#include "fluid/phases.h"
#include "fluid/pressure.h"
#include "fluid/solve_result.h"
#include "fluid/timestep.h"
#include "fluid/viscosity.h"
#include "fluid/viscous_pressure.h"

namespace meniscus::fluid {

/// Everything the fluid step needs besides the grid size and the interface.
struct FluidOptions {
    PhaseOptions phases;
    FluidMode mode = FluidMode::two_phase;
    Eigen::Vector3d gravity = Eigen::Vector3d(0.0, 0.0, -9.81);  ///< m/s² (z up by default)
    BoundaryOptions boundaries;  ///< the six faces of the box (boundary.h)
    AdvectionOptions advection;
    ViscosityOptions viscosity;
    PressureOptions pressure;
    ViscousPressureOptions viscous_pressure;  ///< how viscosity and pressure are coupled
    TimeStepOptions time_step;
    int extrapolation_layers = 4;  ///< free_surface: face layers filled into the void (≥ 0)

    /// Validates every sub-struct; throws std::invalid_argument naming the field.
    void validate() const;
};

/// Wall-clock and process-CPU seconds of each phase of a step. The coupled scheme's Uzawa
/// passes count their viscous solves as viscosity and their pressure preconditioning as
/// pressure_solve; the step's first hydrostatic start and the previous pressure's gradient count
/// as forces.
struct StepTimings {
    PhaseSeconds advection;
    PhaseSeconds forces;          ///< gravity (and the previous pressure's gradient)
    PhaseSeconds viscosity;       ///< implicit viscous solves
    PhaseSeconds pressure_build;  ///< assembling the pressure systems
    PhaseSeconds pressure_solve;  ///< solving them and applying the gradients
    PhaseSeconds extrapolation;   ///< free_surface: velocity into the void
    PhaseSeconds total;

    /// Adds every phase of `other` (a frame's sum over its steps).
    StepTimings& operator+=(const StepTimings& other) {
        for (auto [mine, theirs] :
             {std::pair{&advection, &other.advection}, {&forces, &other.forces},
              {&viscosity, &other.viscosity}, {&pressure_build, &other.pressure_build},
              {&pressure_solve, &other.pressure_solve}, {&extrapolation, &other.extrapolation},
              {&total, &other.total}})
            *mine += *theirs;
        return *this;
    }
};

/// What a step did.
struct StepResult {
    /// Pressure Poisson solves of the step: converged = every pass's did, iterations summed over
    /// the passes, residual the largest.
    SolveResult pressure;
    SolveResult viscosity;        ///< viscous CG solves, summed likewise (0 iterations: skipped)
    double max_divergence = 0.0;  ///< max |∇·u| over the solved cells after projection, 1/s
    /// coupled: Uzawa–PCG iterations of the step (0 for the other schemes and for inviscid
    /// flow); pass_change: after them (before the final projection), the largest |D u|·Δx over
    /// the velocity scale (the largest face speed, at least |g|Δt), times D/(1 + D) (see
    /// ViscousPressureOptions::pass_tolerance; with local passes: over their region, and each
    /// cell left out by its own estimate, which is at most pass_tolerance); converged_passes: it
    /// met pass_tolerance.
    int passes = 0;
    double pass_change = 0.0;
    bool converged_passes = true;
    /// coupled: the cells the passes ran on (the whole grid's, or those of their region:
    /// ViscousPressureOptions::local_passes); 0 without passes.
    std::size_t pass_cells = 0;
    /// coupled: of viscosity.iterations and pressure.iterations, those of the passes (on
    /// pass_cells cells each; the Cahouet–Chabard preconditioner's V-cycles count one each).
    int pass_viscosity_iterations = 0;
    int pass_pressure_iterations = 0;
    StepTimings timings;
};

/// Two-phase / free-surface incompressible flow solver on a MAC grid.
class FluidSolver {
public:
    /// A solver on nx × ny × nz cells of edge dx (m), min corner `origin` (m), fluid at rest.
    /// Throws std::invalid_argument for invalid sizes or options.
    FluidSolver(int nx, int ny, int nz, double dx, const Eigen::Vector3d& origin,
                const FluidOptions& options);
    /// Collective: rank `ranks.rank()`'s part of a solver on the same whole grid, split by
    /// `decomposition` (its z-layers over ranks.size() ranks, with at least
    /// ghost_layers_needed(options) ghost layers): grid(), pressure() and the interface given to
    /// step() are this rank's block (grid_block.h), and every step is collective. The linear
    /// solves run over the ranks (pressure through hypre whatever options.pressure.solver says;
    /// viscosity by Jacobi-preconditioned CG). Not available on several ranks (throws
    /// std::invalid_argument naming the field): inflow faces on x or y, the viscous multigrid
    /// preconditioner, semi-implicit surface tension. One rank: as the constructor above.
    FluidSolver(int nx, int ny, int nz, double dx, const Eigen::Vector3d& origin,
                const FluidOptions& options, const SlabDecomposition& decomposition,
                const RankCommunicator& ranks);

    /// Ghost layers a distributed step needs: the advection's reach (a corrected scheme traces
    /// back twice, each back-trace up to cfl_number cells plus its interpolation stencil) and
    /// the viscous stencil's two layers.
    static int ghost_layers_needed(const FluidOptions& options);

    /// Advances the velocity by `dt` seconds (> 0) with the interface `interface` (sized for the
    /// grid): advection, then viscosity, gravity and pressure coupled as
    /// FluidOptions::viscous_pressure says (viscous_pressure.h), then extrapolation
    /// (free_surface). Hydrostatic rest is an exact steady state of every scheme. Numerical
    /// non-convergence is reported in the result, not thrown.
    StepResult step(double dt, const InterfaceInput& interface);

    /// The time-step limits for the current velocity (CFL, viscous, capillary); collective on
    /// several ranks (the whole grid's).
    TimeStepLimits time_step_limits() const;
    /// How the grid is split over ranks (one process by default).
    const BlockContext& blocks() const { return m_blocks; }
    /// The whole box: min corner (m), cells per axis, max corner (m); grid() is its block of it
    /// on several ranks, the box itself on one.
    const Eigen::Vector3d& box_min() const { return m_box_min; }
    const std::array<int, 3>& box_cells() const { return m_box_cells; }
    Eigen::Vector3d box_max() const {
        return m_box_min +
               m_grid.dx() * Eigen::Vector3d(m_box_cells[0], m_box_cells[1], m_box_cells[2]);
    }
    /// The boundaries of grid(): options().boundaries, with a block's inner ends as free-slip
    /// walls on several ranks (block_boundaries()).
    const BoundaryOptions& grid_boundaries() const { return m_block_boundaries; }

    /// Collective on several ranks: fills the ghost layers of grid() from their owners, after its
    /// velocities were set from outside (an initial field, a checkpoint).
    void refresh_ghost_layers() { m_blocks.exchange(m_grid); }

    MacGrid& grid() { return m_grid; }
    const MacGrid& grid() const { return m_grid; }
    /// Pressure (Pa) at cell centres from the last step, nx × ny × nz; zero in the void
    /// (free_surface); mean zero when the system is pure Neumann (two_phase). The incremental
    /// and coupled schemes start the next step from it.
    const Array3<double>& pressure() const { return m_pressure; }
    /// Time (s) of the velocities: the sum of the steps taken (a pulsed inflow's phase).
    double time() const { return m_time; }
    const FluidOptions& options() const { return m_options; }

    /// Exact state for checkpoints: the face velocities, the pressure the next step starts
    /// from, its increment and the last step's liquid cells. load_state() needs a solver built
    /// with the same grid and options and throws FormatError on truncated or mismatched data.
    /// On several ranks both are collective and the state is the whole grid's (rank 0's `out`
    /// gets the fields gathered from every rank; every rank loads the whole fields and keeps
    /// its block), in the one-process layout.
    void save_state(BinaryWriter& out) const;
    void load_state(BinaryReader& in);

private:
    /// Viscosity, gravity and projection of the split scheme.
    void split_step(double dt, const InterfaceInput& interface, StepResult& result);
    /// The incremental and coupled schemes.
    void incremental_step(double dt, const InterfaceInput& interface, StepResult& result);

    /// project_block() (project() on one process) with the whole box's `boundaries` and
    /// `options` (default: m_options.pressure).
    ProjectionResult projection(MacGrid& grid, const InterfaceInput& interface,
                                const PhaseOptions& phases, double dt, Array3<double>& pressure,
                                const BoundaryOptions& boundaries,
                                const PressureOptions* options = nullptr) const;

    FluidOptions m_options;
    BlockContext m_blocks;
    /// The boundaries of this rank's block (m_options.boundaries on one process).
    BoundaryOptions m_block_boundaries;
    Eigen::Vector3d m_box_min;
    std::array<int, 3> m_box_cells{};
    MacGrid m_grid;
    Array3<double> m_pressure;
    Array3<double> m_increment;  ///< scratch: the projection's pressure increment δ
    ViscositySolver m_viscosity;
    ViscositySolver m_region_viscosity;  ///< the coupled scheme's passes on a part of the grid
    std::vector<char> m_was_liquid;  ///< liquid flags of the last step's cells (empty at first)
    double m_time = 0.0;
};

}  // namespace meniscus::fluid
