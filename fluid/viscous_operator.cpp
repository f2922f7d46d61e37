#include "fluid/viscous_operator.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>

#include "fluid/surface_viscosity.h"

namespace meniscus::fluid {

namespace {

/// Faces per task of apply_dot()'s sum: dot()'s split (poisson_matrix.cpp), so the same value.
constexpr std::size_t DOT_GRAIN = 16384;
/// Weight of a shear strain-rate term: 2 μ ε_ab² = ½ μ (∂_b u_a + ∂_a u_b)².
constexpr double SHEAR_WEIGHT = 0.5;
constexpr double HALF = 0.5;
/// A no-slip wall mirrors the tangential velocity: the one-sided derivative doubles.
constexpr double MIRROR_FACTOR = 2.0;
/// The part of an outflow face's control volume inside the box.
constexpr double OUTFLOW_VOLUME_FRACTION = 0.5;

}  // namespace

using Index3 = ViscousOperator::Index3;

template <class Visit>
void ViscousOperator::for_each_face(int a, Visit&& visit) const {
    const Index3& dims = m_face_dims[a];
    tbb::parallel_for(tbb::blocked_range<int>(0, dims[2]), [&](const tbb::blocked_range<int>& r) {
        for (int k = r.begin(); k != r.end(); ++k) {
            for (int j = 0; j < dims[1]; ++j) {
                for (int i = 0; i < dims[0]; ++i) {
                    const Index3 f = {i, j, k};
                    if (!solvable(a, f)) {
                        continue;
                    }
                    visit(f, face_flat(a, f));
                }
            }
        }
    });
}

template <typename Visit>
void ViscousOperator::for_each_edge_cell(const Index3& e, int a, int b, Visit&& visit) const {
    for (int da = -1; da <= 0; ++da) {
        for (int db = -1; db <= 0; ++db) {
            Index3 cell = e;
            cell[a] += da;
            cell[b] += db;
            for (int axis : {a, b})  // around the seam's edge the last cells
                if (cell[axis] < 0 && periodic(axis))
                    cell[axis] += m_n[axis];
            if (m_mu.contains(cell[0], cell[1], cell[2]))
                visit(cell);
        }
    }
}

void ViscousOperator::build(const MacGrid& grid, const Array3<double>& phi,
                            const PhaseOptions& phases, FluidMode mode,
                            const BoundaryOptions& walls, double dt, double min_liquid_fraction,
                            ViscosityWeights weights, const SurfaceViscosity* surface) {
    m_n = {grid.nx(), grid.ny(), grid.nz()};
    m_dx = grid.dx();
    m_dt = dt;
    m_surface = surface;
    for (int a = 0; a < 3; ++a) {
        for (int side = 0; side < 2; ++side)
            m_open[a][side] = walls.at(a, side) == BoundaryType::outflow;
        m_periodic[static_cast<std::size_t>(a)] = walls.periodic(a);
    }
    // The surface term's energy ½ Δt μ_s (S u)ᵀ L (S u), per cell volume as the rest.
    m_surface_scale = surface ? dt * surface->viscosity / (m_dx * m_dx * m_dx) : 0.0;
    std::size_t offset = 0;
    for (int a = 0; a < 3; ++a) {
        m_face_dims[a] = m_n;
        ++m_face_dims[a][a];
        m_offset[a] = offset;
        offset += grid.velocity(a).size();
        Index3 edge_dims = {m_n[0] + 1, m_n[1] + 1, m_n[2] + 1};
        --edge_dims[a];  // edges parallel to axis a
        m_edge_weight[a].resize(edge_dims[0], edge_dims[1], edge_dims[2], 0.0);
        m_shear_stress[a].resize(edge_dims[0], edge_dims[1], edge_dims[2], 0.0);
        m_normal_stress[a].resize(m_n[0], m_n[1], m_n[2], 0.0);
    }
    m_size = offset;
    m_mu.resize(m_n[0], m_n[1], m_n[2]);
    m_fraction_weights =
        mode == FluidMode::free_surface || weights == ViscosityWeights::volume_fraction;
    m_pointwise_edges = mode == FluidMode::two_phase && weights == ViscosityWeights::pointwise;
    m_mu_gas = mode == FluidMode::two_phase ? phases.mu_gas : 0.0;
    for (std::size_t c = 0; c < m_mu.size(); ++c) {
        m_mu[c] = m_fraction_weights ? blended_mu(phases.mu_liquid, control_volume_fraction(phi[c]))
                                     : (is_liquid(phi[c]) ? phases.mu_liquid : m_mu_gas);
    }
    set_edge_weights(walls, phi, phases);
    set_faces(phi, phases, mode, min_liquid_fraction);
}

void ViscousOperator::gather(const MacGrid& grid, std::vector<double>& x) const {
    x.resize(m_size);
    for (int a = 0; a < 3; ++a) {
        const std::vector<double>& faces = grid.velocity(a).storage();
        std::copy(faces.begin(), faces.end(), x.begin() + m_offset[a]);
    }
}

void ViscousOperator::scatter(const std::vector<double>& x, MacGrid& grid) const {
    for (int a = 0; a < 3; ++a) {
        std::vector<double>& faces = grid.velocity(a).storage();
        std::copy(x.begin() + m_offset[a], x.begin() + m_offset[a] + faces.size(), faces.begin());
    }
}

void ViscousOperator::stiffness(const std::vector<double>& x, std::vector<double>& y,
                                const BoundaryOptions* moving) const {
    y.resize(m_size);
    normal_stresses(x);
    shear_stresses(x, moving);
    stress_divergence(y);
    if (m_surface)
        m_surface->add_stiffness(m_surface_scale, x, y);
}

void ViscousOperator::apply(const std::vector<double>& x, std::vector<double>& y) const {
    apply_dot(x, y);
}

double ViscousOperator::apply_dot(const std::vector<double>& x, std::vector<double>& y) const {
    if (!m_surface) {
        // The mass term, the restriction to the unknowns and x·y in the divergence's own pass.
        y.resize(m_size);
        normal_stresses(x);
        shear_stresses(x, nullptr);
        return stress_divergence(y, &x);
    }
    stiffness(x, y);
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, m_size, DOT_GRAIN), 0.0,
        [&](const tbb::blocked_range<std::size_t>& r, double sum) {
            for (std::size_t f = r.begin(); f != r.end(); ++f) {
                y[f] = m_unknown[f] ? y[f] + m_density[f] * x[f] : 0.0;
                sum += x[f] * y[f];
            }
            return sum;
        },
        std::plus<double>());
}

