#include "fluid/viscosity.h"

#include "fluid/surface_viscosity.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "fluid/hypre_struct_solver.h"
#include "fluid/multigrid.h"
#include "fluid/poisson_matrix.h"
#include "fluid/surface_preconditioner.h"
#include "fluid/viscous_operator.h"

namespace meniscus::fluid {

/// Ghost layers the operator reads around a rank's own faces: the normal stress of the cell
/// beyond the slab's last face and the shear stress of the edges on the slab's ends need the
/// faces one layer out, no further. What the CG refreshes every iteration (a depth of 0, no
/// exchange, fails the distributed tests by 3e5 times their tolerance; 1 passes them).
constexpr int VISCOUS_HALO_DEPTH = 1;

/// Faces per task of the solve's set-up pass.
constexpr std::size_t SETUP_GRAIN = 16384;

void ViscosityOptions::validate() const {
    iteration.validate();
    if (weights != ViscosityWeights::sharp && weights != ViscosityWeights::volume_fraction &&
        weights != ViscosityWeights::pointwise)
        throw std::invalid_argument("ViscosityOptions.weights: unknown weighting");
    if (preconditioner != ViscousPreconditioner::jacobi &&
        preconditioner != ViscousPreconditioner::jacobi_surface &&
        preconditioner != ViscousPreconditioner::multigrid &&
        preconditioner != ViscousPreconditioner::hypre_pfmg)
        throw std::invalid_argument("ViscosityOptions.preconditioner: unknown preconditioner");
    multigrid.validate();
}

/// What the operator was last built from: the coupled scheme's Uzawa passes solve again with
/// the same interface and time step, so the operator and its diagonal are reused.
struct OperatorKey {
    std::array<int, 3> cells{};
    double dx = 0.0, dt = 0.0, min_liquid_fraction = 0.0;
    double rho_liquid = 0.0, rho_gas = 0.0, mu_liquid = 0.0, mu_gas = 0.0;
    FluidMode mode = FluidMode::two_phase;
    std::array<BoundaryType, 6> walls{};
    ViscosityWeights weights = ViscosityWeights::sharp;
    /// The surface term, compared by address: held here, so a new one (the caller builds one
    /// for each step) cannot take the old one's address.
    std::shared_ptr<const SurfaceViscosity> surface;
    std::vector<double> phi;

    OperatorKey() = default;
    OperatorKey(const MacGrid& grid, const PhaseOptions& phases, FluidMode mode_in,
                const BoundaryOptions& walls_in, double dt_in, double min_fraction,
                ViscosityWeights weights_in)
        : cells{grid.nx(), grid.ny(), grid.nz()},
          dx(grid.dx()),
          dt(dt_in),
          min_liquid_fraction(min_fraction),
          rho_liquid(phases.rho_liquid),
          rho_gas(phases.rho_gas),
          mu_liquid(phases.mu_liquid),
          mu_gas(phases.mu_gas),
          mode(mode_in),
          walls{walls_in.x_min.type, walls_in.x_max.type, walls_in.y_min.type,
                walls_in.y_max.type, walls_in.z_min.type, walls_in.z_max.type},
          weights(weights_in) {}

    /// Equal settings (the stored φ is compared separately, without copying the new one).
    bool same_settings(const OperatorKey& o) const {
        return cells == o.cells && dx == o.dx && dt == o.dt &&
               min_liquid_fraction == o.min_liquid_fraction && rho_liquid == o.rho_liquid &&
               rho_gas == o.rho_gas && mu_liquid == o.mu_liquid && mu_gas == o.mu_gas &&
               mode == o.mode && walls == o.walls && weights == o.weights && surface == o.surface;
    }
};

/// Work arrays kept between ViscositySolver::solve calls.
struct ViscositySolver::Workspace {
    ViscousOperator op;
    /// distribute(): the grid is this rank's block (one rank: a plain solve)
    SlabDecomposition decomposition;
    RankCommunicator ranks = RankCommunicator::self();
    std::vector<char> owned;  ///< distributed: 1 on the entries of [u | v | w] this rank owns
    OperatorKey key;          ///< what `op` and `diagonal` were built from (empty φ: nothing yet)
    std::vector<double> u_star, fixed, x, b, r, z, p, q, diagonal;
    /// multigrid, hypre_pfmg: the component blocks and their V-cycles (built on first use
    /// after `op`, of the kind `cycles_kind`). Distributed, the block of w stops below its top
    /// face layer, so that it has the decomposition's z-layers as hypre needs.
    std::array<PoissonMatrix, 3> blocks;
    std::array<std::unique_ptr<Preconditioner>, 3> cycles;
    ViscousPreconditioner cycles_kind = ViscousPreconditioner::jacobi;
    /// jacobi_surface with the implicit tension's surface term: the diagonal made exact for
    /// that term (built on first use after `op`)
    SurfacePreconditioner surface_jacobi;

