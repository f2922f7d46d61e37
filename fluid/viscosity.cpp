#include "fluid/viscosity.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace meniscus::fluid {

namespace {

/// Weight of a shear strain-rate term: 2 μ ε_ab² = ½ μ (∂_b u_a + ∂_a u_b)².
constexpr double SHEAR_WEIGHT = 0.5;
constexpr int MAX_TERM_ENTRIES = 4;
constexpr double HALF = 0.5;

/// A linear combination Σ coeff·(face velocity) that enters the energy squared.
struct StrainTerm {
    int count = 0;
    std::array<int, MAX_TERM_ENTRIES> axis{};
    std::array<std::size_t, MAX_TERM_ENTRIES> face{};
    std::array<double, MAX_TERM_ENTRIES> coeff{};

    void add(int a, std::size_t f, double c) {
        axis[count] = a;
        face[count] = f;
        coeff[count] = c;
        ++count;
    }
};

class ViscousSystem {
public:
    ViscousSystem(const MacGrid& grid, const InterfaceInput& interface, const PhaseOptions& phases,
                  FluidMode mode, const WallOptions& walls, double dt)
        : m_grid(grid),
          m_phi(interface.phi),
          m_phases(phases),
          m_mode(mode),
          m_walls(walls),
          m_dt(dt) {
        number_unknowns();
        cell_viscosity();
    }

    std::int64_t unknown_count() const { return m_count; }

    void assemble(Eigen::SparseMatrix<double>& matrix, Eigen::VectorXd& rhs,
                  Eigen::VectorXd& guess) {
        rhs.setZero(m_count);
        guess.setZero(m_count);
        std::vector<Eigen::Triplet<double>> triplets;
        mass_terms(triplets, rhs, guess);
        diagonal_strain_terms(triplets, rhs);
        shear_strain_terms(triplets, rhs);
        matrix.resize(m_count, m_count);
        matrix.setFromTriplets(triplets.begin(), triplets.end());
    }

    void scatter(const Eigen::VectorXd& solution, MacGrid& grid) const {
        for (int a = 0; a < 3; ++a) {
            Array3<double>& faces = grid.velocity(a);
            for (std::size_t f = 0; f < faces.size(); ++f) {
                if (m_unknown[a][f] >= 0) {
                    faces[f] = solution[m_unknown[a][f]];
                }
            }
        }
    }

private:
    void number_unknowns() {
        for (int a = 0; a < 3; ++a) {
            const Array3<double>& faces = m_grid.velocity(a);
            m_unknown[a].assign(faces.size(), -1);
            const int n_axis = m_grid.cells(a);
            for (int k = 0; k < faces.nk(); ++k) {
                for (int j = 0; j < faces.nj(); ++j) {
                    for (int i = 0; i < faces.ni(); ++i) {
                        const std::array<int, 3> idx = {i, j, k};
                        if (idx[a] == 0 || idx[a] == n_axis) {
                            continue;
                        }
                        std::array<int, 3> lo = idx;
                        --lo[a];
                        const double phi_lo = m_phi(lo[0], lo[1], lo[2]);
                        const double phi_hi = m_phi(i, j, k);
                        if (m_mode == FluidMode::free_surface && !is_liquid(phi_lo) &&
                            !is_liquid(phi_hi)) {
                            continue;
                        }
                        m_unknown[a][faces.index(i, j, k)] = m_count++;
                    }
                }
            }
        }
    }

    void cell_viscosity() {
        const double mu_gas = m_mode == FluidMode::two_phase ? m_phases.mu_gas : 0.0;
        m_mu.resize(m_grid.nx(), m_grid.ny(), m_grid.nz());
        for (std::size_t c = 0; c < m_mu.size(); ++c) {
            m_mu[c] = is_liquid(m_phi[c]) ? m_phases.mu_liquid : mu_gas;
        }
    }