ViscousOperator::FaceReach ViscousOperator::face_reach(int a) const {
    FaceReach reach;
    reach.cell_step = a == 0   ? 1
                      : a == 1 ? static_cast<std::size_t>(m_n[0])
                               : static_cast<std::size_t>(m_n[0]) * m_n[1];
    for (int b = 0, t = 0; b < 3; ++b) {
        if (b == a)
            continue;
        const Array3<double>& edges = m_edge_weight[3 - a - b];
        reach.other[t] = b;
        reach.edge_step[t] = b == 0   ? 1
                             : b == 1 ? static_cast<std::size_t>(edges.ni())
                                      : static_cast<std::size_t>(edges.ni()) * edges.nj();
        ++t;
    }
    return reach;
}

bool ViscousOperator::row_inside(int a, int j, int k) const {
    const Index3 row = {0, j, k};
    bool inside = true;
    for (int axis = 1; axis < 3; ++axis) {
        const int limit = axis == a ? m_n[a] - 1 : m_n[axis] - 2;
        inside = inside && row[axis] >= 1 && row[axis] <= limit;
    }
    return inside;
}

void ViscousOperator::diagonal(std::vector<double>& d, bool with_surface) const {
    d.assign(m_size, 1.0);
    const double inv_dx2 = 1.0 / (m_dx * m_dx);
    for (int a = 0; a < 3; ++a) {
        // The faces whose cells and edges are all inside the box (no wall, seam or outflow):
        // the general case's operations in the same order, by flat index along the rows.
        const Index3& dims = m_face_dims[a];
        const FaceReach reach = face_reach(a);
        const std::size_t cell_step = reach.cell_step;
        const std::array<int, 2>& other = reach.other;
        const std::array<std::size_t, 2>& edge_step = reach.edge_step;
        const double* mu = m_mu.data();
        const double* weight0 = m_edge_weight[3 - a - other[0]].data();
        const double* weight1 = m_edge_weight[3 - a - other[1]].data();
        const double edge_scale = 2.0 * m_dt * inv_dx2;
        tbb::parallel_for(
            tbb::blocked_range<int>(0, dims[2]), [&](const tbb::blocked_range<int>& r) {
                for (int k = r.begin(); k != r.end(); ++k)
                    for (int j = 0; j < dims[1]; ++j) {
                        if (!row_inside(a, j, k))
                            continue;
                        const int end = a == 0 ? m_n[0] : m_n[0] - 1;
                        const std::size_t face_row = face_flat(a, {0, j, k});
                        const std::size_t cell_row =
                            static_cast<std::size_t>(m_n[0]) *
                            (static_cast<std::size_t>(j) + static_cast<std::size_t>(m_n[1]) * k);
                        const std::size_t edge_row0 =
                            m_edge_weight[3 - a - other[0]].index(0, j, k);
                        const std::size_t edge_row1 =
                            m_edge_weight[3 - a - other[1]].index(0, j, k);
                        for (int i = 1; i < end; ++i) {
                            const std::size_t flat = face_row + static_cast<std::size_t>(i);
                            if (!m_unknown[flat])
                                continue;
                            const std::size_t cell = cell_row + static_cast<std::size_t>(i);
                            double sum = m_density[flat] +
                                         2.0 * m_dt * (mu[cell - cell_step] + mu[cell]) * inv_dx2;
                            const std::size_t e0 = edge_row0 + static_cast<std::size_t>(i);
                            sum += edge_scale * (weight0[e0] + weight0[e0 + edge_step[0]]);
                            const std::size_t e1 = edge_row1 + static_cast<std::size_t>(i);
                            sum += edge_scale * (weight1[e1] + weight1[e1 + edge_step[1]]);
                            d[flat] = sum;
                        }
                    }
            });
        for_each_face(a, [&](const Index3& f, std::size_t flat) {
            if (!m_unknown[flat]) {
                return;
            }
            const int last = a == 0 ? m_n[0] - 1 : m_n[0] - 2;
            if (f[0] >= 1 && f[0] <= last && row_inside(a, f[1], f[2]))
                return;  // done above
            Index3 lo = f;
            --lo[a];
            // An outflow face has its cell on one side only.
            if (f[a] == 0 && periodic(a))
                lo[a] = m_n[a] - 1;  // the seam
            const double mu_lo = lo[a] >= 0 ? m_mu(lo[0], lo[1], lo[2]) : 0.0;
            const double mu_hi = f[a] < m_n[a] ? m_mu(f[0], f[1], f[2]) : 0.0;
            double sum = m_density[flat] + 2.0 * m_dt * (mu_lo + mu_hi) * inv_dx2;
            for (int b = 0; b < 3; ++b) {
                if (b == a) {
                    continue;
                }
                const Array3<double>& weight = m_edge_weight[3 - a - b];
                Index3 above = f;
                ++above[b];
                const bool wrap = periodic(b);
                const double c_below = (f[b] == 0 && !wrap ? MIRROR_FACTOR : 1.0);
                const double c_above = (above[b] == m_n[b] && !wrap ? MIRROR_FACTOR : 1.0);
                if (above[b] == m_n[b] && wrap)
                    above[b] = 0;  // the seam's edge
                sum += 2.0 * m_dt * inv_dx2 *
                       (weight(f[0], f[1], f[2]) * c_below * c_below +
                        weight(above[0], above[1], above[2]) * c_above * c_above);
            }
            d[flat] = sum;
        });
    }
    if (m_surface && with_surface) {
        std::vector<double> surface(m_size, 0.0);
        m_surface->add_diagonal_bound(m_surface_scale, surface);
        for (std::size_t f = 0; f < m_size; ++f)
            if (m_unknown[f])
                d[f] += surface[f];
    }
}

