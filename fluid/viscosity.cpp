#include "fluid/viscosity.h"

#include "fluid/surface_viscosity.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "fluid/multigrid.h"
#include "fluid/poisson_matrix.h"

namespace meniscus::fluid {

namespace {

/// Weight of a shear strain-rate term: 2 μ ε_ab² = ½ μ (∂_b u_a + ∂_a u_b)².
constexpr double SHEAR_WEIGHT = 0.5;
constexpr double HALF = 0.5;
/// A no-slip wall mirrors the tangential velocity: the one-sided derivative doubles.
constexpr double MIRROR_FACTOR = 2.0;
/// The part of an outflow face's control volume inside the box.
constexpr double OUTFLOW_VOLUME_FRACTION = 0.5;

using Index3 = std::array<int, 3>;

/// Matrix-free operator of the backward-Euler viscous step on all face velocities, stored as one
/// flat vector [u | v | w] (each block in its Array3 layout). With the energy of viscosity.h,
///   A x = ρ_f x + K x,  K x = Dᵀ (2Δt W) D x,
/// where D maps face velocities to strain rates (cell centres and edges) and W holds μ_c or
/// ½ μ_e (× the dual-cell fraction inside the box). K x is evaluated in three TBB-parallel
/// passes: diagonal stresses at cells, shear stresses on edges, their divergence on faces.
class ViscousOperator {
public:
    /// (Re)builds the operator for a grid, interface and time step, reusing the arrays' memory.
    void build(const MacGrid& grid, const Array3<double>& phi, const PhaseOptions& phases,
               FluidMode mode, const BoundaryOptions& walls, double dt, double min_liquid_fraction,
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
            m_mu[c] = m_fraction_weights
                          ? blended_mu(phases.mu_liquid, control_volume_fraction(phi[c]))
                          : (is_liquid(phi[c]) ? phases.mu_liquid : m_mu_gas);
        }
        set_edge_weights(walls, phi, phases);
        set_faces(phi, phases, mode, min_liquid_fraction);
    }

    std::size_t size() const { return m_size; }
    const std::vector<char>& unknown() const { return m_unknown; }
    const std::vector<double>& density() const { return m_density; }

    /// Flat vector [u | v | w] of the grid's face velocities.
    void gather(const MacGrid& grid, std::vector<double>& x) const {
        x.resize(m_size);
        for (int a = 0; a < 3; ++a) {
            const std::vector<double>& faces = grid.velocity(a).storage();
            std::copy(faces.begin(), faces.end(), x.begin() + m_offset[a]);
        }
    }

    void scatter(const std::vector<double>& x, MacGrid& grid) const {
        for (int a = 0; a < 3; ++a) {
            std::vector<double>& faces = grid.velocity(a).storage();
            std::copy(x.begin() + m_offset[a], x.begin() + m_offset[a] + faces.size(),
                      faces.begin());
        }
    }

    /// y = K x on every interior face (entries on wall-normal faces are left unspecified). With
    /// `moving` walls the shear strain next to a no-slip wall is taken relative to the wall's
    /// velocity, which makes the map affine: use it only for the right-hand side.
    void stiffness(const std::vector<double>& x, std::vector<double>& y,
                   const BoundaryOptions* moving = nullptr) const {
        y.resize(m_size);
        normal_stresses(x);
        shear_stresses(x, moving);
        stress_divergence(y);
        if (m_surface)
            m_surface->add_stiffness(m_surface_scale, x, y);
    }

    /// y = (ρ + K) x restricted to the unknowns (x must vanish on fixed faces; y does too).
    void apply(const std::vector<double>& x, std::vector<double>& y) const {
        stiffness(x, y);
        for (std::size_t f = 0; f < m_size; ++f) {
            y[f] = m_unknown[f] ? y[f] + m_density[f] * x[f] : 0.0;
        }
    }

