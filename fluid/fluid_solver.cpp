#include "fluid/fluid_solver.h"

#include "fluid/surface_viscosity.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "fluid/distributed_projection.h"
#include "fluid/extrapolation.h"
#include "fluid/forces.h"

namespace meniscus::fluid {

namespace {

const FluidOptions& validated(const FluidOptions& options) {
    options.validate();
    return options;
}

/// Coupled scheme: a velocity of this many cells per step counts as rest when the divergence
/// left by the viscous solve is measured against the flow's speed.
constexpr double RESTING_CELLS_PER_STEP = 1e-12;

/// Coupled scheme: the passes run on the box of the cells that need them while it holds at most
/// this share of the grid (beyond, the whole grid's kernels cost no more).
constexpr double MAX_PASS_REGION_SHARE = 0.5;

/// Coupled scheme: the viscous solves of the passes stop at this share of pass_tolerance
/// (or at the viscosity's own tolerance when that is looser).
constexpr double INNER_TOLERANCE_SHARE = 0.1;

/// Coupled scheme: the final projection's relative tolerance, scaled to the divergence before
/// the passes, is kept at most this (the scale can be large when the passes converged far).
constexpr double MAX_FINAL_PROJECTION_TOLERANCE = 0.5;

/// Subtracts the mean over the pressure system's unknown cells (all cells in two_phase, liquid
/// cells in free_surface) from `pressure` on those cells (every cell of the block: the mean is a
/// constant).
void remove_unknown_mean(const InterfaceInput& interface, FluidMode mode,
                         const BlockContext& blocks, Array3<double>& pressure) {
    // On several ranks: the whole grid's mean, over the cells each rank owns.
    const std::size_t layer =
        static_cast<std::size_t>(pressure.ni()) * static_cast<std::size_t>(pressure.nj());
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t c = blocks.owned_cells_begin(layer); c < blocks.owned_cells_end(layer); ++c)
        if (mode == FluidMode::two_phase || is_liquid(interface.phi[c])) {
            sum += pressure[c];
            ++count;
        }
    if (blocks.distributed()) {
        sum = blocks.sum(sum);
        count = static_cast<std::size_t>(blocks.sum(static_cast<double>(count)));
    }
    if (count == 0)
        return;
    const double mean = sum / static_cast<double>(count);
    for (std::size_t c = 0; c < pressure.size(); ++c)
        if (mode == FluidMode::two_phase || is_liquid(interface.phi[c]))
            pressure[c] -= mean;
}

}  // namespace

void FluidOptions::validate() const {
    phases.validate();
    if (mode != FluidMode::two_phase && mode != FluidMode::free_surface) {
        throw std::invalid_argument("FluidOptions.mode: unknown mode");
    }
    if (!gravity.allFinite()) {
        throw std::invalid_argument("FluidOptions.gravity must be finite (m/s^2)");
    }
    try {
        boundaries.validate();
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("boundaries/") + e.what());
    }
    advection.validate();
    viscosity.validate();
    pressure.validate();
    time_step.validate();
    viscous_pressure.validate();
    if (extrapolation_layers < 0) {
        throw std::invalid_argument("FluidOptions.extrapolation_layers must be non-negative");
    }
}

FluidSolver::FluidSolver(int nx, int ny, int nz, double dx, const Eigen::Vector3d& origin,
                         const FluidOptions& options)
    : FluidSolver(nx, ny, nz, dx, origin, options, SlabDecomposition(std::max(nz, 1)),
                  RankCommunicator::self()) {}