void ViscousOperator::component_blocks(const std::vector<double>& d,
                                       std::array<PoissonMatrix, 3>& blocks) const {
    const double scale = 2.0 * m_dt / (m_dx * m_dx);
    for (int a = 0; a < 3; ++a) {
        const Index3& dims = m_face_dims[a];
        PoissonMatrix& m = blocks[static_cast<std::size_t>(a)];
        m.resize(dims[0], dims[1], dims[2]);
        Array3<double>* off[3] = {&m.off_x, &m.off_y, &m.off_z};
        for_each_face(a, [&](const Index3& f, std::size_t flat) {
            if (!m_unknown[flat])
                return;
            m.diag(f[0], f[1], f[2]) = d[flat];
            for (int b = 0; b < 3; ++b) {
                Index3 next = f;
                ++next[b];
                if (next[b] >= dims[b] || !m_unknown[face_flat(a, next)])
                    continue;
                // Along a the two faces share cell f; across b the edge between them.
                const double weight = b == a ? m_mu(f[0], f[1], f[2])
                                             : m_edge_weight[3 - a - b](next[0], next[1], next[2]);
                (*off[b])(f[0], f[1], f[2]) = -scale * weight;
            }
        });
    }
}

double ViscousOperator::control_volume_fraction(double phi) const {
    return std::clamp(HALF - phi / m_dx, 0.0, 1.0);
}

