#include "fluid/pressure.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "fluid/eigen_reference_solver.h"
#include "fluid/pcg.h"

namespace meniscus::fluid {

namespace {

/// An outflow face lies half a cell from the centre of its cell (like a free-surface ghost face
/// with θ = ½).
constexpr double OUTFLOW_FRACTION = 0.5;

/// How one interior face enters the pressure system.
struct FaceCoupling {
    enum class Kind {
        none,          ///< no unknown on either side (free surface: gas–gas)
        coupled,       ///< both cells unknown: coefficient beta, jump p(hi) − p(lo) = jump
        dirichlet_lo,  ///< only lo is unknown; p = boundary_pressure at θ·dx from lo's centre
        dirichlet_hi   ///< only hi is unknown; p = boundary_pressure at θ·dx from hi's centre
    };
    Kind kind = Kind::none;
    double beta = 0.0;               ///< 1/ρ_f, m³/kg (divided by θ for Dirichlet faces)
    double jump = 0.0;               ///< Pa, coupled faces
    double boundary_pressure = 0.0;  ///< Pa, Dirichlet faces
};

FaceCoupling classify_face(double phi_lo, double phi_hi, double kappa, const PhaseOptions& phases,
                           FluidMode mode, double min_liquid_fraction) {
    FaceCoupling face;
    const bool liquid_lo = is_liquid(phi_lo);
    const bool liquid_hi = is_liquid(phi_hi);
    if (mode == FluidMode::two_phase) {
        face.kind = FaceCoupling::Kind::coupled;
        face.beta = 1.0 / face_density(liquid_fraction(phi_lo, phi_hi), phases, mode);
        face.jump = face_pressure_jump(phi_lo, phi_hi, phases.sigma, kappa);
        return face;
    }
    if (liquid_lo && liquid_hi) {
        face.kind = FaceCoupling::Kind::coupled;
        face.beta = 1.0 / phases.rho_liquid;
        return face;
    }
    if (!liquid_lo && !liquid_hi) {
        return face;
    }
    const double theta = std::max(liquid_fraction(phi_lo, phi_hi), min_liquid_fraction);
    face.kind = liquid_lo ? FaceCoupling::Kind::dirichlet_lo : FaceCoupling::Kind::dirichlet_hi;
    face.beta = 1.0 / (phases.rho_liquid * theta);
    face.boundary_pressure = phases.sigma * kappa;  // gas at zero pressure: p_liquid = σκ
    return face;
}

bool is_unknown(double phi, FluidMode mode) {
    return mode == FluidMode::two_phase || is_liquid(phi);
}

/// classify_face() with the faces between two cells of one phase, most of a grid's, taken from
/// two couplings made once: the function depends on such a face's level set values only through
/// their phase (its liquid fraction is 0 or 1, its jump 0), so the result is the same bit for bit.
class FaceClassifier {
public:
    FaceClassifier(const PhaseOptions& phases, FluidMode mode, double min_liquid_fraction)
        : m_phases(phases),
          m_mode(mode),
          m_min_liquid_fraction(min_liquid_fraction),
          m_liquid(classify_face(-1.0, -1.0, 0.0, phases, mode, min_liquid_fraction)),
          m_gas(classify_face(1.0, 1.0, 0.0, phases, mode, min_liquid_fraction)) {}