    void build_cycles(const ViscousOperator& op, bool distributed, const ViscosityOptions& options);
    std::array<std::vector<double>, 3> block_r, block_z;
};

ViscositySolver::ViscositySolver() : m_workspace(std::make_unique<Workspace>()) {}
ViscositySolver::~ViscositySolver() = default;
ViscositySolver::ViscositySolver(ViscositySolver&&) noexcept = default;
ViscositySolver& ViscositySolver::operator=(ViscositySolver&&) noexcept = default;

void ViscositySolver::distribute(const SlabDecomposition& decomposition,
                                 const RankCommunicator& ranks) {
    if (decomposition.ranks() != ranks.size())
        throw std::invalid_argument("ViscositySolver::distribute: a decomposition over " +
                                    std::to_string(decomposition.ranks()) + " ranks on " +
                                    std::to_string(ranks.size()));
    if (decomposition.distributed() && decomposition.ghost_layers() < 2)
        throw std::invalid_argument(
            "ViscositySolver::distribute: the viscous stencil needs at least 2 ghost layers");
    m_workspace->decomposition = decomposition;
    m_workspace->ranks = ranks;
    m_workspace->owned.clear();
}

/// The per-component preconditioners of `options.preconditioner` (multigrid or hypre_pfmg) on
/// the blocks of `op` (ViscousOperator::component_blocks with the workspace's diagonal).
/// hypre: one HypreStructSolver (a 7-point Struct system with its PFMG V-cycle) per component;
/// distributed, collective, on each rank's block, w's cropped to the decomposition's layers.
void ViscositySolver::Workspace::build_cycles(const ViscousOperator& op, bool distributed,
                                              const ViscosityOptions& options) {
    Workspace& ws = *this;
    op.component_blocks(ws.diagonal, ws.blocks);
    const int rank = ws.ranks.rank();
    for (std::size_t a = 0; a < 3; ++a) {
        ws.cycles[a].reset();
        if (options.preconditioner == ViscousPreconditioner::multigrid) {
            ws.cycles[a] =
                std::make_unique<MultigridPreconditioner>(ws.blocks[a], options.multigrid);
            continue;
        }
        if (!distributed) {
            ws.cycles[a] = std::make_unique<HypreStructSolver>(ws.blocks[a], false);
            continue;
        }
        PoissonMatrix& block = ws.blocks[a];
        const int layers = ws.decomposition.local_layers(rank);
        if (block.nk() == layers + 1) {  // w: its faces' layers, one more than the cells'
            PoissonMatrix cropped;
            cropped.resize(block.ni(), block.nj(), layers);
            for (int k = 0; k < layers; ++k)
                for (int j = 0; j < block.nj(); ++j)
                    for (int i = 0; i < block.ni(); ++i) {
                        cropped.diag(i, j, k) = block.diag(i, j, k);
                        cropped.off_x(i, j, k) = block.off_x(i, j, k);
                        cropped.off_y(i, j, k) = block.off_y(i, j, k);
                        cropped.off_z(i, j, k) = k + 1 < layers ? block.off_z(i, j, k) : 0.0;
                    }
            block = std::move(cropped);
        }
        ws.cycles[a] =
            std::make_unique<HypreStructSolver>(block, false, ws.decomposition, ws.ranks);
    }
    ws.cycles_kind = options.preconditioner;
}

SolveResult ViscositySolver::solve(MacGrid& grid, const InterfaceInput& interface,
                                   const PhaseOptions& phases, FluidMode mode,
                                   const BoundaryOptions& walls, double dt,
                                   const ViscosityOptions& options, double min_liquid_fraction) {
    options.validate();
    walls.validate();
    interface.validate(grid);
    if (!(dt > 0.0)) {
        throw std::invalid_argument("apply_viscosity: dt must be positive (s)");
    }
    SolveResult result;
    std::shared_ptr<const SurfaceViscosity> surface = interface.surface_viscosity;
    if (surface && !surface->active())
        surface.reset();
    // Viscosity switched off leaves the surface term alone to solve for.
    PhaseOptions viscous_phases = phases;
    if (!options.enabled)
        viscous_phases.mu_liquid = viscous_phases.mu_gas = 0.0;
    const double mu_gas = mode == FluidMode::two_phase ? viscous_phases.mu_gas : 0.0;
    if (!surface && (viscous_phases.mu_liquid == 0.0 && mu_gas == 0.0)) {
        result.converged = true;
        return result;
    }
    Workspace& ws = *m_workspace;
    ViscousOperator& op = ws.op;
    OperatorKey key(grid, viscous_phases, mode, walls, dt, min_liquid_fraction, options.weights);
    key.surface = surface;
    bool reuse =
        !ws.key.phi.empty() && ws.key.same_settings(key) && ws.key.phi == interface.phi.storage();
    // Distributed, every rank rebuilds when one does: the hypre V-cycles are built collectively
    // (a rank whose block's φ had not changed kept its operator while the others waited in
    // hypre's set-up: a deadlock, found by `mpirun -n 2 meniscus run` of bubble_merge).
    if (ws.decomposition.distributed())
        reuse = ws.ranks.all(reuse);
    if (!reuse) {
        ws.key.phi.clear();  // nothing valid until the build is complete
        ws.diagonal.clear();
        for (auto& cycle : ws.cycles)
            cycle.reset();
        ws.surface_jacobi = SurfacePreconditioner();
        op.build(grid, interface.phi, viscous_phases, mode, walls, dt, min_liquid_fraction,
                 options.weights, surface.get());
        key.phi = interface.phi.storage();
        ws.key = std::move(key);
    }
    const std::vector<char>& unknown = op.unknown();
    const std::vector<double>& density = op.density();
    const std::size_t n = op.size();
    // Distributed (the grid is this rank's block): each rank solves for the faces it owns. Dot
    // products sum its own entries over the ranks; the operator reads the ghost layers of its
    // argument, so the search direction's are exchanged before each application (the operator's
    // reach is one cell and one edge: two ghost layers suffice).
    const bool distributed = ws.decomposition.distributed();
    if (distributed) {
        if (ws.decomposition.local_layers(ws.ranks.rank()) != grid.nz())
            throw std::invalid_argument(
                "ViscositySolver: the grid is not this rank's block of the decomposition");
        if (surface)
            throw std::invalid_argument(
                "ViscositySolver: semi-implicit surface tension is not available on several "
                "ranks yet");
        if (options.preconditioner == ViscousPreconditioner::multigrid)
            throw std::invalid_argument(
                "ViscosityOptions.preconditioner: multigrid is not available on several ranks "
                "(jacobi or hypre_pfmg are)");
        if (ws.owned.size() != n) {
            ws.owned.assign(n, 0);
            const int rank = ws.ranks.rank();
            const int begin =
                ws.decomposition.owned_begin(rank) - ws.decomposition.local_begin(rank);
            const int end = ws.decomposition.owned_end(rank) - ws.decomposition.local_begin(rank);
            std::size_t offset = 0;
            for (int a = 0; a < 3; ++a) {
                const Array3<double>& faces = grid.velocity(a);
                const std::size_t layer = static_cast<std::size_t>(faces.ni()) * faces.nj();
                // The last rank of a walled z also owns the top z-face.
                const bool top =
                    a == 2 && !ws.decomposition.periodic() && rank == ws.decomposition.ranks() - 1;
                for (int k = 0; k < faces.nk(); ++k)
                    if ((k >= begin && k < end) || (top && k == faces.nk() - 1))
                        std::fill_n(
                            ws.owned.begin() + static_cast<std::ptrdiff_t>(offset + layer * k),
                            layer, 1);
                offset += faces.size();
            }
        }
    }
    const auto global_dot = [&](const std::vector<double>& a, const std::vector<double>& c) {
        if (!distributed)
            return dot(a, c);
        double sum = 0.0;
        for (std::size_t f = 0; f < n; ++f)
            sum += ws.owned[f] ? a[f] * c[f] : 0.0;
        return ws.ranks.sum(sum);
    };
    const auto refresh_ghosts = [&](std::vector<double>& v) {
        if (!distributed)
            return;
        std::size_t offset = 0;
        for (int a = 0; a < 3; ++a) {
            const Array3<double>& faces = grid.velocity(a);
            exchange_halo_layers(
                v.data() + offset, static_cast<std::size_t>(faces.ni()) * faces.nj(),
                ws.decomposition, ws.ranks, a == 2 ? LayerKind::z_faces : LayerKind::cells,
                VISCOUS_HALO_DEPTH);
            offset += faces.size();
        }
    };
    std::vector<double>& x = ws.x;
    std::vector<double>& fixed = ws.fixed;
    std::vector<double>& b = ws.b;
    // Split u* into the unknowns x (initial guess) and the fixed faces; b = ρ u* − K u_fixed,
    // K's wall strains relative to moving walls. One pass splits, forms ρ u* on the unknowns and
    // finds whether the fixed faces are at rest.
    op.gather(grid, ws.u_star);
    x.resize(n);
    fixed.resize(n);
    b.resize(n);
    const bool fixed_at_rest = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, SETUP_GRAIN), true,
        [&](const tbb::blocked_range<std::size_t>& range, bool at_rest) {
            for (std::size_t f = range.begin(); f != range.end(); ++f) {
                const double u = ws.u_star[f];
                x[f] = unknown[f] ? u : 0.0;
                fixed[f] = unknown[f] ? 0.0 : u;
                b[f] = unknown[f] ? density[f] * u : 0.0;
                at_rest = at_rest && fixed[f] == 0.0;
            }
            return at_rest;
        },
        [](bool a, bool c) { return a && c; });
    // At rest, K 0 = 0 (the map is linear without moving walls): b = ρ u* exactly, without the
    // operator's three passes (two_phase in a box of walls at rest: every step).
    if (!fixed_at_rest || walls.moving()) {
        op.stiffness(fixed, b, walls.moving() ? &walls : nullptr);
        for (std::size_t f = 0; f < n; ++f) {
            b[f] = unknown[f] ? density[f] * ws.u_star[f] - b[f] : 0.0;
        }
    }
    const double b_norm = std::sqrt(global_dot(b, b));
    if (b_norm == 0.0) {
        x.assign(n, 0.0);
        result.converged = true;
    } else {
        // Jacobi-preconditioned CG from the initial guess u*.
        std::vector<double>& r = ws.r;
        std::vector<double>& z = ws.z;
        std::vector<double>& p = ws.p;
        std::vector<double>& q = ws.q;
        if (ws.diagonal.empty())
            op.diagonal(ws.diagonal);
        const std::vector<double>& diagonal = ws.diagonal;
        const ViscousPreconditioner kind = options.preconditioner;
        const bool diagonal_kind =
            kind == ViscousPreconditioner::jacobi || kind == ViscousPreconditioner::jacobi_surface;
        if (!diagonal_kind && (!ws.cycles[0] || ws.cycles_kind != kind))
            ws.build_cycles(op, distributed, options);
        // Far past the capillary limit the surface term outweighs the faces' mass along the
        // surface: jacobi_surface takes D + Sᵀ B S whole (surface_preconditioner.h).
        const bool surface_jacobi = kind == ViscousPreconditioner::jacobi_surface && surface;
        if (surface_jacobi && !ws.surface_jacobi.built()) {
            std::vector<double> grid_diagonal;
            op.diagonal(grid_diagonal, false);
            ws.surface_jacobi.build(*surface, op.surface_scale(), grid_diagonal, unknown);
        }
        // z = M⁻¹ r: Jacobi, or a V-cycle on each component's block (r is zero on fixed faces,
        // and so is z). The layer of w's faces left out of a cropped block (the top face of the
        // last rank's block, solved for only below an outflow; a ghost layer elsewhere) takes
        // the diagonal.
        const auto precondition = [&]() {
            if (surface_jacobi) {
                ws.surface_jacobi.apply(r, z);
                return;
            }
            if (diagonal_kind) {
                for (std::size_t f = 0; f < n; ++f)
                    z[f] = r[f] / diagonal[f];
                return;
            }
            std::size_t offset = 0;
            for (std::size_t a = 0; a < 3; ++a) {
                const std::size_t size = grid.velocity(static_cast<int>(a)).size();
                const std::size_t in_block = ws.blocks[a].size();
                ws.block_r[a].assign(r.begin() + static_cast<std::ptrdiff_t>(offset),
                                     r.begin() + static_cast<std::ptrdiff_t>(offset + in_block));
                ws.cycles[a]->apply(ws.block_r[a], ws.block_z[a]);
                std::copy(ws.block_z[a].begin(), ws.block_z[a].end(),
                          z.begin() + static_cast<std::ptrdiff_t>(offset));
                for (std::size_t f = offset + in_block; f < offset + size; ++f)
                    z[f] = r[f] / diagonal[f];
                offset += size;
            }
        };
        // On one process the plain diagonal's update, residual and dot products take one pass.
        const bool fused_jacobi = !distributed && diagonal_kind && !surface_jacobi;
        op.apply(x, q);
        double rz = 0.0;
        if (fused_jacobi) {
            const ResidualDots dots = jacobi_cg_start(b, q, diagonal, r, z, p);
            rz = dots.rz;
            result.residual = std::sqrt(dots.rr) / b_norm;
        } else {
            r.resize(n);
            z.resize(n);
            for (std::size_t f = 0; f < n; ++f)
                r[f] = b[f] - q[f];
            precondition();
            p = z;
            rz = global_dot(r, z);
            result.residual = std::sqrt(global_dot(r, r)) / b_norm;
        }
        result.converged = result.residual <= options.iteration.tolerance;
        while (!result.converged && result.iterations < options.iteration.max_iterations) {
            options.iteration.cancel.throw_if_requested("the viscosity solve");
            refresh_ghosts(p);
            double curvature = 0.0;
            if (distributed) {
                op.apply(p, q);
                curvature = global_dot(p, q);
            } else {
                curvature = op.apply_dot(p, q);  // p·q from the same pass
            }
            if (!(curvature > 0.0)) {
                break;
            }
            const double alpha = rz / curvature;
            ++result.iterations;
            double rz_new = 0.0;
            if (fused_jacobi) {
                const ResidualDots dots = jacobi_cg_update(alpha, p, q, diagonal, x, r, z);
                result.residual = std::sqrt(dots.rr) / b_norm;
                rz_new = dots.rz;
            } else {
                axpy(alpha, p, x);
                axpy(-alpha, q, r);
                result.residual = std::sqrt(global_dot(r, r)) / b_norm;
                precondition();
                rz_new = global_dot(r, z);
            }
            result.converged = result.residual <= options.iteration.tolerance;
            xpby(z, rz_new / rz, p);
            rz = rz_new;
        }
    }
    for (std::size_t f = 0; f < n; ++f) {
        x[f] += fixed[f];
    }
    op.scatter(x, grid);
    for (int axis = 0; axis < 3; ++axis)  // the faces at n of periodic axes repeat those at 0
        if (walls.periodic(axis))
            copy_seam_faces(grid.velocity(axis), axis);
    if (distributed)
        for (int a = 0; a < 3; ++a)
            exchange_halos(grid.velocity(a), ws.decomposition, ws.ranks,
                           a == 2 ? LayerKind::z_faces : LayerKind::cells);
    return result;
}

SolveResult apply_viscosity(MacGrid& grid, const InterfaceInput& interface,
                            const PhaseOptions& phases, FluidMode mode,
                            const BoundaryOptions& walls, double dt,
                            const ViscosityOptions& options, double min_liquid_fraction) {
    ViscositySolver solver;
    return solver.solve(grid, interface, phases, mode, walls, dt, options, min_liquid_fraction);
}

}  // namespace meniscus::fluid