    /// Diagonal of ρ + K on the unknowns (1 on fixed faces), for Jacobi preconditioning.
    void diagonal(std::vector<double>& d) const {
        d.assign(m_size, 1.0);
        const double inv_dx2 = 1.0 / (m_dx * m_dx);
        for (int a = 0; a < 3; ++a) {
            for_each_face(a, [&](const Index3& f, std::size_t flat) {
                if (!m_unknown[flat]) {
                    return;
                }
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
        if (m_surface) {
            std::vector<double> surface(m_size, 0.0);
            m_surface->add_diagonal_bound(m_surface_scale, surface);
            for (std::size_t f = 0; f < m_size; ++f)
                if (m_unknown[f])
                    d[f] += surface[f];
        }
    }

    /// The diagonal blocks of ρ + K, each velocity component coupled with itself alone (the
    /// normal-stress couplings through cells, the shear couplings through edges), as 7-point
    /// matrices on that component's face lattice: same diagonal `d` (diagonal()) as the whole
    /// operator, fixed faces inactive (zero rows and columns).
    void component_blocks(const std::vector<double>& d,
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
                    const double weight = b == a
                                              ? m_mu(f[0], f[1], f[2])
                                              : m_edge_weight[3 - a - b](next[0], next[1], next[2]);
                    (*off[b])(f[0], f[1], f[2]) = -scale * weight;
                }
            });
        }
    }

private:
    /// Calls visit(face index, flat index in [u|v|w]) for every face of component a that can be
    /// an unknown: the interior ones and those on an outflow face of the box.
    template <class Visit>
    void for_each_face(int a, Visit&& visit) const {
        const Index3& dims = m_face_dims[a];
        tbb::parallel_for(tbb::blocked_range<int>(0, dims[2]),
                          [&](const tbb::blocked_range<int>& r) {
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

    /// Is face f of component a inside the box or on one of its outflow faces?
    bool solvable(int a, const Index3& f) const {
        if (f[a] == 0)  // across a periodic axis the face at 0 is the seam; the one at n its copy
            return m_open[a][0] || periodic(a);
        return f[a] != m_n[a] || m_open[a][1];
    }

    std::size_t face_flat(int a, const Index3& f) const {
        const Index3& d = m_face_dims[a];
        return m_offset[a] + static_cast<std::size_t>(f[0]) +
               static_cast<std::size_t>(d[0]) *
                   (static_cast<std::size_t>(f[1]) + static_cast<std::size_t>(d[1]) * f[2]);
    }

    /// Liquid fraction of a cube of edge dx centred where the level set is `phi`: exact for a
    /// plane parallel to a face, 1 and 0 a half cell inside and outside (free_surface weights).
    double control_volume_fraction(double phi) const {
        return std::clamp(HALF - phi / m_dx, 0.0, 1.0);
    }

    /// μ of a control volume whose liquid fraction is `fraction`.
    double blended_mu(double mu_liquid, double fraction) const {
        return m_mu_gas + (mu_liquid - m_mu_gas) * fraction;
    }

    /// Calls visit(cell) for each of the (up to 4) grid cells around edge e of axis c, whose
    /// other two axes are a and b.
    template <typename Visit>
    void for_each_edge_cell(const Index3& e, int a, int b, Visit&& visit) const {
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

    void set_edge_weights(const BoundaryOptions& walls, const Array3<double>& phi,
                          const PhaseOptions& phases) {
        for (int c = 0; c < 3; ++c) {
            const int a = (c + 1) % 3;
            const int b = (c + 2) % 3;
            Array3<double>& weight = m_edge_weight[c];
            for (int k = 0; k < weight.nk(); ++k) {
                for (int j = 0; j < weight.nj(); ++j) {
                    for (int i = 0; i < weight.ni(); ++i) {
                        const Index3 e = {i, j, k};
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
                            const double phi_edge = phi_sum / count;
                            weight(i, j, k) =
                                SHEAR_WEIGHT * fraction *
                                (m_pointwise_edges
                                     ? (is_liquid(phi_edge) ? phases.mu_liquid : m_mu_gas)
                                     : blended_mu(phases.mu_liquid,
                                                  control_volume_fraction(phi_edge)));
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
                        if (!inviscid) {
                            weight(i, j, k) = SHEAR_WEIGHT * fraction * count / inverse_sum;
                        }
                    }
                }
            }
        }
    }

    void set_faces(const Array3<double>& phi, const PhaseOptions& phases, FluidMode mode,
                   double min_liquid_fraction) {
        m_unknown.assign(m_size, 0);
        m_density.assign(m_size, 0.0);
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
                if (mode == FluidMode::free_surface && !is_liquid(phi_lo) && !is_liquid(phi_hi)) {
                    return;
                }
                m_unknown[flat] = 1;
                const double theta = liquid_fraction(phi_lo, phi_hi);
                m_density[flat] = mode == FluidMode::free_surface
                                      ? phases.rho_liquid * std::max(theta, min_liquid_fraction)
                                      : face_density(theta, phases, mode);
                // An outflow face's control volume is the half cell inside the box, like the
                // half dual cells of the shear terms on it and the pressure's distance Δx/2.
                if ((f[a] == 0 && !seam) || f[a] == m_n[a])
                    m_density[flat] *= OUTFLOW_VOLUME_FRACTION;
            });
        }
    }

    /// σ_a(cell) = 2Δt μ_c ∂_a x_a.
    void normal_stresses(const std::vector<double>& x) const {
        const double scale = 2.0 * m_dt / m_dx;
        for (int a = 0; a < 3; ++a) {
            Array3<double>& sigma = m_normal_stress[a];
            tbb::parallel_for(
                tbb::blocked_range<int>(0, m_n[2]), [&](const tbb::blocked_range<int>& r) {
                    for (int k = r.begin(); k != r.end(); ++k) {
                        for (int j = 0; j < m_n[1]; ++j) {
                            for (int i = 0; i < m_n[0]; ++i) {
                                const Index3 c = {i, j, k};
                                Index3 hi = c;
                                ++hi[a];
                                if (hi[a] == m_n[a] && periodic(a))
                                    hi[a] = 0;  // the face at n is the seam's copy
                                sigma(i, j, k) = scale * m_mu(i, j, k) *
                                                 (x[face_flat(a, hi)] - x[face_flat(a, c)]);
                            }
                        }
                    }
                });
        }
    }

    /// Flat-index step of axis `axis` in the face array of component a.
    std::size_t face_stride(int a, int axis) const {
        const Index3& d = m_face_dims[a];
        return axis == 0   ? 1
               : axis == 1 ? static_cast<std::size_t>(d[0])
                           : static_cast<std::size_t>(d[0]) * d[1];
    }

    /// τ(edge) = 2Δt W_e (∂_b x_a + ∂_a x_b) on edges parallel to c, (a, b) the other axes; ∂
    /// one-sided at walls, where a no-slip wall mirrors the tangential velocity relative to the
    /// wall's own (`moving`, else at rest), with the face indices stepped along each row instead
    /// of recomputed.
    void shear_stresses(const std::vector<double>& x, const BoundaryOptions* moving) const {
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
                            for (int i = 0; i < weight.ni(); ++i) {
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

    /// y_f = Σ over the strain terms containing face f of stress × coefficient.
    void stress_divergence(std::vector<double>& y) const {
        const double inv_dx = 1.0 / m_dx;
        for (int a = 0; a < 3; ++a) {
            const Array3<double>& sigma = m_normal_stress[a];
            const Index3& dims = m_face_dims[a];
            const std::size_t cell_step = a == 0   ? 1
                                          : a == 1 ? static_cast<std::size_t>(m_n[0])
                                                   : static_cast<std::size_t>(m_n[0]) * m_n[1];
            // The two shear arrays this component meets, in the order b = 0, 1, 2 (b ≠ a).
            std::array<int, 2> other{};
            std::array<std::size_t, 2> edge_step{};
            int count = 0;
            for (int b = 0; b < 3; ++b) {
                if (b == a)
                    continue;
                const Array3<double>& tau = m_shear_stress[3 - a - b];
                other[count] = b;
                edge_step[count] = b == 0   ? 1
                                   : b == 1 ? static_cast<std::size_t>(tau.ni())
                                            : static_cast<std::size_t>(tau.ni()) * tau.nj();
                ++count;
            }
            tbb::parallel_for(
                tbb::blocked_range<int>(0, dims[2]), [&](const tbb::blocked_range<int>& r) {
                    for (int k = r.begin(); k != r.end(); ++k) {
                        for (int j = 0; j < dims[1]; ++j) {
                            const std::size_t face_row = face_flat(a, {0, j, k});
                            for (int i = 0; i < dims[0]; ++i) {
                                const Index3 f = {i, j, k};
                                if (!solvable(a, f))
                                    continue;
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
                                    const std::size_t above = wrap && last
                                                                  ? below - f[b] * edge_step[t]
                                                                  : below + edge_step[t];
                                    const double c_below =
                                        (f[b] == 0 && !wrap ? MIRROR_FACTOR : 1.0) * inv_dx;
                                    const double c_above =
                                        -(last && !wrap ? MIRROR_FACTOR : 1.0) * inv_dx;
                                    sum += tau[below] * c_below + tau[above] * c_above;
                                }
                                y[face_row + i] = sum;
                            }
                        }
                    }
                });
        }
    }

    Index3 m_n{};
    bool m_open[3][2] = {};  ///< outflow faces of the box: their normal velocity is solved for
    /// periodic axes: the face at 0 is the seam (cells n−1 and 0), the one at n its copy, and
    /// the edges at 0 are the seam's (those at n copies, weight 0)
    Periodicity m_periodic = {false, false, false};
    bool periodic(int axis) const { return m_periodic[static_cast<std::size_t>(axis)]; }
    double m_dx = 0.0;
    double m_dt = 0.0;
    std::array<Index3, 3> m_face_dims{};
    std::array<std::size_t, 3> m_offset{};
    std::size_t m_size = 0;
    Array3<double> m_mu;                          ///< μ per cell
    bool m_fraction_weights = false;              ///< μ blended by control-volume fractions
    bool m_pointwise_edges = false;               ///< μ_e of the phase at the edge's midpoint
    const SurfaceViscosity* m_surface = nullptr;  ///< the implicit tension term, if any
    double m_surface_scale = 0.0;                 ///< Δt μ_s / Δx³
    double m_mu_gas = 0.0;                        ///< 0 in free_surface mode
    std::array<Array3<double>, 3> m_edge_weight;  ///< W_e per edge, by the axis it is parallel to
    std::vector<char> m_unknown;                  ///< 1 on faces that are solved for
    std::vector<double> m_density;                ///< ρ_f on unknown faces
    mutable std::array<Array3<double>, 3> m_normal_stress;  ///< scratch: σ_aa at cells
    mutable std::array<Array3<double>, 3> m_shear_stress;   ///< scratch: τ on edges
};

}  // namespace

/// Ghost layers the operator reads around a rank's own faces: the normal stress of the cell
/// beyond the slab's last face and the shear stress of the edges on the slab's ends need the
/// faces one layer out, no further. What the CG refreshes every iteration (a depth of 0, no
/// exchange, fails the distributed tests by 3e5 times their tolerance; 1 passes them).
constexpr int VISCOUS_HALO_DEPTH = 1;

void ViscosityOptions::validate() const {
    iteration.validate();
    if (weights != ViscosityWeights::sharp && weights != ViscosityWeights::volume_fraction &&
        weights != ViscosityWeights::pointwise)
        throw std::invalid_argument("ViscosityOptions.weights: unknown weighting");
    if (preconditioner != ViscousPreconditioner::jacobi &&
        preconditioner != ViscousPreconditioner::multigrid)
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
    OperatorKey key;  ///< what `op` and `diagonal` were built from (empty φ: nothing yet)
    std::vector<double> u_star, fixed, x, b, r, z, p, q, diagonal;
    /// multigrid: the component blocks and their V-cycles (built on first use after `op`).
    std::array<PoissonMatrix, 3> blocks;
    std::array<std::unique_ptr<MultigridPreconditioner>, 3> cycles;
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
    const bool reuse =
        !ws.key.phi.empty() && ws.key.same_settings(key) && ws.key.phi == interface.phi.storage();
    if (!reuse) {
        ws.key.phi.clear();  // nothing valid until the build is complete
        ws.diagonal.clear();
        for (auto& cycle : ws.cycles)
            cycle.reset();
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
        if (options.preconditioner != ViscousPreconditioner::jacobi)
            throw std::invalid_argument(
                "ViscosityOptions.preconditioner: only jacobi is available on several ranks");
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
    // K's wall strains relative to moving walls.
    op.gather(grid, ws.u_star);
    x.assign(n, 0.0);
    fixed.assign(n, 0.0);
    for (std::size_t f = 0; f < n; ++f) {
        (unknown[f] ? x[f] : fixed[f]) = ws.u_star[f];
    }
    op.stiffness(fixed, b, walls.moving() ? &walls : nullptr);
    for (std::size_t f = 0; f < n; ++f) {
        b[f] = unknown[f] ? density[f] * ws.u_star[f] - b[f] : 0.0;
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
        const bool multigrid = options.preconditioner == ViscousPreconditioner::multigrid;
        if (multigrid && !ws.cycles[0]) {
            op.component_blocks(diagonal, ws.blocks);
            for (std::size_t a = 0; a < 3; ++a)
                ws.cycles[a] =
                    std::make_unique<MultigridPreconditioner>(ws.blocks[a], options.multigrid);
        }
        // z = M⁻¹ r: Jacobi, or a V-cycle on each component's block (r is zero on fixed faces,
        // and so is z).
        const auto precondition = [&]() {
            if (!multigrid) {
                for (std::size_t f = 0; f < n; ++f)
                    z[f] = r[f] / diagonal[f];
                return;
            }
            std::size_t offset = 0;
            for (std::size_t a = 0; a < 3; ++a) {
                const std::size_t size = ws.blocks[a].size();
                ws.block_r[a].assign(r.begin() + static_cast<std::ptrdiff_t>(offset),
                                     r.begin() + static_cast<std::ptrdiff_t>(offset + size));
                ws.cycles[a]->apply(ws.block_r[a], ws.block_z[a]);
                std::copy(ws.block_z[a].begin(), ws.block_z[a].end(),
                          z.begin() + static_cast<std::ptrdiff_t>(offset));
                offset += size;
            }
        };
        r.resize(n);
        z.resize(n);
        op.apply(x, q);
        for (std::size_t f = 0; f < n; ++f)
            r[f] = b[f] - q[f];
        precondition();
        p = z;
        double rz = global_dot(r, z);
        result.residual = std::sqrt(global_dot(r, r)) / b_norm;
        result.converged = result.residual <= options.iteration.tolerance;
        while (!result.converged && result.iterations < options.iteration.max_iterations) {
            options.iteration.cancel.throw_if_requested("the viscosity solve");
            refresh_ghosts(p);
            op.apply(p, q);
            const double curvature = global_dot(p, q);
            if (!(curvature > 0.0)) {
                break;
            }
            const double alpha = rz / curvature;
            axpy(alpha, p, x);
            axpy(-alpha, q, r);
            ++result.iterations;
            result.residual = std::sqrt(global_dot(r, r)) / b_norm;
            result.converged = result.residual <= options.iteration.tolerance;
            precondition();
            const double rz_new = global_dot(r, z);
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