    FaceCoupling operator()(double phi_lo, double phi_hi, double kappa) const {
        const bool liquid_lo = is_liquid(phi_lo);
        if (liquid_lo == is_liquid(phi_hi))
            return liquid_lo ? m_liquid : m_gas;
        return classify_face(phi_lo, phi_hi, kappa, m_phases, m_mode, m_min_liquid_fraction);
    }

private:
    const PhaseOptions& m_phases;
    FluidMode m_mode;
    double m_min_liquid_fraction;
    FaceCoupling m_liquid, m_gas;
};

/// Calls visit(face, lo cell, hi cell) (flat indices: the face's in its face array, the cells'
/// in the cell arrays) for every face of component `axis` that lies strictly inside the box; the
/// hi cell is the one at the face's own (i, j, k). With a `periodic` axis the face on the min side
/// is the seam between cell n−1 (lo) and cell 0 (hi), and is visited too (its copy on the max
/// side is not); not where n = 1 (the cell would neighbour itself). Row by row in (k, j, i) order;
/// with `Parallel` the k-planes are split over threads (only for visits that write nothing another
/// face's visit reads or writes).
template <bool Parallel, class Visit>
void for_each_interior_face(const MacGrid& grid, int axis, bool periodic, Visit&& visit) {
    const Array3<double>& faces = grid.velocity(axis);
    const int n_axis = grid.cells(axis);
    const bool seam = periodic && n_axis > 1;
    const std::size_t nx = static_cast<std::size_t>(grid.nx());
    const std::size_t ny = static_cast<std::size_t>(grid.ny());
    const std::size_t cell_step = axis == 0 ? 1 : (axis == 1 ? nx : nx * ny);
    // The seam's lo cell is the last one along the axis.
    const std::size_t seam_step = static_cast<std::size_t>(n_axis - 1) * cell_step;
    const auto planes = [&](const tbb::blocked_range<int>& r) {
        for (int k = r.begin(); k != r.end(); ++k)
            for (int j = 0; j < faces.nj(); ++j) {
                const int row_along = axis == 1 ? j : k;
                if (axis != 0 && ((row_along == 0 && !seam) || row_along == n_axis))
                    continue;
                const std::size_t face_row = faces.index(0, j, k);
                const std::size_t cell_row = nx * (static_cast<std::size_t>(j) + ny * k);
                for (int i = 0; i < faces.ni(); ++i) {
                    const int along = axis == 0 ? i : row_along;
                    if ((along == 0 && !seam) || along == n_axis)
                        continue;
                    const std::size_t hi = cell_row + static_cast<std::size_t>(i);
                    visit(face_row + static_cast<std::size_t>(i),
                          along == 0 ? hi + seam_step : hi - cell_step, hi);
                }
            }
    };
    const tbb::blocked_range<int> all(0, faces.nk());
    if constexpr (Parallel)
        tbb::parallel_for(all, planes);
    else
        planes(all);
}

/// Calls visit(axis, face index (i, j, k), the cell inside it, its coupling) for every boundary
/// face of an outflow side of the box whose cell is an unknown of the face's ambient phase — the
/// phase of most of its cells: a Dirichlet face with p = the outflow's pressure on the face itself,
/// half a cell from the cell's centre (coefficient 2/ρ of the cell's phase). The faces of the
/// cells of the other phase (a drop or a bubble on its way out) are left out: they keep the
/// zero-gradient velocity they were given (a Neumann face, like a wall's), so what leaves does
/// so at its own speed and its Laplace pressure is not pinned to the ambient's.
template <class Visit>
void for_each_outflow_face(const MacGrid& grid, const InterfaceInput& interface,
                           const PhaseOptions& phases, FluidMode mode,
                           const BoundaryOptions& boundaries, Visit&& visit) {
    const Array3<double>& phi = interface.phi;
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const FaceBoundary& boundary = boundaries.face(axis, side);
            if (boundary.type != BoundaryType::outflow)
                continue;
            const Array3<double>& faces = grid.velocity(axis);
            const int ni = axis == 0 ? 1 : faces.ni();
            const int nj = axis == 1 ? 1 : faces.nj();
            const int nk = axis == 2 ? 1 : faces.nk();
            const auto cell_of = [&](int i, int j, int k) {
                std::array<int, 3> cell = {i, j, k};
                cell[static_cast<size_t>(axis)] = side == 0 ? 0 : grid.cells(axis) - 1;
                return cell;
            };
            long long liquid = 0, total = 0;
            for (int k = 0; k < nk; ++k)
                for (int j = 0; j < nj; ++j)
                    for (int i = 0; i < ni; ++i) {
                        const std::array<int, 3> cell = cell_of(i, j, k);
                        liquid += is_liquid(phi(cell[0], cell[1], cell[2])) ? 1 : 0;
                        ++total;
                    }
            const bool ambient_liquid = 2 * liquid >= total;
            for (int k = 0; k < nk; ++k)
                for (int j = 0; j < nj; ++j)
                    for (int i = 0; i < ni; ++i) {
                        const std::array<int, 3> cell = cell_of(i, j, k);
                        std::array<int, 3> face = {i, j, k};
                        face[static_cast<size_t>(axis)] = side == 0 ? 0 : grid.cells(axis);
                        const double phi_cell = phi(cell[0], cell[1], cell[2]);
                        if (!is_unknown(phi_cell, mode) || is_liquid(phi_cell) != ambient_liquid)
                            continue;
                        FaceCoupling coupling;
                        coupling.kind = side == 0 ? FaceCoupling::Kind::dirichlet_hi
                                                  : FaceCoupling::Kind::dirichlet_lo;
                        const double theta = is_liquid(phi_cell) ? 1.0 : 0.0;
                        coupling.beta = 1.0 / (OUTFLOW_FRACTION *
                                               face_density(theta, phases, FluidMode::two_phase));
                        coupling.boundary_pressure = boundary.pressure;
                        visit(axis, face[0], face[1], face[2], phi.index(cell[0], cell[1], cell[2]),
                              coupling);
                    }
        }
}

}  // namespace