double ViscousOperator::blended_mu(double mu_liquid, double fraction) const {
    return m_mu_gas + (mu_liquid - m_mu_gas) * fraction;
}

void ViscousOperator::set_edge_weights(const BoundaryOptions& walls, const Array3<double>& phi,
                                       const PhaseOptions& phases) {
    for (int c = 0; c < 3; ++c) {
        const int a = (c + 1) % 3;
        const int b = (c + 2) % 3;
        Array3<double>& weight = m_edge_weight[c];
        // Cell-array steps along a and b: an edge inside the box along both has its 4 cells at
        // its own cell index less 0 or 1 step along each.
        const std::size_t step_a = a == 0 ? 1 : (a == 1 ? m_mu.ni() : m_mu.ni() * m_mu.nj());
        const std::size_t step_b = b == 0 ? 1 : (b == 1 ? m_mu.ni() : m_mu.ni() * m_mu.nj());
        // The 4 cells in for_each_edge_cell()'s order (so the sums are the same).
        const std::array<std::size_t, 4> around = {step_a + step_b, step_a, step_b, 0};
        // W_e from the mean φ of the edge's cells (fraction or pointwise weights) and from the
        // sum of their 1/μ (harmonic weights; 0 when one is inviscid), `fraction` of the edge's
        // dual cell inside the box.
        const auto phase_weight = [&](double phi_edge, double fraction) {
            return SHEAR_WEIGHT * fraction *
                   (m_pointwise_edges
                        ? (is_liquid(phi_edge) ? phases.mu_liquid : m_mu_gas)
                        : blended_mu(phases.mu_liquid, control_volume_fraction(phi_edge)));
        };
        const auto harmonic_weight = [&](double inverse_sum, int count, double fraction,
                                         bool inviscid) {
            return inviscid ? 0.0 : SHEAR_WEIGHT * fraction * count / inverse_sum;
        };
        constexpr int EDGE_CELLS = 4;
        tbb::parallel_for(
            tbb::blocked_range<int>(0, weight.nk()), [&](const tbb::blocked_range<int>& r) {
                for (int k = r.begin(); k != r.end(); ++k) {
                    for (int j = 0; j < weight.nj(); ++j) {
                        for (int i = 0; i < weight.ni(); ++i) {
                            const Index3 e = {i, j, k};
                            if (e[a] > 0 && e[a] < m_n[a] && e[b] > 0 && e[b] < m_n[b]) {
                                // Inside the box: whole dual cell, no wall, no seam.
                                const std::size_t cell = m_mu.index(i, j, k);
                                if (m_fraction_weights || m_pointwise_edges) {
                                    double phi_sum = 0.0;
                                    for (std::size_t back : around)
                                        phi_sum += phi[cell - back];
                                    weight(i, j, k) = phase_weight(phi_sum / EDGE_CELLS, 1.0);
                                } else {
                                    double inverse_sum = 0.0;
                                    bool inviscid = false;
                                    for (std::size_t back : around) {
                                        const double mu = m_mu[cell - back];
                                        inviscid |= mu == 0.0;
                                        inverse_sum += inviscid ? 0.0 : 1.0 / mu;
                                    }
                                    weight(i, j, k) =
                                        harmonic_weight(inverse_sum, EDGE_CELLS, 1.0, inviscid);
                                }
                                continue;
                            }
                            double fraction = 1.0;
                            bool free_slip = false;
                            bool copy = false;  // the seam's edge at n, a copy of the one at 0
                            for (int axis : {a, b}) {
                                if (periodic(axis)) {
                                    copy |= e[axis] == m_n[axis];
                                    continue;
                                }
                                if (e[axis] == 0 || e[axis] == m_n[axis]) {
                                    fraction *= HALF;  // half the edge's dual cell is outside
                                    const int side = e[axis] == 0 ? 0 : 1;
                                    free_slip |= walls.at(axis, side) == BoundaryType::free_slip;
                                }
                            }
                            if (free_slip || copy) {
                                continue;  // zero shear stress on a free-slip wall
                            }
                            if (m_fraction_weights || m_pointwise_edges) {
                                // Batty & Bridson 2008: the shear term weighted by the liquid
                                // fraction of the edge's control volume (φ at the edge: the mean of
                                // its cells), so a traction-free surface sits where φ = 0, not on
                                // the cell faces next to the void. Pointwise: the μ of the phase
                                // at the edge's midpoint, by the sign of the same φ.
                                double phi_sum = 0.0;
                                int count = 0;
                                for_each_edge_cell(e, a, b, [&](const Index3& cell) {
                                    phi_sum += phi(cell[0], cell[1], cell[2]);
                                    ++count;
                                });
                                weight(i, j, k) = phase_weight(phi_sum / count, fraction);
                                continue;
                            }
                            // Harmonic mean of the (up to 4) cells around the edge: exact for the
                            // shear stress across a layer interface through the edge; 0 next to a
                            // cell with μ = 0.
                            double inverse_sum = 0.0;
                            int count = 0;
                            bool inviscid = false;
                            for_each_edge_cell(e, a, b, [&](const Index3& cell) {
                                const double mu = m_mu(cell[0], cell[1], cell[2]);
                                inviscid |= mu == 0.0;
                                inverse_sum += inviscid ? 0.0 : 1.0 / mu;
                                ++count;
                            });
                            weight(i, j, k) =
                                harmonic_weight(inverse_sum, count, fraction, inviscid);
                        }
                    }
                }
            });
    }
}