int FluidSolver::ghost_layers_needed(const FluidOptions& options) {
    // Each advection reads up to cfl_number cells back plus its interpolation stencil; MacCormack
    // advects twice, BFECC three times, each from the previous one's result.
    const int reach = static_cast<int>(std::ceil(options.time_step.cfl_number)) + 1;
    const int traces = options.advection.scheme == AdvectionScheme::semi_lagrangian ? 1
                       : options.advection.scheme == AdvectionScheme::maccormack    ? 2
                                                                                    : 3;
    int layers = std::max(traces * reach + 1, 2);  // 2: the viscous stencil (cell and edge)
    // Free surface: each extrapolation pass moves the wrong values at a block's end one layer in.
    if (options.mode == FluidMode::free_surface)
        layers = std::max(layers, options.extrapolation_layers + 1);
    return layers;
}

FluidSolver::FluidSolver(int nx, int ny, int nz, double dx, const Eigen::Vector3d& origin,
                         const FluidOptions& options, const SlabDecomposition& decomposition,
                         const RankCommunicator& ranks)
    : m_options(validated(options)),
      m_blocks(decomposition, ranks),
      m_block_boundaries(block_boundaries(options.boundaries, decomposition, ranks.rank())),
      m_box_min(origin),
      m_box_cells{nx, ny, nz},
      m_grid(nx, ny, nz >= 1 ? decomposition.local_layers(ranks.rank()) : nz, dx,
             origin + Eigen::Vector3d(0.0, 0.0, dx * decomposition.local_begin(ranks.rank()))),
      m_pressure(nx, ny, m_grid.nz(), 0.0) {
    const BoundaryOptions& b = m_options.boundaries;
    if (decomposition.layers() != nz)
        throw std::invalid_argument("FluidSolver: the decomposition splits " +
                                    std::to_string(decomposition.layers()) +
                                    " z-layers, the grid has " + std::to_string(nz));
    if (decomposition.distributed()) {
        if (m_options.pressure.iteration.cancel.can_be_requested() ||
            m_options.viscosity.iteration.cancel.can_be_requested())
            throw std::invalid_argument(
                "FluidSolver: the solves cannot be cancelled on several ranks (a rank leaving a "
                "solve alone would leave the others waiting); stop between steps instead");
        if (decomposition.periodic() != b.periodic(2))
            throw std::invalid_argument(
                "FluidSolver: the decomposition and boundaries/z disagree on a periodic z");
        if (decomposition.ghost_layers() < ghost_layers_needed(m_options))
            throw std::invalid_argument(
                "FluidSolver: " + std::to_string(decomposition.ghost_layers()) +
                " ghost layers, the step needs " + std::to_string(ghost_layers_needed(m_options)));
        for (int axis = 0; axis < 2; ++axis)
            for (int side = 0; side < 2; ++side)
                if (b.at(axis, side) == BoundaryType::inflow)
                    throw std::invalid_argument(
                        std::string("boundaries/") + (axis == 0 ? "x" : "y") +
                        (side == 0 ? "_min" : "_max") +
                        ": inflow faces on x or y are not available on several ranks (their "
                        "profile spans z, which the ranks split); put the inflow on a z face");
        if (m_options.viscosity.preconditioner == ViscousPreconditioner::multigrid)
            throw std::invalid_argument(
                "viscosity/viscosity_preconditioner: multigrid is not available on several ranks "
                "(jacobi or hypre_pfmg are)");
        m_viscosity.distribute(decomposition, ranks);
    }
    m_grid.set_periodic(
        {b.periodic(0), b.periodic(1), b.periodic(2) && !decomposition.distributed()});
    apply_boundary_velocity(m_grid, m_block_boundaries);
    m_blocks.exchange(m_grid);
}

ProjectionResult FluidSolver::projection(MacGrid& grid, const InterfaceInput& interface,
                                         const PhaseOptions& phases, double dt,
                                         Array3<double>& pressure,
                                         const BoundaryOptions& boundaries,
                                         const PressureOptions* options) const {
    return project_block(grid, interface, phases, m_options.mode, dt,
                         options ? *options : m_options.pressure, pressure, boundaries,
                         m_blocks.decomposition(), m_blocks.ranks());
}