void PressureOptions::validate() const {
    iteration.validate();
    if (solver != PressureSolver::mic0_pcg && solver != PressureSolver::multigrid_pcg &&
        solver != PressureSolver::eigen_ic_cg && solver != PressureSolver::hypre_pfmg_pcg) {
        throw std::invalid_argument("PressureOptions.solver: unknown solver");
    }
    if (!(min_liquid_fraction > 0.0 && min_liquid_fraction <= 1.0)) {
        throw std::invalid_argument("PressureOptions.min_liquid_fraction must be in (0, 1]");
    }
    mic0.validate();
    multigrid.validate();
}

PressureSystem build_pressure_system(const MacGrid& grid, const InterfaceInput& interface,
                                     const PhaseOptions& phases, FluidMode mode, double dt,
                                     const PressureOptions& options,
                                     const BoundaryOptions& boundaries) {
    interface.validate(grid);
    if (!(dt > 0.0)) {
        throw std::invalid_argument("build_pressure_system: dt must be positive (s)");
    }
    const int nx = grid.nx(), ny = grid.ny(), nz = grid.nz();
    PressureSystem system;
    system.matrix.resize(nx, ny, nz);
    system.rhs.assign(system.matrix.size(), 0.0);
    PoissonMatrix& a = system.matrix;
    std::vector<double>& b = system.rhs;
    const Array3<double>& phi = interface.phi;
    const FaceClassifier classify(phases, mode, options.min_liquid_fraction);
    bool has_dirichlet = false;
    for (int axis = 0; axis < 3; ++axis) {
        a.periodic[static_cast<std::size_t>(axis)] = boundaries.periodic(axis);
        Array3<double>& off = a.off(axis);
        const Array3<double>& kappa = interface.kappa(axis);
        // In order (the sums into a cell's diagonal and right-hand side as before).
        for_each_interior_face<false>(grid, axis, boundaries.periodic(axis),
                                      [&](std::size_t f, std::size_t lo, std::size_t hi) {
                                          const FaceCoupling face =
                                              classify(phi[lo], phi[hi], kappa[f]);
                                          switch (face.kind) {
                                              case FaceCoupling::Kind::none:
                                                  break;
                                              case FaceCoupling::Kind::coupled:
                                                  a.diag[lo] += face.beta;
                                                  a.diag[hi] += face.beta;
                                                  off[lo] = -face.beta;
                                                  b[lo] -= face.beta * face.jump;
                                                  b[hi] += face.beta * face.jump;
                                                  break;
                                              case FaceCoupling::Kind::dirichlet_lo:
                                                  a.diag[lo] += face.beta;
                                                  b[lo] += face.beta * face.boundary_pressure;
                                                  has_dirichlet = true;
                                                  break;
                                              case FaceCoupling::Kind::dirichlet_hi:
                                                  a.diag[hi] += face.beta;
                                                  b[hi] += face.beta * face.boundary_pressure;
                                                  has_dirichlet = true;
                                                  break;
                                          }
                                      });
    }
    for_each_outflow_face(grid, interface, phases, mode, boundaries,
                          [&](int, int, int, int, std::size_t c, const FaceCoupling& face) {
                              a.diag[c] += face.beta;
                              b[c] += face.beta * face.boundary_pressure;
                              has_dirichlet = true;
                          });
    const double flux_scale = grid.dx() * grid.dx() / dt;
    for (int k = 0; k < nz; ++k) {
        for (int j = 0; j < ny; ++j) {
            for (int i = 0; i < nx; ++i) {
                const std::size_t c = phi.index(i, j, k);
                if (!is_unknown(phi[c], mode)) {
                    continue;
                }
                b[c] -= flux_scale * grid.divergence(i, j, k);
                if (a.diag[c] <= 0.0) {
                    // An unknown cell with no open face (a 1-cell box): nothing to solve.
                    b[c] = 0.0;
                }
            }
        }
    }
    system.singular = !has_dirichlet;
    return system;
}