    void mass_terms(std::vector<Eigen::Triplet<double>>& triplets, Eigen::VectorXd& rhs,
                    Eigen::VectorXd& guess) const {
        for (int a = 0; a < 3; ++a) {
            const Array3<double>& faces = m_grid.velocity(a);
            for (int k = 0; k < faces.nk(); ++k) {
                for (int j = 0; j < faces.nj(); ++j) {
                    for (int i = 0; i < faces.ni(); ++i) {
                        const std::size_t f = faces.index(i, j, k);
                        const std::int64_t row = m_unknown[a][f];
                        if (row < 0) {
                            continue;
                        }
                        std::array<int, 3> lo = {i, j, k};
                        --lo[a];
                        const double theta =
                            liquid_fraction(m_phi(lo[0], lo[1], lo[2]), m_phi(i, j, k));
                        const double rho = face_density(theta, m_phases, m_mode);
                        triplets.emplace_back(row, row, rho);
                        rhs[row] += rho * faces[f];
                        guess[row] = faces[f];
                    }
                }
            }
        }
    }

    /// Adds 2Δt·weight·(Σ c u)² to the quadratic form: matrix entries among unknowns, known
    /// (fixed) face values moved to the right-hand side.
    void add_term(const StrainTerm& term, double weight,
                  std::vector<Eigen::Triplet<double>>& triplets, Eigen::VectorXd& rhs) const {
        if (weight == 0.0) {
            return;
        }
        const double scale = 2.0 * m_dt * weight;
        for (int m = 0; m < term.count; ++m) {
            const std::int64_t row = m_unknown[term.axis[m]][term.face[m]];
            if (row < 0) {
                continue;
            }
            for (int n = 0; n < term.count; ++n) {
                const double value = scale * term.coeff[m] * term.coeff[n];
                const std::int64_t col = m_unknown[term.axis[n]][term.face[n]];
                if (col >= 0) {
                    triplets.emplace_back(row, col, value);
                } else {
                    rhs[row] -= value * m_grid.velocity(term.axis[n])[term.face[n]];
                }
            }
        }
    }

    void diagonal_strain_terms(std::vector<Eigen::Triplet<double>>& triplets,
                               Eigen::VectorXd& rhs) const {
        const double inv_dx = 1.0 / m_grid.dx();
        for (int k = 0; k < m_grid.nz(); ++k) {
            for (int j = 0; j < m_grid.ny(); ++j) {
                for (int i = 0; i < m_grid.nx(); ++i) {
                    const double mu = m_mu(i, j, k);
                    for (int a = 0; a < 3; ++a) {
                        const Array3<double>& faces = m_grid.velocity(a);
                        std::array<int, 3> hi = {i, j, k};
                        ++hi[a];
                        StrainTerm term;
                        term.add(a, faces.index(hi[0], hi[1], hi[2]), inv_dx);
                        term.add(a, faces.index(i, j, k), -inv_dx);
                        add_term(term, mu, triplets, rhs);
                    }
                }
            }
        }
    }

    /// Adds ∂(velocity component a)/∂x_b at edge `edge` (indices of the edge lattice) to `term`.
    /// Returns false when the edge lies on a free-slip wall of axis b (term dropped).
    bool add_derivative(int a, int b, const std::array<int, 3>& edge, StrainTerm& term) const {
        const double inv_dx = 1.0 / m_grid.dx();
        const Array3<double>& faces = m_grid.velocity(a);
        const int n_b = m_grid.cells(b);
        std::array<int, 3> hi = edge;  // face of component a just above the edge along b
        std::array<int, 3> lo = edge;
        --lo[b];
        if (edge[b] == 0 || edge[b] == n_b) {
            const int side = edge[b] == 0 ? 0 : 1;
            if (m_walls.at(b, side) == WallType::free_slip) {
                return false;
            }
            // No-slip: the ghost is minus the interior face, so ∂/∂x_b = ±2 u_interior / dx.
            const std::array<int, 3>& inside = side == 0 ? hi : lo;
            const double sign = side == 0 ? 1.0 : -1.0;
            term.add(a, faces.index(inside[0], inside[1], inside[2]), sign * 2.0 * inv_dx);
            return true;
        }
        term.add(a, faces.index(hi[0], hi[1], hi[2]), inv_dx);
        term.add(a, faces.index(lo[0], lo[1], lo[2]), -inv_dx);
        return true;
    }