StepResult FluidSolver::step(double dt, const InterfaceInput& interface) {
    if (!(dt > 0.0)) {
        throw std::invalid_argument("FluidSolver::step: dt must be positive (s)");
    }
    interface.validate(m_grid);
    const Periodicity& periodic = m_grid.periodic();
    if ((periodic[0] || periodic[1] || periodic[2]) && interface.surface_viscosity)
        throw std::invalid_argument(
            "FluidSolver::step: semi-implicit surface tension (a viscous solve) is not available "
            "with periodic faces yet");
    if (m_blocks.distributed() && interface.surface_viscosity)
        throw std::invalid_argument(
            "FluidSolver::step: semi-implicit surface tension is not available on several ranks");
    StepResult result;
    PhaseClock step_clock;
    PhaseClock clock;
    // On several ranks each phase runs on the rank's block and its ghost layers are refreshed
    // from their owners where the next phase reads them (grid_block.h).
    advect_velocity(m_grid, dt, m_options.advection, &m_block_boundaries);
    m_time += dt;  // the step's velocities are those of its end
    apply_boundary_velocity(m_grid, m_block_boundaries, m_time);
    m_blocks.exchange(m_grid);
    clock.lap_into(result.timings.advection);

    if (m_options.viscous_pressure.coupling == ViscousPressureCoupling::split) {
        split_step(dt, interface, result);
    } else {
        incremental_step(dt, interface, result);
    }

    if (m_options.mode == FluidMode::free_surface) {
        clock = PhaseClock();
        extrapolate_velocity(m_grid, interface, m_options.extrapolation_layers);
        m_blocks.exchange(m_grid);
        clock.lap_into(result.timings.extrapolation);
    }
    m_was_liquid = liquid_cells(interface.phi);
    step_clock.lap_into(result.timings.total);
    return result;
}

void FluidSolver::split_step(double dt, const InterfaceInput& interface, StepResult& result) {
    // Viscosity before gravity: the body force is then balanced by the pressure of the same
    // projection, so a fluid at rest in hydrostatic equilibrium stays exactly at rest.
    PhaseClock clock;
    result.viscosity =
        m_viscosity.solve(m_grid, interface, m_options.phases, m_options.mode, m_block_boundaries,
                          dt, m_options.viscosity, m_options.pressure.min_liquid_fraction);
    clock.lap_into(result.timings.viscosity);

    apply_gravity(m_grid, m_options.gravity, dt, m_block_boundaries);
    m_blocks.exchange(m_grid);
    clock.lap_into(result.timings.forces);

    const ProjectionResult projected =
        projection(m_grid, interface, m_options.phases, dt, m_pressure, m_options.boundaries);
    result.pressure = projected.solve;
    result.max_divergence = projected.max_divergence;
    result.timings.pressure_build += projected.build_time;
    result.timings.pressure_solve += projected.solve_time;
}