PressureSystemSolver::PressureSystemSolver(const PressureSystem& system,
                                           const PressureOptions& options)
    : PressureSystemSolver(system, options, BlockContext()) {}

PressureSystemSolver::PressureSystemSolver(const PressureSystem& system,
                                           const PressureOptions& options,
                                           const BlockContext& blocks)
    : m_system(system), m_options(options) {
    options.validate();
    if (!blocks.distributed()) {
        switch (options.solver) {
            case PressureSolver::mic0_pcg:
                m_preconditioner =
                    std::make_unique<Mic0Preconditioner>(system.matrix, options.mic0);
                break;
            case PressureSolver::multigrid_pcg:
                m_preconditioner =
                    std::make_unique<MultigridPreconditioner>(system.matrix, options.multigrid);
                break;
            case PressureSolver::eigen_ic_cg:
                break;
            case PressureSolver::hypre_pfmg_pcg: {
                auto hypre = std::make_unique<HypreStructSolver>(system.matrix, system.singular);
                m_hypre = hypre.get();
                m_preconditioner = std::move(hypre);
                break;
            }
        }
        return;
    }
    m_options.solver = PressureSolver::hypre_pfmg_pcg;
    auto hypre = std::make_unique<HypreStructSolver>(system.matrix, system.singular,
                                                     blocks.decomposition(), blocks.ranks());
    m_hypre = hypre.get();
    m_preconditioner = std::move(hypre);
    m_distributed = true;
}

PressureSystemSolver::~PressureSystemSolver() = default;

SolveResult PressureSystemSolver::solve(const std::vector<double>& rhs,
                                        Array3<double>& pressure) const {
    const PoissonMatrix& a = m_system.matrix;
    if (rhs.size() != a.size())
        throw std::invalid_argument("PressureSystemSolver::solve: right-hand side of " +
                                    std::to_string(rhs.size()) + " values for " +
                                    std::to_string(a.size()) + " cells");
    std::vector<double> solution;
    const SolveResult result =
        m_hypre ? m_hypre->solve(rhs, m_options.iteration, solution)
        : m_preconditioner
            ? solve_pcg(a, rhs, *m_preconditioner, m_options.iteration, m_system.singular, solution)
            : solve_eigen_ic_cg(a, rhs, m_options.iteration, m_system.singular, solution);
    pressure.resize(a.ni(), a.nj(), a.nk(), 0.0);
    pressure.storage() = std::move(solution);
    return result;
}

SolveResult PressureSystemSolver::precondition(const std::vector<double>& rhs,
                                               Array3<double>& pressure) const {
    if (!m_preconditioner)
        return solve(rhs, pressure);
    const PoissonMatrix& a = m_system.matrix;
    if (rhs.size() != a.size())
        throw std::invalid_argument("PressureSystemSolver::precondition: right-hand side of " +
                                    std::to_string(rhs.size()) + " values for " +
                                    std::to_string(a.size()) + " cells");
    std::vector<double> b = rhs, z;
    // Distributed, the mean is the whole system's over every rank's owned cells.
    const auto remove_mean = [&](std::vector<double>& v) {
        if (m_distributed)
            m_hypre->remove_mean(v);
        else
            remove_active_mean(a, v);
    };
    if (m_system.singular)
        remove_mean(b);
    m_preconditioner->apply(b, z);
    if (m_system.singular)
        remove_mean(z);
    pressure.resize(a.ni(), a.nj(), a.nk(), 0.0);
    pressure.storage() = std::move(z);
    SolveResult result;
    result.converged = true;
    result.iterations = 1;
    return result;
}