void ViscousOperator::set_faces(const Array3<double>& phi, const PhaseOptions& phases,
                                FluidMode mode, double min_liquid_fraction) {
    m_unknown.assign(m_size, 0);
    m_density.assign(m_size, 0.0);
    // ρ_f of a face whose liquid fraction is θ; a face between two cells of one phase (θ exactly
    // 1 or 0, most of the grid's) takes it from the two made once.
    const auto density_of = [&](double theta) {
        return mode == FluidMode::free_surface
                   ? phases.rho_liquid * std::max(theta, min_liquid_fraction)
                   : face_density(theta, phases, mode);
    };
    const double liquid_density = density_of(1.0), gas_density = density_of(0.0);
    for (int a = 0; a < 3; ++a) {
        for_each_face(a, [&](const Index3& f, std::size_t flat) {
            Index3 lo = f;
            --lo[a];
            // An outflow face takes the phase of its one cell.
            Index3 hi = f;
            const bool seam = periodic(a) && f[a] == 0;
            if (seam)
                lo[a] = m_n[a] - 1;
            else if (f[a] == 0)
                lo = hi;
            if (f[a] == m_n[a])
                hi = lo;
            const double phi_lo = phi(lo[0], lo[1], lo[2]);
            const double phi_hi = phi(hi[0], hi[1], hi[2]);
            const bool liquid_lo = is_liquid(phi_lo);
            const bool liquid_hi = is_liquid(phi_hi);
            if (mode == FluidMode::free_surface && !liquid_lo && !liquid_hi) {
                return;
            }
            m_unknown[flat] = 1;
            m_density[flat] = liquid_lo != liquid_hi ? density_of(liquid_fraction(phi_lo, phi_hi))
                              : liquid_lo            ? liquid_density
                                                     : gas_density;
            // An outflow face's control volume is the half cell inside the box, like the
            // half dual cells of the shear terms on it and the pressure's distance Δx/2.
            if ((f[a] == 0 && !seam) || f[a] == m_n[a])
                m_density[flat] *= OUTFLOW_VOLUME_FRACTION;
        });
    }
}