void FluidSolver::incremental_step(double dt, const InterfaceInput& interface, StepResult& result) {
    const PhaseOptions& phases = m_options.phases;
    const FluidMode mode = m_options.mode;
    const ViscousPressureOptions& scheme = m_options.viscous_pressure;
    const SurfaceViscosity* surface = interface.surface_viscosity.get();
    // The whole box's boundaries (for the projections) and this rank's block's (for the rest).
    const BoundaryOptions& whole_boundaries = m_options.boundaries;
    const BoundaryOptions& boundaries = m_block_boundaries;
    // The increments are homogeneous: walls at rest, inflows still, outflows at zero pressure.
    const BoundaryOptions increment_boundaries = boundaries.at_rest();
    const BoundaryOptions whole_increment_boundaries = whole_boundaries.at_rest();
    const std::size_t layer =
        static_cast<std::size_t>(m_grid.nx()) * static_cast<std::size_t>(m_grid.ny());
    const bool implicit_tension = surface && surface->active();
    const bool viscous =
        (m_options.viscosity.enabled &&
         (phases.mu_liquid > 0.0 || (mode == FluidMode::two_phase && phases.mu_gas > 0.0))) ||
        implicit_tension;
    // Without viscosity the projection alone already is the coupled step.
    const int max_iterations =
        scheme.coupling == ViscousPressureCoupling::coupled && viscous ? scheme.max_passes : 0;
    // The increment carries no jump: G_J p⁽ⁿ⁾ already holds it (and the free-surface value σκ).
    PhaseOptions increment_phases = phases;
    increment_phases.sigma = 0.0;
    const auto add_solve = [](SolveResult& total, const SolveResult& one) {
        total.converged = total.converged && one.converged;
        total.iterations += one.iterations;
        total.residual = std::max(total.residual, one.residual);
    };
    result.viscosity.converged = true;
    result.pressure.converged = true;

    // Momentum with the previous pressure: u = A⁻¹(ρ/Δt u_a + ρ g − G_J p⁽ⁿ⁾).
    PhaseClock clock;
    if (m_was_liquid.empty()) {
        // No previous pressure: start from the one that balances the body force and the jump
        // (hydrostatic plus Laplace), so that rest is exact from the first step.
        MacGrid body(m_grid.nx(), m_grid.ny(), m_grid.nz(), m_grid.dx(), m_grid.origin());
        body.set_periodic(m_grid.periodic());
        apply_gravity(body, m_options.gravity, dt, boundaries);
        m_blocks.exchange(body);
        add_solve(result.pressure,
                  projection(body, interface, phases, dt, m_pressure, whole_boundaries).solve);
    }
    carry_pressure_to_new_phase(m_was_liquid, interface, phases, mode, m_pressure);
    m_blocks.exchange(m_pressure);
    apply_gravity(m_grid, m_options.gravity, dt, boundaries);
    apply_pressure_gradient(m_grid, interface, phases, mode, dt, m_options.pressure, m_pressure,
                            boundaries);
    if (mode == FluidMode::free_surface) {
        // Gas faces took the body force but no pressure: give them the liquid's velocity again,
        // or the viscous solve would drag the liquid along with them (rest would not be exact).
        extrapolate_velocity(m_grid, interface, m_options.extrapolation_layers);
    }
    m_blocks.exchange(m_grid);
    clock.lap_into(result.timings.forces);
    add_solve(result.viscosity,
              m_viscosity.solve(m_grid, interface, phases, mode, boundaries, dt,
                                m_options.viscosity, m_options.pressure.min_liquid_fraction));
    clock.lap_into(result.timings.viscosity);

    // ‖D u‖ before the passes (zero when none run).
    double divergence_before = 0.0;
    if (max_iterations > 0) {
        // Uzawa–PCG on T δ = −D u, T = Gᵀ A⁻¹ G: u ← u + V(δ) with V(δ) = −A⁻¹ G δ the viscous
        // solve of the velocity impulse −Δt/ρ G δ, so the residual is always −D u.
        const double dx = m_grid.dx();
        std::vector<double> r = unknown_divergence(m_grid, interface, mode);
        for (double& x : r)
            x = -x;
        divergence_before = std::sqrt(m_blocks.dot_cells(r, r, layer));
        // The velocity scale: the flow's, the body force's over the step, or (at rest without
        // gravity) a displacement of RESTING_CELLS_PER_STEP cells per step.
        const double velocity_floor =
            std::max(m_options.gravity.norm() * dt, RESTING_CELLS_PER_STEP * dx / dt);
        // The final projection removes what divergence the passes leave; it then differs from
        // the coupled velocity by the viscous part of A⁻¹, about D/(1 + D) of its own change
        // (D = νΔt/Δx², the larger phase's). The passes stop once that estimate is small.
        double nu = phases.mu_liquid / phases.rho_liquid;
        if (mode == FluidMode::two_phase)
            nu = std::max(nu, phases.mu_gas / phases.rho_gas);
        if (!m_options.viscosity.enabled)
            nu = 0.0;
        double diffusion = nu * dt / (dx * dx);
        if (implicit_tension) {
            // The surface viscosity μ_s spread over a cell, a bulk μ_s/Δx, at the mean density.
            const double rho_mean = mode == FluidMode::two_phase
                                        ? 0.5 * (phases.rho_liquid + phases.rho_gas)
                                        : phases.rho_liquid;
            diffusion = std::max(diffusion, surface->viscosity * dt / (rho_mean * dx * dx * dx));
        }
        const double viscous_share = diffusion / (1.0 + diffusion);
        const auto velocity_scale = [&]() {
            return std::max(m_blocks.max(m_grid.max_abs_velocity().maxCoeff()), velocity_floor);
        };
        double settled = 0.0;  // with local passes: the largest estimate of the cells left out
        // The estimate over the cells of r (the whole block's, or the passes' region's).
        const auto divergence_ratio = [&](const BlockContext& blocks, std::size_t cells_layer,
                                          double speed) {
            return std::max(viscous_share * blocks.max_abs_cells(r, cells_layer) * dx / speed,
                            settled);
        };
        const double start_speed = velocity_scale();
        result.pass_change = divergence_ratio(m_blocks, layer, start_speed);
        result.converged_passes = result.pass_change <= scheme.pass_tolerance;
        // The passes run on the box of the cells that need them (the interface and the gas of a
        // water-air flow), their increments vanishing at its cut faces; the final projection
        // below takes the whole box's divergence. One process, no periodic axis, no implicit
        // tension (its term lives on the whole grid): else, and when that box is most of the
        // grid, on the whole grid.
        CellBox region = CellBox::whole(m_pressure);
        // (An open face's ambient phase is decided over the whole face: no box reaches one.)
        if (!result.converged_passes && scheme.local_passes && !m_blocks.distributed() &&
            !implicit_tension && !m_grid.periodic()[0] && !m_grid.periodic()[1] &&
            !m_grid.periodic()[2] && !whole_boundaries.open() && !whole_boundaries.inflow()) {
            const PassRegion needed =
                pass_region(r, interface.phi, phases, mode, dt, dx, start_speed,
                            scheme.pass_tolerance, scheme.pass_margin);
            if (needed.box.empty()) {
                result.converged_passes = true;
                result.pass_change = needed.settled;
            } else if (static_cast<double>(needed.box.size()) <=
                       MAX_PASS_REGION_SHARE * static_cast<double>(region.size())) {
                region = needed.box;
                settled = needed.settled;
            }
        }
        const bool local = !(region == CellBox::whole(m_pressure));
        if (!result.converged_passes)
            result.pass_cells =
                local ? region.size()
                      : static_cast<std::size_t>(m_box_cells[0]) * m_box_cells[1] * m_box_cells[2];
        // The pass problem: the whole block's, or the region's copy.
        InterfaceInput region_interface;
        BoundaryOptions region_boundaries;
        const BlockContext one_box;
        if (local) {
            region_interface = interface_in_box(interface, region);
            region_boundaries = box_boundaries(whole_increment_boundaries, region, m_box_cells);
            Array3<double> whole_r(m_pressure.ni(), m_pressure.nj(), m_pressure.nk());
            whole_r.storage() = std::move(r);
            r = std::move(
                part_at(whole_r, region.lo, region.cells(0), region.cells(1), region.cells(2))
                    .storage());
        }
        const InterfaceInput& pass_interface = local ? region_interface : interface;
        const BoundaryOptions& pass_boundaries = local ? region_boundaries : increment_boundaries;
        const BlockContext& pass_blocks = local ? one_box : m_blocks;
        ViscositySolver& pass_viscosity = local ? m_region_viscosity : m_viscosity;
        const std::size_t pass_layer =
            local ? static_cast<std::size_t>(region.cells(0)) * region.cells(1) : layer;
        const Eigen::Vector3d pass_origin =
            m_grid.origin() + dx * Eigen::Vector3d(region.lo[0], region.lo[1], region.lo[2]);
        PressureSystem system;
        std::unique_ptr<PressureSystemSolver> poisson;  // its preconditioner serves every pass
        std::vector<double> z, q;
        Array3<double> direction;
        MacGrid impulse(1, 1, 1, dx);
        double rz = 0.0;
        if (!result.converged_passes) {
            impulse =
                local ? MacGrid(region.cells(0), region.cells(1), region.cells(2), dx, pass_origin)
                      : MacGrid(m_grid.nx(), m_grid.ny(), m_grid.nz(), dx, m_grid.origin());
            if (!local)
                impulse.set_periodic(m_grid.periodic());
            clock.lap_into(result.timings.pressure_solve);
            system =
                build_pressure_system(local ? impulse : m_grid, pass_interface, increment_phases,
                                      mode, dt, m_options.pressure, pass_boundaries);
            system.singular = pass_blocks.all(system.singular);  // the whole system's
            clock.lap_into(result.timings.pressure_build);
            poisson =
                std::make_unique<PressureSystemSolver>(system, m_options.pressure, pass_blocks);
            const SolveResult preconditioned =
                apply_cahouet_chabard(system, *poisson, scheme.preconditioner, pass_interface,
                                      phases, mode, dt, dx, r, z, pass_blocks);
            add_solve(result.pressure, preconditioned);
            result.pass_pressure_iterations += preconditioned.iterations;
            direction.resize(impulse.nx(), impulse.ny(), impulse.nz(), 0.0);
            direction.storage() = z;
            pass_blocks.exchange(direction);
            rz = pass_blocks.dot_cells(r, z, pass_layer);
        }
        // The inner viscous solves need only be an order of magnitude more accurate than the
        // passes aim for (inexact Uzawa): B6 and B7 quick give the same ω, γ and rise speed to
        // 4 digits, with 30 % fewer viscous CG iterations.
        ViscosityOptions pass_viscosity_options = m_options.viscosity;
        pass_viscosity_options.iteration.tolerance =
            std::max(pass_viscosity_options.iteration.tolerance,
                     INNER_TOLERANCE_SHARE * scheme.pass_tolerance);
        clock.lap_into(result.timings.pressure_solve);
        for (int iteration = 0; iteration < max_iterations && !result.converged_passes;
             ++iteration) {
            for (int axis = 0; axis < 3; ++axis)
                impulse.velocity(axis).fill(0.0);
            apply_pressure_gradient(impulse, pass_interface, increment_phases, mode, dt,
                                    m_options.pressure, direction, pass_boundaries);
            pass_blocks.exchange(impulse);
            const SolveResult pass_solve = pass_viscosity.solve(
                impulse, pass_interface, phases, mode, pass_boundaries, dt, pass_viscosity_options,
                m_options.pressure.min_liquid_fraction);
            add_solve(result.viscosity, pass_solve);
            result.pass_viscosity_iterations += pass_solve.iterations;
            clock.lap_into(result.timings.viscosity);
            q = unknown_divergence(impulse, pass_interface, mode);  // T s
            const double curvature = pass_blocks.dot_cells(direction.storage(), q, pass_layer);
            if (!(curvature > 0.0)) {
                // Breakdown (inexact inner solves): the projection below still applies.
                clock.lap_into(result.timings.pressure_solve);
                break;
            }
            const double alpha = rz / curvature;
            for (int axis = 0; axis < 3; ++axis)
                add_part_at(m_grid.velocity(axis), region.lo, alpha, impulse.velocity(axis));
            add_part_at(m_pressure, region.lo, alpha, direction);
            for (std::size_t c = 0; c < r.size(); ++c)
                r[c] -= alpha * q[c];
            ++result.passes;
            result.pass_change = divergence_ratio(pass_blocks, pass_layer, velocity_scale());
            result.converged_passes = result.pass_change <= scheme.pass_tolerance;
            if (!result.converged_passes) {
                const SolveResult again =
                    apply_cahouet_chabard(system, *poisson, scheme.preconditioner, pass_interface,
                                          phases, mode, dt, dx, r, z, pass_blocks);
                add_solve(result.pressure, again);
                result.pass_pressure_iterations += again.iterations;
                const double rz_new = pass_blocks.dot_cells(r, z, pass_layer);
                const double beta = rz_new / rz;
                rz = rz_new;
                for (std::size_t c = 0; c < r.size(); ++c)
                    direction[c] = z[c] + beta * direction[c];
                pass_blocks.exchange(direction);
            }
            clock.lap_into(result.timings.pressure_solve);
        }
    }

    // The projection of what is left: u divergence-free to the pressure solver's tolerance.
    // After passes its tolerance is relative to the divergence before them: the step's velocity
    // then is as divergence-free as the incremental scheme's (whose projection solves that
    // divergence to the tolerance), not the passes' residual solved a second time over.
    clock = PhaseClock();
    PressureOptions final_options = m_options.pressure;
    if (result.passes > 0 && divergence_before > 0.0) {
        const std::vector<double> left = unknown_divergence(m_grid, interface, mode);
        const double divergence_after = std::sqrt(m_blocks.dot_cells(left, left, layer));
        if (divergence_after > 0.0 && divergence_after < divergence_before)
            final_options.iteration.tolerance =
                std::min(MAX_FINAL_PROJECTION_TOLERANCE,
                         final_options.iteration.tolerance * divergence_before / divergence_after);
    }
    clock.lap_into(result.timings.pressure_solve);
    const ProjectionResult projected =
        projection(m_grid, interface, increment_phases, dt, m_increment, whole_increment_boundaries,
                   &final_options);
    for (std::size_t c = 0; c < m_pressure.size(); ++c)
        m_pressure[c] += m_increment[c];
    if (projected.singular)
        remove_unknown_mean(interface, mode, m_blocks, m_pressure);
    add_solve(result.pressure, projected.solve);
    result.max_divergence = projected.max_divergence;
    // The block's time less the assembly is solving.
    PhaseSeconds solving = clock.lap();
    solving -= projected.build_time;
    result.timings.pressure_build += projected.build_time;
    result.timings.pressure_solve += solving;
}