SolveResult solve_pressure_system(const PressureSystem& system, const PressureOptions& options,
                                  Array3<double>& pressure) {
    return PressureSystemSolver(system, options).solve(system.rhs, pressure);
}

void apply_pressure_gradient(MacGrid& grid, const InterfaceInput& interface,
                             const PhaseOptions& phases, FluidMode mode, double dt,
                             const PressureOptions& options, const Array3<double>& pressure,
                             const BoundaryOptions& boundaries) {
    const Array3<double>& phi = interface.phi;
    interface.check_sizes(grid);
    if (pressure.ni() != grid.nx() || pressure.nj() != grid.ny() || pressure.nk() != grid.nz())
        throw std::invalid_argument(
            "apply_pressure_gradient: pressure must have the grid's cell counts");
    const double scale = dt / grid.dx();
    const FaceClassifier classify(phases, mode, options.min_liquid_fraction);
    for (int axis = 0; axis < 3; ++axis) {
        Array3<double>& velocity = grid.velocity(axis);
        const Array3<double>& kappa = interface.kappa(axis);
        for_each_interior_face<true>(
            grid, axis, boundaries.periodic(axis),
            [&](std::size_t f, std::size_t lo, std::size_t hi) {
                const FaceCoupling face = classify(phi[lo], phi[hi], kappa[f]);
                double difference = 0.0;  // p(hi) − p(lo) as seen from the unknown side(s), Pa
                switch (face.kind) {
                    case FaceCoupling::Kind::none:
                        return;
                    case FaceCoupling::Kind::coupled:
                        difference = pressure[hi] - pressure[lo] - face.jump;
                        break;
                    case FaceCoupling::Kind::dirichlet_lo:
                        difference = face.boundary_pressure - pressure[lo];
                        break;
                    case FaceCoupling::Kind::dirichlet_hi:
                        difference = pressure[hi] - face.boundary_pressure;
                        break;
                }
                velocity[f] -= scale * face.beta * difference;
            });
        if (boundaries.periodic(axis))  // the seam's copy on the max side
            copy_seam_faces(velocity, axis);
    }
    for_each_outflow_face(
        grid, interface, phases, mode, boundaries,
        [&](int axis, int i, int j, int k, std::size_t c, const FaceCoupling& face) {
            // p(hi) − p(lo) across the face, the outside being the face's p.
            const double difference = face.kind == FaceCoupling::Kind::dirichlet_lo
                                          ? face.boundary_pressure - pressure[c]
                                          : pressure[c] - face.boundary_pressure;
            grid.velocity(axis)(i, j, k) -= scale * face.beta * difference;
        });
}

double max_fluid_divergence(const MacGrid& grid, const InterfaceInput& interface, FluidMode mode) {
    const Array3<double>& phi = interface.phi;
    interface.check_sizes(grid);
    // A largest value: the same whatever the split.
    return tbb::parallel_reduce(
        tbb::blocked_range<int>(0, grid.nz()), 0.0,
        [&](const tbb::blocked_range<int>& r, double largest) {
            for (int k = r.begin(); k != r.end(); ++k)
                for (int j = 0; j < grid.ny(); ++j) {
                    const std::size_t row = phi.index(0, j, k);
                    for (int i = 0; i < grid.nx(); ++i)
                        if (is_unknown(phi[row + static_cast<std::size_t>(i)], mode))
                            largest = std::max(largest, std::abs(grid.divergence(i, j, k)));
                }
            return largest;
        },
        [](double a, double b) { return std::max(a, b); });
}

ProjectionResult project(MacGrid& grid, const InterfaceInput& interface, const PhaseOptions& phases,
                         FluidMode mode, double dt, const PressureOptions& options,
                         Array3<double>& pressure, const BoundaryOptions& boundaries) {
    PhaseClock clock;
    const PressureSystem system =
        build_pressure_system(grid, interface, phases, mode, dt, options, boundaries);
    ProjectionResult result;
    result.build_time = clock.lap();
    result.solve = solve_pressure_system(system, options, pressure);
    result.singular = system.singular;
    apply_pressure_gradient(grid, interface, phases, mode, dt, options, pressure, boundaries);
    result.max_divergence = max_fluid_divergence(grid, interface, mode);
    result.solve_time = clock.lap();
    return result;
}

}  // namespace meniscus::fluid
