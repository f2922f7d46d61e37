#include "fluid/multigrid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <stdexcept>

namespace meniscus::fluid {

namespace {

/// Weight of the nearer and the farther coarse cell in cell-centred linear prolongation.
constexpr double NEAR_WEIGHT = 0.75;
constexpr double FAR_WEIGHT = 0.25;
/// Rediscretisation factor of a coarse face coefficient: (average over the 2×2 fine lines) ×
/// (coarse face area / coarse spacing) / (fine face area / fine spacing) = Σ lines / 4 × 2.
constexpr double COARSE_FACE_SCALE = 0.5;
constexpr int MAX_RESTRICT = 4;
/// Weight of the two fine faces inside the coarse cells, relative to the face on the coarse face.
constexpr double END_FACE_WEIGHT = 0.5;

using AxisTransfer = MultigridPreconditioner::AxisTransfer;

AxisTransfer make_axis_transfer(int fine_n) {
    const int coarse_n = (fine_n + 1) / 2;
    AxisTransfer t;
    for (int s = 0; s < 2; ++s) {
        t.prolong_cell[s].assign(fine_n, 0);
        t.prolong_weight[s].assign(fine_n, 0.0);
    }
    t.restrict_count.assign(coarse_n, 0);
    t.restrict_cell.assign(static_cast<std::size_t>(coarse_n) * MAX_RESTRICT, 0);
    t.restrict_weight.assign(static_cast<std::size_t>(coarse_n) * MAX_RESTRICT, 0.0);
    const auto add_restrict = [&](int coarse, int fine, double weight) {
        if (weight == 0.0) {
            return;
        }
        const int slot = t.restrict_count[coarse]++;
        t.restrict_cell[static_cast<std::size_t>(coarse) * MAX_RESTRICT + slot] = fine;
        t.restrict_weight[static_cast<std::size_t>(coarse) * MAX_RESTRICT + slot] = weight;
    };
    for (int i = 0; i < fine_n; ++i) {
        const int parent = i / 2;
        const int other = (i % 2 == 0) ? parent - 1 : parent + 1;
        if (other < 0 || other >= coarse_n) {
            t.prolong_cell[0][i] = parent;
            t.prolong_weight[0][i] = 1.0;
            t.prolong_cell[1][i] = parent;
            t.prolong_weight[1][i] = 0.0;
        } else {
            t.prolong_cell[0][i] = parent;
            t.prolong_weight[0][i] = NEAR_WEIGHT;
            t.prolong_cell[1][i] = other;
            t.prolong_weight[1][i] = FAR_WEIGHT;
        }
        add_restrict(t.prolong_cell[0][i], i, t.prolong_weight[0][i]);
        add_restrict(t.prolong_cell[1][i], i, t.prolong_weight[1][i]);
    }
    return t;
}

/// Dirichlet part of the diagonal of fine cell c: A_cc − Σ |off-diagonals| ≥ 0.
double dirichlet_excess(const PoissonMatrix& a, int i, int j, int k) {
    const std::size_t c = a.diag.index(i, j, k);
    double excess = a.diag[c] + a.off_x[c] + a.off_y[c] + a.off_z[c];
    if (i > 0)
        excess += a.off_x(i - 1, j, k);
    if (j > 0)
        excess += a.off_y(i, j - 1, k);
    if (k > 0)
        excess += a.off_z(i, j, k - 1);
    return std::max(excess, 0.0);
}

/// Off-diagonal entry (≤ 0) of the coarse matrix between coarse cell (ii, jj, kk) and its
/// neighbour along `axis`. Each of the 2×2 fine lines crossing the coarse face joins the two
/// coarse centres through three fine faces: the lower coarse cell's inner face, the face on the
/// coarse face and the upper coarse cell's inner face. The line's coefficient is the
/// (½, 1, ½)-weighted average of their fine coefficients β, the coarse coupling is
/// COARSE_FACE_SCALE × the sum over the lines (2β for a constant β: the coarse rediscretisation).
/// Averaging along the line (rather than taking only the middle face) lets a high-β inclusion such
/// as a gas bubble at density ratio 1000 keep its extent on the coarse levels, which halves the
/// PCG iterations on such systems. A line whose middle face is closed (an inactive neighbour in
/// free-surface mode) carries nothing; closed or missing end faces are left out of the average.
double coarse_coupling(const PoissonMatrix& fine, int axis, int ii, int jj, int kk) {
    const Array3<double>& off = axis == 0 ? fine.off_x : (axis == 1 ? fine.off_y : fine.off_z);
    const std::array<int, 3> fine_n = {fine.ni(), fine.nj(), fine.nk()};
    const std::array<int, 3> base = {2 * ii, 2 * jj, 2 * kk};
    const int t1 = (axis + 1) % 3;
    const int t2 = (axis + 2) % 3;
    double total = 0.0;
    for (int a = base[t1]; a < std::min(base[t1] + 2, fine_n[t1]); ++a) {
        for (int b = base[t2]; b < std::min(base[t2] + 2, fine_n[t2]); ++b) {
            std::array<int, 3> face = base;
            face[t1] = a;
            face[t2] = b;
            const double middle =
                -off(face[0] + (axis == 0), face[1] + (axis == 1), face[2] + (axis == 2));
            if (middle <= 0.0) {
                continue;
            }
            double weighted = middle;
            double weights = 1.0;
            for (int step : {0, 2}) {
                std::array<int, 3> end = face;
                end[axis] = base[axis] + step;
                if (end[axis] + 1 >= fine_n[axis]) {
                    continue;
                }
                const double beta = -off(end[0], end[1], end[2]);
                if (beta > 0.0) {
                    weighted += END_FACE_WEIGHT * beta;
                    weights += END_FACE_WEIGHT;
                }
            }
            total += weighted / weights;
        }
    }
    return -COARSE_FACE_SCALE * total;
}

void build_coarse_matrix(const PoissonMatrix& fine, PoissonMatrix& coarse) {
    const int fi = fine.ni(), fj = fine.nj(), fk = fine.nk();
    const int ci = (fi + 1) / 2, cj = (fj + 1) / 2, ck = (fk + 1) / 2;
    coarse.resize(ci, cj, ck);
    tbb::parallel_for(tbb::blocked_range<int>(0, ck), [&](const tbb::blocked_range<int>& range) {
        for (int kk = range.begin(); kk != range.end(); ++kk) {
            for (int jj = 0; jj < cj; ++jj) {
                for (int ii = 0; ii < ci; ++ii) {
                    double excess = 0.0;
                    for (int k = 2 * kk; k < std::min(2 * kk + 2, fk); ++k) {
                        for (int j = 2 * jj; j < std::min(2 * jj + 2, fj); ++j) {
                            for (int i = 2 * ii; i < std::min(2 * ii + 2, fi); ++i) {
                                if (fine.diag(i, j, k) > 0.0) {
                                    excess += dirichlet_excess(fine, i, j, k);
                                }
                            }
                        }
                    }
                    coarse.diag(ii, jj, kk) = COARSE_FACE_SCALE * excess;
                    if (ii + 1 < ci)
                        coarse.off_x(ii, jj, kk) = coarse_coupling(fine, 0, ii, jj, kk);
                    if (jj + 1 < cj)
                        coarse.off_y(ii, jj, kk) = coarse_coupling(fine, 1, ii, jj, kk);
                    if (kk + 1 < ck)
                        coarse.off_z(ii, jj, kk) = coarse_coupling(fine, 2, ii, jj, kk);
                }
            }
        }
    });
    // Diagonal = Dirichlet part + Σ |couplings| (row sums of the Neumann part vanish).
    for (int kk = 0; kk < ck; ++kk) {
        for (int jj = 0; jj < cj; ++jj) {
            for (int ii = 0; ii < ci; ++ii) {
                double sum = -(coarse.off_x(ii, jj, kk) + coarse.off_y(ii, jj, kk) +
                               coarse.off_z(ii, jj, kk));
                if (ii > 0)
                    sum -= coarse.off_x(ii - 1, jj, kk);
                if (jj > 0)
                    sum -= coarse.off_y(ii, jj - 1, kk);
                if (kk > 0)
                    sum -= coarse.off_z(ii, jj, kk - 1);
                coarse.diag(ii, jj, kk) += sum;
            }
        }
    }
}

/// One red–black Gauss–Seidel half sweep over cells with (i + j + k) % 2 == colour.
void smooth_colour(const PoissonMatrix& a, const std::vector<double>& b, std::vector<double>& x,
                   int colour) {
    const int ni = a.ni(), nj = a.nj(), nk = a.nk();
    const std::size_t sj = static_cast<std::size_t>(ni);
    const std::size_t sk = static_cast<std::size_t>(ni) * nj;
    const double* a_d = a.diag.data();
    const double* a_x = a.off_x.data();
    const double* a_y = a.off_y.data();
    const double* a_z = a.off_z.data();
    const double* bv = b.data();
    double* xv = x.data();
    tbb::parallel_for(tbb::blocked_range<int>(0, nk), [&](const tbb::blocked_range<int>& range) {
        for (int k = range.begin(); k != range.end(); ++k) {
            for (int j = 0; j < nj; ++j) {
                const std::size_t row = sk * k + sj * j;
                for (int i = (j + k + colour) % 2; i < ni; i += 2) {
                    const std::size_t c = row + i;
                    if (a_d[c] <= 0.0) {
                        continue;
                    }
                    double sum = bv[c];
                    if (i + 1 < ni)
                        sum -= a_x[c] * xv[c + 1];
                    if (i > 0)
                        sum -= a_x[c - 1] * xv[c - 1];
                    if (j + 1 < nj)
                        sum -= a_y[c] * xv[c + sj];
                    if (j > 0)
                        sum -= a_y[c - sj] * xv[c - sj];
                    if (k + 1 < nk)
                        sum -= a_z[c] * xv[c + sk];
                    if (k > 0)
                        sum -= a_z[c - sk] * xv[c - sk];
                    xv[c] = sum / a_d[c];
                }
            }
        }
    });
}

/// The first red half-sweep from x = 0: x = b / A_cc on red active cells, 0 elsewhere (same
/// result as clearing x and calling smooth_colour(RED), in one pass without neighbour reads).
void first_red_from_zero(const PoissonMatrix& a, const std::vector<double>& b,
                         std::vector<double>& x) {
    const int ni = a.ni(), nj = a.nj(), nk = a.nk();
    const std::size_t sj = static_cast<std::size_t>(ni);
    const std::size_t sk = static_cast<std::size_t>(ni) * nj;
    const double* a_d = a.diag.data();
    const double* bv = b.data();
    double* xv = x.data();
    tbb::parallel_for(tbb::blocked_range<int>(0, nk), [&](const tbb::blocked_range<int>& range) {
        for (int k = range.begin(); k != range.end(); ++k) {
            for (int j = 0; j < nj; ++j) {
                const std::size_t row = sk * k + sj * j;
                const int first_red = (j + k) % 2;
                for (int i = 0; i < ni; ++i) {
                    const std::size_t c = row + i;
                    xv[c] = ((i % 2) == first_red && a_d[c] > 0.0) ? bv[c] / a_d[c] : 0.0;
                }
            }
        }
    });
}

/// coarse_b = Pᵀ fine_r on active coarse cells.
void restrict_residual(const AxisTransfer* t, const PoissonMatrix& fine,
                       const std::vector<double>& fine_r, const PoissonMatrix& coarse,
                       std::vector<double>& coarse_b) {
    const int ci = coarse.ni(), cj = coarse.nj(), ck = coarse.nk();
    tbb::parallel_for(tbb::blocked_range<int>(0, ck), [&](const tbb::blocked_range<int>& range) {
        for (int kk = range.begin(); kk != range.end(); ++kk) {
            for (int jj = 0; jj < cj; ++jj) {
                for (int ii = 0; ii < ci; ++ii) {
                    const std::size_t cc = coarse.diag.index(ii, jj, kk);
                    if (coarse.diag[cc] <= 0.0) {
                        coarse_b[cc] = 0.0;
                        continue;
                    }
                    double sum = 0.0;
                    for (int sk = 0; sk < t[2].restrict_count[kk]; ++sk) {
                        const std::size_t ok = static_cast<std::size_t>(kk) * MAX_RESTRICT + sk;
                        const int k = t[2].restrict_cell[ok];
                        const double wk = t[2].restrict_weight[ok];
                        for (int sj = 0; sj < t[1].restrict_count[jj]; ++sj) {
                            const std::size_t oj = static_cast<std::size_t>(jj) * MAX_RESTRICT + sj;
                            const int j = t[1].restrict_cell[oj];
                            const double wjk = wk * t[1].restrict_weight[oj];
                            const std::size_t row = fine.diag.index(0, j, k);
                            for (int si = 0; si < t[0].restrict_count[ii]; ++si) {
                                const std::size_t oi =
                                    static_cast<std::size_t>(ii) * MAX_RESTRICT + si;
                                sum += wjk * t[0].restrict_weight[oi] *
                                       fine_r[row + t[0].restrict_cell[oi]];
                            }
                        }
                    }
                    coarse_b[cc] = sum;
                }
            }
        }
    });
}

/// fine_x += P coarse_x on active fine cells.
void prolong_add(const AxisTransfer* t, const PoissonMatrix& coarse,
                 const std::vector<double>& coarse_x, const PoissonMatrix& fine,
                 std::vector<double>& fine_x) {
    const int fi = fine.ni(), fj = fine.nj(), fk = fine.nk();
    tbb::parallel_for(tbb::blocked_range<int>(0, fk), [&](const tbb::blocked_range<int>& range) {
        for (int k = range.begin(); k != range.end(); ++k) {
            for (int j = 0; j < fj; ++j) {
                for (int i = 0; i < fi; ++i) {
                    const std::size_t c = fine.diag.index(i, j, k);
                    if (fine.diag[c] <= 0.0) {
                        continue;
                    }
                    double sum = 0.0;
                    for (int sk = 0; sk < 2; ++sk) {
                        const double wk = t[2].prolong_weight[sk][k];
                        const int kk = t[2].prolong_cell[sk][k];
                        for (int sj = 0; sj < 2; ++sj) {
                            const double wjk = wk * t[1].prolong_weight[sj][j];
                            const int jj = t[1].prolong_cell[sj][j];
                            const std::size_t row = coarse.diag.index(0, jj, kk);
                            for (int si = 0; si < 2; ++si) {
                                sum += wjk * t[0].prolong_weight[si][i] *
                                       coarse_x[row + t[0].prolong_cell[si][i]];
                            }
                        }
                    }
                    fine_x[c] += sum;
                }
            }
        }
    });
}

}  // namespace

void MultigridOptions::validate() const {
    if (smoothing_sweeps < 1) {
        throw std::invalid_argument("MultigridOptions.smoothing_sweeps must be at least 1");
    }
    if (coarsest_sweeps < 1) {
        throw std::invalid_argument("MultigridOptions.coarsest_sweeps must be at least 1");
    }
    if (coarsest_max_cells < 1) {
        throw std::invalid_argument("MultigridOptions.coarsest_max_cells must be at least 1");
    }
}

MultigridPreconditioner::MultigridPreconditioner(const PoissonMatrix& matrix,
                                                 const MultigridOptions& options)
    : m_fine(matrix), m_options(options) {
    options.validate();
    m_levels.emplace_back();
    while (true) {
        const PoissonMatrix& current = level_matrix(m_levels.size() - 1);
        const int largest = std::max({current.ni(), current.nj(), current.nk()});
        if (current.size() <= static_cast<std::size_t>(options.coarsest_max_cells) ||
            largest <= 2) {
            break;
        }
        Level& level = m_levels.back();
        level.transfer[0] = make_axis_transfer(current.ni());
        level.transfer[1] = make_axis_transfer(current.nj());
        level.transfer[2] = make_axis_transfer(current.nk());
        Level coarse;
        build_coarse_matrix(current, coarse.matrix);
        m_levels.push_back(std::move(coarse));
    }
    for (std::size_t l = 0; l < m_levels.size(); ++l) {
        const std::size_t n = level_matrix(l).size();
        if (l > 0) {  // level 0 works on the caller's r and z
            m_levels[l].x.assign(n, 0.0);
            m_levels[l].b.assign(n, 0.0);
        }
        m_levels[l].r.assign(n, 0.0);
    }
}

const PoissonMatrix& MultigridPreconditioner::level_matrix(std::size_t level) const {
    return level == 0 ? m_fine : m_levels[level].matrix;
}

void MultigridPreconditioner::cycle(std::size_t level, const std::vector<double>& b,
                                    std::vector<double>& x) const {
    const PoissonMatrix& a = level_matrix(level);
    const Level& data = m_levels[level];
    constexpr int RED = 0;
    constexpr int BLACK = 1;
    // From x = 0 the first red half-sweep needs no neighbours; it also clears the black cells.
    first_red_from_zero(a, b, x);
    if (level + 1 == m_levels.size()) {
        // Palindromic order R (B R)^n keeps the coarsest solve a symmetric operator.
        for (int sweep = 0; sweep < m_options.coarsest_sweeps; ++sweep) {
            smooth_colour(a, b, x, BLACK);
            smooth_colour(a, b, x, RED);
        }
        return;
    }
    smooth_colour(a, b, x, BLACK);
    for (int sweep = 1; sweep < m_options.smoothing_sweeps; ++sweep) {
        smooth_colour(a, b, x, RED);
        smooth_colour(a, b, x, BLACK);
    }
    a.residual(x, b, data.r);
    const PoissonMatrix& coarse = level_matrix(level + 1);
    const Level& next = m_levels[level + 1];
    restrict_residual(data.transfer, a, data.r, coarse, next.b);
    cycle(level + 1, next.b, next.x);
    prolong_add(data.transfer, coarse, next.x, a, x);
    for (int sweep = 0; sweep < m_options.smoothing_sweeps; ++sweep) {
        smooth_colour(a, b, x, BLACK);
        smooth_colour(a, b, x, RED);
    }
}

void MultigridPreconditioner::apply(const std::vector<double>& r, std::vector<double>& z) const {
    z.resize(r.size());
    cycle(0, r, z);
}

}  // namespace meniscus::fluid