TimeStepLimits FluidSolver::time_step_limits() const {
    if (!m_blocks.distributed())
        return compute_time_step(m_grid, m_options.phases, m_options.mode, m_options.time_step);
    // The whole grid's limits come from its largest |u|, |v|, |w| (a block holds copies of its
    // neighbours' faces, never other values): the same computation on a one-cell grid holding
    // them (the other limits depend on Δx and the phases only).
    const Eigen::Vector3d largest = m_grid.max_abs_velocity();
    MacGrid probe(1, 1, 1, m_grid.dx());
    for (int a = 0; a < 3; ++a)
        probe.velocity(a).fill(m_blocks.max(largest[a]));
    return compute_time_step(probe, m_options.phases, m_options.mode, m_options.time_step);
}

namespace {

LayerKind velocity_layers(int axis) {
    return axis == 2 ? LayerKind::z_faces : LayerKind::cells;
}

/// Liquid flags as a cell field (a distributed run gathers and splits fields of doubles).
Array3<double> flags_field(const std::vector<char>& flags, const Array3<double>& shape) {
    Array3<double> field(shape.ni(), shape.nj(), shape.nk(), 0.0);
    for (std::size_t c = 0; c < flags.size() && c < field.size(); ++c)
        field[c] = flags[c] ? 1.0 : 0.0;
    return field;
}

std::vector<char> field_flags(const Array3<double>& field) {
    std::vector<char> flags(field.size());
    for (std::size_t c = 0; c < field.size(); ++c)
        flags[c] = field[c] != 0.0 ? 1 : 0;
    return flags;
}

}  // namespace