    double edge_viscosity(const std::array<int, 3>& edge, int a, int b) const {
        double sum = 0.0;
        int count = 0;
        for (int da = -1; da <= 0; ++da) {
            for (int db = -1; db <= 0; ++db) {
                std::array<int, 3> cell = edge;
                cell[a] += da;
                cell[b] += db;
                if (m_mu.contains(cell[0], cell[1], cell[2])) {
                    sum += m_mu(cell[0], cell[1], cell[2]);
                    ++count;
                }
            }
        }
        return count > 0 ? sum / count : 0.0;
    }

    /// Fraction of an edge's dual cell inside the box: ½ per wall the edge lies on.
    double edge_volume_fraction(const std::array<int, 3>& edge, int a, int b) const {
        double fraction = 1.0;
        for (int axis : {a, b}) {
            if (edge[axis] == 0 || edge[axis] == m_grid.cells(axis)) {
                fraction *= HALF;
            }
        }
        return fraction;
    }

    void shear_strain_terms(std::vector<Eigen::Triplet<double>>& triplets,
                            Eigen::VectorXd& rhs) const {
        for (int c = 0; c < 3; ++c) {
            const int a = (c + 1) % 3;
            const int b = (c + 2) % 3;
            std::array<int, 3> extent = {m_grid.nx() + 1, m_grid.ny() + 1, m_grid.nz() + 1};
            extent[c] -= 1;  // edges parallel to axis c sit at cell-centre height along c
            std::array<int, 3> edge;
            for (edge[2] = 0; edge[2] < extent[2]; ++edge[2]) {
                for (edge[1] = 0; edge[1] < extent[1]; ++edge[1]) {
                    for (edge[0] = 0; edge[0] < extent[0]; ++edge[0]) {
                        StrainTerm term;
                        if (!add_derivative(a, b, edge, term) ||
                            !add_derivative(b, a, edge, term)) {
                            continue;
                        }
                        add_term(term,
                                 SHEAR_WEIGHT * edge_volume_fraction(edge, a, b) *
                                     edge_viscosity(edge, a, b),
                                 triplets, rhs);
                    }
                }
            }
        }
    }

    const MacGrid& m_grid;
    const Array3<double>& m_phi;
    const PhaseOptions& m_phases;
    FluidMode m_mode;
    const WallOptions& m_walls;
    double m_dt;
    std::array<std::vector<std::int64_t>, 3> m_unknown;
    std::int64_t m_count = 0;
    Array3<double> m_mu;
};

}  // namespace

void ViscosityOptions::validate() const {
    iteration.validate();
}

SolveResult apply_viscosity(MacGrid& grid, const InterfaceInput& interface,
                            const PhaseOptions& phases, FluidMode mode, const WallOptions& walls,
                            double dt, const ViscosityOptions& options) {
    options.validate();
    walls.validate();
    interface.validate(grid);
    if (!(dt > 0.0)) {
        throw std::invalid_argument("apply_viscosity: dt must be positive (s)");
    }
    SolveResult result;
    const double mu_gas = mode == FluidMode::two_phase ? phases.mu_gas : 0.0;
    if (!options.enabled || (phases.mu_liquid == 0.0 && mu_gas == 0.0)) {
        result.converged = true;
        return result;
    }
    ViscousSystem system(grid, interface, phases, mode, walls, dt);
    if (system.unknown_count() == 0) {
        result.converged = true;
        return result;
    }
    Eigen::SparseMatrix<double> matrix;
    Eigen::VectorXd rhs, guess;
    system.assemble(matrix, rhs, guess);
    Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> solver;
    solver.setTolerance(options.iteration.tolerance);
    solver.setMaxIterations(options.iteration.max_iterations);
    solver.compute(matrix);
    const Eigen::VectorXd solution = solver.solveWithGuess(rhs, guess);
    result.iterations = static_cast<int>(solver.iterations());
    result.residual = solver.error();
    result.converged =
        solver.info() == Eigen::Success && result.residual <= options.iteration.tolerance;
    system.scatter(solution, grid);
    return result;
}

}  // namespace meniscus::fluid