void ViscousOperator::normal_stresses(const std::vector<double>& x) const {
    const double scale = 2.0 * m_dt / m_dx;
    for (int a = 0; a < 3; ++a) {
        Array3<double>& sigma = m_normal_stress[a];
        const std::size_t step = face_stride(a, a);
        // The cell below the face at n along a periodic a takes the seam's face at 0 as its hi.
        const std::size_t seam_back = static_cast<std::size_t>(m_n[a] - 1) * step;
        const bool wrap = periodic(a);
        tbb::parallel_for(
            tbb::blocked_range<int>(0, m_n[2]), [&](const tbb::blocked_range<int>& r) {
                for (int k = r.begin(); k != r.end(); ++k) {
                    for (int j = 0; j < m_n[1]; ++j) {
                        const std::size_t face_row = face_flat(a, {0, j, k});
                        const std::size_t cell_row = sigma.index(0, j, k);
                        const int row_along = a == 1 ? j : k;  // the row's index along a ≠ 0
                        for (int i = 0; i < m_n[0]; ++i) {
                            const std::size_t lo = face_row + static_cast<std::size_t>(i);
                            const int along = a == 0 ? i : row_along;
                            const std::size_t hi =
                                wrap && along + 1 == m_n[a] ? lo - seam_back : lo + step;
                            sigma[cell_row + i] = scale * m_mu[cell_row + i] * (x[hi] - x[lo]);
                        }
                    }
                }
            });
    }
}

std::size_t ViscousOperator::face_stride(int a, int axis) const {
    const Index3& d = m_face_dims[a];
    return axis == 0   ? 1
           : axis == 1 ? static_cast<std::size_t>(d[0])
                       : static_cast<std::size_t>(d[0]) * d[1];
}