// On several ranks both are collective and the state is the whole grid's, in the one-process
// layout: rank 0 writes the arrays gathered from every rank's owned layers, and each rank loads
// the whole arrays and keeps its block. A checkpoint so resumes on any number of ranks.
void FluidSolver::save_state(BinaryWriter& out) const {
    // The whole field (gathered on several ranks; one process writes its own without a copy).
    const auto save_whole = [&](const Array3<double>& block, LayerKind kind) {
        if (m_blocks.distributed())
            save_array(out, m_blocks.gather_whole(block, kind));
        else
            save_array(out, block);
    };
    for (int axis = 0; axis < 3; ++axis)
        save_whole(m_grid.velocity(axis), velocity_layers(axis));
    save_whole(m_pressure, LayerKind::cells);
    out.put<std::uint8_t>(m_increment.size() > 0 ? 1 : 0);
    if (m_increment.size() > 0)
        save_whole(m_increment, LayerKind::cells);
    if (m_blocks.distributed() && !m_was_liquid.empty())
        out.put_vector(field_flags(
            m_blocks.gather_whole(flags_field(m_was_liquid, m_pressure), LayerKind::cells)));
    else
        out.put_vector(m_was_liquid);
    out.put(m_time);
}

void FluidSolver::load_state(BinaryReader& in) {
    const bool distributed = m_blocks.distributed();
    // Reads an array shaped like `block` (its block) or, distributed, like the whole field, and
    // returns this rank's block of it.
    const auto load_block = [&](const Array3<double>& block, LayerKind kind, const char* what) {
        Array3<double> a(block.ni(), block.nj(),
                         distributed ? m_blocks.whole_layers(kind) : block.nk(), 0.0);
        load_array(in, a, what);
        return m_blocks.block_of(a, kind);
    };
    std::array<Array3<double>, 3> velocity;
    const char* names[] = {"fluid state: u", "fluid state: v", "fluid state: w"};
    for (int axis = 0; axis < 3; ++axis)
        velocity[static_cast<size_t>(axis)] =
            load_block(m_grid.velocity(axis), velocity_layers(axis), names[axis]);
    Array3<double> pressure = load_block(m_pressure, LayerKind::cells, "fluid state: pressure");
    Array3<double> increment;
    const std::uint8_t has_increment = in.get<std::uint8_t>();
    if (has_increment > 1)
        throw FormatError("fluid state: bad increment flag");
    if (has_increment)
        increment = load_block(m_pressure, LayerKind::cells, "fluid state: pressure increment");
    std::vector<char> was_liquid = in.get_vector<char>();
    const std::size_t cells =
        static_cast<std::size_t>(m_pressure.ni()) * m_pressure.nj() *
        (distributed ? m_blocks.whole_layers(LayerKind::cells) : m_pressure.nk());
    if (!was_liquid.empty() && was_liquid.size() != cells)
        throw FormatError("fluid state: the liquid flags do not match the grid");
    if (distributed && !was_liquid.empty()) {
        Array3<double> whole(m_pressure.ni(), m_pressure.nj(),
                             m_blocks.whole_layers(LayerKind::cells), 0.0);
        was_liquid =
            field_flags(m_blocks.block_of(flags_field(was_liquid, whole), LayerKind::cells));
    }
    const double time = in.get<double>();
    if (!std::isfinite(time) || time < 0.0)
        throw FormatError("fluid state: the time is not a number >= 0");
    for (int axis = 0; axis < 3; ++axis)
        m_grid.velocity(axis) = std::move(velocity[static_cast<size_t>(axis)]);
    m_pressure = std::move(pressure);
    m_increment = std::move(increment);
    m_was_liquid = std::move(was_liquid);
    m_time = time;
}

}  // namespace meniscus::fluid
