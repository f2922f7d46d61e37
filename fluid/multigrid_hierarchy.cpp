#include "fluid/multigrid_hierarchy.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <utility>

namespace meniscus::fluid {

namespace {

using AxisTransfer = MultigridPreconditioner::AxisTransfer;

/// Weight of the nearer and the farther coarse cell in cell-centred linear prolongation.
constexpr double NEAR_WEIGHT = 0.75;
constexpr double FAR_WEIGHT = 0.25;
/// Rediscretisation factor of a coarse face coefficient: (average over the 2×2 fine lines) ×
/// (coarse face area / coarse spacing) / (fine face area / fine spacing) = Σ lines / 4 × 2.
constexpr double COARSE_FACE_SCALE = 0.5;
/// Weight of the two fine faces inside the coarse cells, relative to the face on the coarse face.
constexpr double END_FACE_WEIGHT = 0.5;

/// The transfer along an axis of `fine_n` cells; along a `periodic` axis the fine cells at either
/// end also interpolate from the coarse cell across the seam.
AxisTransfer make_axis_transfer(int fine_n, bool periodic) {
    const int coarse_n = (fine_n + 1) / 2;
    AxisTransfer t;
    for (int s = 0; s < 2; ++s) {
        t.prolong_cell[s].assign(fine_n, 0);
        t.prolong_weight[s].assign(fine_n, 0.0);
    }
    t.restrict_count.assign(coarse_n, 0);
    t.restrict_cell.assign(static_cast<std::size_t>(coarse_n) * AXIS_TRANSFER_SLOTS, 0);
    t.restrict_weight.assign(static_cast<std::size_t>(coarse_n) * AXIS_TRANSFER_SLOTS, 0.0);
    const auto add_restrict = [&](int coarse, int fine, double weight) {
        if (weight == 0.0) {
            return;
        }
        const int slot = t.restrict_count[coarse]++;
        t.restrict_cell[static_cast<std::size_t>(coarse) * AXIS_TRANSFER_SLOTS + slot] = fine;
        t.restrict_weight[static_cast<std::size_t>(coarse) * AXIS_TRANSFER_SLOTS + slot] = weight;
    };
    for (int i = 0; i < fine_n; ++i) {
        const int parent = i / 2;
        int other = (i % 2 == 0) ? parent - 1 : parent + 1;
        if (periodic)
            other = (other + coarse_n) % coarse_n;
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
    // off_*(c) is 0 at the far end of a bounded axis and the seam's coupling on a periodic one.
    double excess = a.diag[c] + a.off_x[c] + a.off_y[c] + a.off_z[c];
    if (i > 0 || a.periodic[0])
        excess += a.off_x(i > 0 ? i - 1 : a.ni() - 1, j, k);
    if (j > 0 || a.periodic[1])
        excess += a.off_y(i, j > 0 ? j - 1 : a.nj() - 1, k);
    if (k > 0 || a.periodic[2])
        excess += a.off_z(i, j, k > 0 ? k - 1 : a.nk() - 1);
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
    const Array3<double>& off = fine.off(axis);
    const std::array<int, 3> fine_n = {fine.ni(), fine.nj(), fine.nk()};
    const std::array<int, 3> base = {2 * ii, 2 * jj, 2 * kk};
    const int n = fine_n[axis];
    // The lower coarse cell's last fine cell and the upper one's first: across a periodic seam
    // (ii the last coarse cell) the upper is coarse cell 0, and the lower may hold one fine cell.
    const int lower_last = std::min(base[axis] + 1, n - 1);
    const int upper_first = (lower_last + 1) % n;
    const int t1 = (axis + 1) % 3;
    const int t2 = (axis + 2) % 3;
    // Flat indices (this runs for every coarse face of every hierarchy: no checked access).
    const std::array<std::size_t, 3> stride = {
        1, static_cast<std::size_t>(fine_n[0]),
        static_cast<std::size_t>(fine_n[0]) * static_cast<std::size_t>(fine_n[1])};
    const double* entries = off.data();
    double total = 0.0;
    for (int a = base[t1]; a < std::min(base[t1] + 2, fine_n[t1]); ++a) {
        for (int b = base[t2]; b < std::min(base[t2] + 2, fine_n[t2]); ++b) {
            const std::size_t line =
                static_cast<std::size_t>(a) * stride[t1] + static_cast<std::size_t>(b) * stride[t2];
            const auto beta_at = [&](int along) {
                return -entries[line + static_cast<std::size_t>(along) * stride[axis]];
            };
            const double middle = beta_at(lower_last);
            if (middle <= 0.0) {
                continue;
            }
            double weighted = middle;
            double weights = 1.0;
            // The inner faces of the two coarse cells, where they hold two fine cells.
            for (int end : {lower_last > base[axis] ? base[axis] : -1,
                            upper_first + 1 < n ? upper_first : -1}) {
                if (end < 0) {
                    continue;
                }
                const double beta = beta_at(end);
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

/// The coarse matrix of `fine`. A periodic axis stays periodic while the coarse level has at
/// least 3 cells along it; with 2 the seam's coupling joins the same two cells as the inner face
/// and is added to it, with 1 it would couple the cell to itself and is left out.
void build_coarse_matrix(const PoissonMatrix& fine, PoissonMatrix& coarse) {
    const int fi = fine.ni(), fj = fine.nj(), fk = fine.nk();
    const std::array<int, 3> cn = {(fi + 1) / 2, (fj + 1) / 2, (fk + 1) / 2};
    const int ci = cn[0], cj = cn[1], ck = cn[2];
    coarse.resize(ci, cj, ck);
    for (std::size_t axis = 0; axis < 3; ++axis)
        coarse.periodic[axis] = fine.periodic[axis] && cn[axis] >= 3;
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
                    const std::array<int, 3> at = {ii, jj, kk};
                    for (int axis = 0; axis < 3; ++axis) {
                        const auto a = static_cast<std::size_t>(axis);
                        const bool last = at[a] + 1 == cn[a];
                        if (!last || coarse.periodic[a])
                            coarse.off(axis)(ii, jj, kk) = coarse_coupling(fine, axis, ii, jj, kk);
                    }
                }
            }
        }
    });
    for (int axis = 0; axis < 3; ++axis) {
        const auto a = static_cast<std::size_t>(axis);
        if (!fine.periodic[a] || cn[a] != 2)
            continue;
        Array3<double>& off = coarse.off(axis);
        for (int kk = 0; kk < (axis == 2 ? 1 : ck); ++kk)
            for (int jj = 0; jj < (axis == 1 ? 1 : cj); ++jj)
                for (int ii = 0; ii < (axis == 0 ? 1 : ci); ++ii) {
                    std::array<int, 3> seam = {ii, jj, kk};
                    seam[a] = 1;
                    off(ii, jj, kk) += coarse_coupling(fine, axis, seam[0], seam[1], seam[2]);
                }
    }
    // Diagonal = Dirichlet part + Σ |couplings| (row sums of the Neumann part vanish).
    for (int kk = 0; kk < ck; ++kk) {
        for (int jj = 0; jj < cj; ++jj) {
            for (int ii = 0; ii < ci; ++ii) {
                double sum = -(coarse.off_x(ii, jj, kk) + coarse.off_y(ii, jj, kk) +
                               coarse.off_z(ii, jj, kk));
                if (ii > 0 || coarse.periodic[0])
                    sum -= coarse.off_x(ii > 0 ? ii - 1 : ci - 1, jj, kk);
                if (jj > 0 || coarse.periodic[1])
                    sum -= coarse.off_y(ii, jj > 0 ? jj - 1 : cj - 1, kk);
                if (kk > 0 || coarse.periodic[2])
                    sum -= coarse.off_z(ii, jj, kk > 0 ? kk - 1 : ck - 1);
                coarse.diag(ii, jj, kk) += sum;
            }
        }
    }
}

}  // namespace

MultigridHierarchy build_multigrid_hierarchy(const PoissonMatrix& fine, int coarsest_max_cells) {
    MultigridHierarchy h;
    while (true) {
        const PoissonMatrix& current = h.coarse.empty() ? fine : h.coarse.back();
        const int largest = std::max({current.ni(), current.nj(), current.nk()});
        if (current.size() <= static_cast<std::size_t>(coarsest_max_cells) || largest <= 2) {
            break;
        }
        h.transfers.push_back({make_axis_transfer(current.ni(), current.periodic[0]),
                               make_axis_transfer(current.nj(), current.periodic[1]),
                               make_axis_transfer(current.nk(), current.periodic[2])});
        PoissonMatrix coarse;
        build_coarse_matrix(current, coarse);
        h.coarse.push_back(std::move(coarse));
    }
    return h;
}

}  // namespace meniscus::fluid