void ViscousOperator::shear_stresses(const std::vector<double>& x,
                                     const BoundaryOptions* moving) const {
    for (int c = 0; c < 3; ++c) {
        const int a = (c + 1) % 3;
        const int b = (c + 2) % 3;
        // The walls' velocity components along the derivative's numerator: x_a at the b
        // walls, x_b at the a walls.
        const auto wall = [&](int axis, int side, int component) {
            return moving ? moving->face(axis, side).velocity[component] : 0.0;
        };
        const double a_lo = wall(b, 0, a), a_hi = wall(b, 1, a);
        const double b_lo = wall(a, 0, b), b_hi = wall(a, 1, b);
        const Array3<double>& weight = m_edge_weight[c];
        Array3<double>& tau = m_shear_stress[c];
        const std::size_t step_a = face_stride(a, b);  // x_a along b
        const std::size_t step_b = face_stride(b, a);  // x_b along a
        const int n_a = m_n[a];
        const int n_b = m_n[b];
        const bool wrap_a = periodic(a), wrap_b = periodic(b);
        // Across a periodic seam (an edge at 0) the derivative reaches back to the last face.
        const std::size_t seam_a = static_cast<std::size_t>(n_b - 1) * step_a;
        const std::size_t seam_b = static_cast<std::size_t>(n_a - 1) * step_b;
        tbb::parallel_for(
            tbb::blocked_range<int>(0, weight.nk()), [&](const tbb::blocked_range<int>& r) {
                for (int k = r.begin(); k != r.end(); ++k) {
                    for (int j = 0; j < weight.nj(); ++j) {
                        // Face indices of (0, j, k) in arrays a and b (an index one past
                        // an array's end on axis b or a is only ever used minus its step).
                        const std::size_t row_a = face_flat(a, {0, j, k});
                        const std::size_t row_b = face_flat(b, {0, j, k});
                        const std::size_t edge_row = weight.index(0, j, k);
                        // The edges of the row whose derivatives reach no wall, seam or
                        // outflow (i in [fast_begin, fast_end)): both differences inside.
                        const Index3 row = {0, j, k};
                        bool inside = true;
                        for (const auto& [axis, n_axis] : {std::pair{a, n_a}, std::pair{b, n_b}})
                            if (axis != 0)
                                inside = inside && row[axis] >= 1 && row[axis] <= n_axis - 1;
                        const int fast_begin = !inside ? weight.ni() : (a == 0 || b == 0 ? 1 : 0);
                        const int fast_end = !inside ? weight.ni() : m_n[0];
                        for (int i = fast_begin; i < fast_end; ++i) {
                            // Same operations, in the same order, as the general case below.
                            const double w = weight[edge_row + i];
                            const std::size_t fa = row_a + i;
                            const std::size_t fb = row_b + i;
                            const double d_ab = (x[fa] - x[fa - step_a]) / m_dx;
                            const double d_ba = (x[fb] - x[fb - step_b]) / m_dx;
                            tau[edge_row + i] = w == 0.0 ? 0.0 : 2.0 * m_dt * w * (d_ab + d_ba);
                        }
                        for (int i = 0; i < weight.ni(); ++i) {
                            if (i == fast_begin)
                                i = fast_end;  // done above
                            if (i >= weight.ni())
                                break;
                            const double w = weight[edge_row + i];
                            if (w == 0.0) {
                                tau[edge_row + i] = 0.0;
                                continue;
                            }
                            const Index3 e = {i, j, k};
                            const std::size_t fa = row_a + i;
                            const std::size_t fb = row_b + i;
                            const double d_ab =
                                e[b] == 0 && wrap_b ? (x[fa] - x[fa + seam_a]) / m_dx
                                : e[b] == 0         ? MIRROR_FACTOR * (x[fa] - a_lo) / m_dx
                                : e[b] == n_b ? -MIRROR_FACTOR * (x[fa - step_a] - a_hi) / m_dx
                                              : (x[fa] - x[fa - step_a]) / m_dx;
                            const double d_ba =
                                e[a] == 0 && wrap_a ? (x[fb] - x[fb + seam_b]) / m_dx
                                : e[a] == 0         ? MIRROR_FACTOR * (x[fb] - b_lo) / m_dx
                                : e[a] == n_a ? -MIRROR_FACTOR * (x[fb - step_b] - b_hi) / m_dx
                                              : (x[fb] - x[fb - step_b]) / m_dx;
                            tau[edge_row + i] = 2.0 * m_dt * w * (d_ab + d_ba);
                        }
                    }
                }
            });
    }
}

double ViscousOperator::stress_divergence(std::vector<double>& y,
                                          const std::vector<double>* x) const {
    const double inv_dx = 1.0 / m_dx;
    // With x: y_f = ρ_f x_f + (K x)_f on the unknowns, 0 elsewhere, and x·y summed per face
    // layer (each layer in its own order, the layers in theirs: the same for any thread count).
    const char* unknown = m_unknown.data();
    const double* density = m_density.data();
    const double* xs = x ? x->data() : nullptr;
    const auto finish = [&](std::size_t flat, double sum, double& dot) {
        if (!xs)
            return sum;
        const double value = unknown[flat] ? sum + density[flat] * xs[flat] : 0.0;
        dot += xs[flat] * value;
        return value;
    };
    std::vector<double>& layer_dots = m_layer_dots;
    layer_dots.assign(
        static_cast<std::size_t>(m_face_dims[0][2] + m_face_dims[1][2] + m_face_dims[2][2]), 0.0);
    std::size_t layer_offset = 0;
    for (int a = 0; a < 3; ++a) {
        const Array3<double>& sigma = m_normal_stress[a];
        const Index3& dims = m_face_dims[a];
        // The two shear arrays this component meets, in the order b = 0, 1, 2 (b ≠ a).
        const FaceReach reach = face_reach(a);
        const std::size_t cell_step = reach.cell_step;
        const std::array<int, 2>& other = reach.other;
        const std::array<std::size_t, 2>& edge_step = reach.edge_step;
        tbb::parallel_for(
            tbb::blocked_range<int>(0, dims[2]), [&](const tbb::blocked_range<int>& r) {
                for (int k = r.begin(); k != r.end(); ++k) {
                    double layer_dot = 0.0;
                    for (int j = 0; j < dims[1]; ++j) {
                        const std::size_t face_row = face_flat(a, {0, j, k});
                        // The faces of the row whose cells, below and above, and edges, below
                        // and above along both other axes, are all inside the box: no seam,
                        // wall or outflow to treat (i in [fast_begin, fast_end)).
                        const bool inside = row_inside(a, j, k);
                        const int fast_begin = inside ? 1 : dims[0];
                        const int fast_end =
                            inside ? std::max(fast_begin, a == 0 ? m_n[0] : m_n[0] - 1) : dims[0];
                        const std::size_t cell_row =
                            static_cast<std::size_t>(m_n[0]) *
                            (static_cast<std::size_t>(j) + static_cast<std::size_t>(m_n[1]) * k);
                        const Array3<double>& tau0 = m_shear_stress[3 - a - other[0]];
                        const Array3<double>& tau1 = m_shear_stress[3 - a - other[1]];
                        const std::size_t tau0_row = tau0.index(0, j, k);
                        const std::size_t tau1_row = tau1.index(0, j, k);
                        for (int i = fast_begin; i < fast_end; ++i) {
                            // Same operations, in the same order, as the general case below.
                            const std::size_t cell = cell_row + static_cast<std::size_t>(i);
                            double sum = 0.0;
                            sum += sigma[cell - cell_step] * inv_dx;
                            sum -= sigma[cell] * inv_dx;
                            const std::size_t below0 = tau0_row + static_cast<std::size_t>(i);
                            sum += tau0[below0] * inv_dx + tau0[below0 + edge_step[0]] * -inv_dx;
                            const std::size_t below1 = tau1_row + static_cast<std::size_t>(i);
                            sum += tau1[below1] * inv_dx + tau1[below1 + edge_step[1]] * -inv_dx;
                            y[face_row + i] = finish(face_row + i, sum, layer_dot);
                        }
                        for (int i = 0; i < dims[0]; ++i) {
                            if (i == fast_begin)
                                i = fast_end;  // done above
                            if (i >= dims[0])
                                break;
                            const Index3 f = {i, j, k};
                            if (!solvable(a, f)) {
                                if (xs)
                                    y[face_row + i] = 0.0;
                                continue;
                            }
                            // Cell f lies above the face, cell f − e_a below it (an outflow
                            // face has one of them). The flat index of f is formed without
                            // the array's bounds: on the max face only cell − step is read.
                            const std::size_t cell = static_cast<std::size_t>(i) +
                                                     static_cast<std::size_t>(m_n[0]) *
                                                         (static_cast<std::size_t>(j) +
                                                          static_cast<std::size_t>(m_n[1]) * k);
                            double sum = 0.0;
                            if (f[a] > 0)
                                sum += sigma[cell - cell_step] * inv_dx;
                            else if (periodic(a))  // the seam: the last cell below it
                                sum += sigma[cell + (m_n[a] - 1) * cell_step] * inv_dx;
                            if (f[a] < m_n[a])
                                sum -= sigma[cell] * inv_dx;
                            for (int t = 0; t < 2; ++t) {
                                const int b = other[t];
                                const Array3<double>& tau = m_shear_stress[3 - a - b];
                                const std::size_t below = tau.index(i, j, k);
                                // Across a periodic b the edge above the last face is the
                                // seam's, at 0; no wall there to mirror.
                                const bool wrap = periodic(b);
                                const bool last = f[b] + 1 == m_n[b];
                                const std::size_t above = wrap && last ? below - f[b] * edge_step[t]
                                                                       : below + edge_step[t];
                                const double c_below =
                                    (f[b] == 0 && !wrap ? MIRROR_FACTOR : 1.0) * inv_dx;
                                const double c_above =
                                    -(last && !wrap ? MIRROR_FACTOR : 1.0) * inv_dx;
                                sum += tau[below] * c_below + tau[above] * c_above;
                            }
                            y[face_row + i] = finish(face_row + i, sum, layer_dot);
                        }
                    }
                    layer_dots[layer_offset + static_cast<std::size_t>(k)] = layer_dot;
                }
            });
        layer_offset += static_cast<std::size_t>(dims[2]);
    }
    double total = 0.0;
    for (const double d : layer_dots)
        total += d;
    return total;
}

}  // namespace meniscus::fluid
