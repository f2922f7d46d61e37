#include "fluid/multigrid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace meniscus::fluid {

namespace {

/// Weight of the nearer and the farther coarse cell in cell-centred linear prolongation.
constexpr double NEAR_WEIGHT = 0.75;
constexpr double FAR_WEIGHT = 0.25;
/// Rediscretisation factor of a coarse face coefficient: (average over the 2×2 fine lines) ×
/// (coarse face area / coarse spacing) / (fine face area / fine spacing) = Σ lines / 4 × 2.
constexpr double COARSE_FACE_SCALE = 0.5;
constexpr int MAX_RESTRICT = 4;
/// Elements per task in flat conversions and reductions.
constexpr std::size_t VECTOR_GRAIN = 16384;
/// Weight of the two fine faces inside the coarse cells, relative to the face on the coarse face.
constexpr double END_FACE_WEIGHT = 0.5;

using AxisTransfer = MultigridPreconditioner::AxisTransfer;

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

/// x on the first and the last plane of each periodic axis of a level, taken before each half
/// sweep of the smoother: neighbours across the seam are read from here, so where an odd cell
/// count puts one colour on both sides of the seam the half sweep is still a Jacobi update of its
/// colour (the cycle stays symmetric, and independent of the order and the threads).
template <class T>
struct SeamPlanes {
    std::array<std::vector<T>, 3> first;
    std::array<std::vector<T>, 3> last;
};

/// Index of cell (i, j, k) within a plane normal to `axis`.
inline std::size_t plane_index(int axis, int i, int j, int k, int ni, int nj) {
    if (axis == 0)
        return static_cast<std::size_t>(j) + static_cast<std::size_t>(nj) * k;
    if (axis == 1)
        return static_cast<std::size_t>(i) + static_cast<std::size_t>(ni) * k;
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(ni) * j;
}

template <class T>
void take_seam_planes(const BasicPoissonMatrix<T>& a, const std::vector<T>& x,
                      SeamPlanes<T>& seams) {
    const std::array<int, 3> n = {a.ni(), a.nj(), a.nk()};
    for (int axis = 0; axis < 3; ++axis) {
        const auto ax = static_cast<std::size_t>(axis);
        if (!a.periodic[ax])
            continue;
        const std::size_t plane = a.size() / static_cast<std::size_t>(n[ax]);
        seams.first[ax].resize(plane);
        seams.last[ax].resize(plane);
        std::array<int, 3> hi = n;  // the plane's range, along `axis` one cell
        hi[ax] = 1;
        for (int side = 0; side < 2; ++side) {
            std::vector<T>& out = side == 0 ? seams.first[ax] : seams.last[ax];
            const int along = side == 0 ? 0 : n[ax] - 1;
            for (int k = 0; k < hi[2]; ++k)
                for (int j = 0; j < hi[1]; ++j)
                    for (int i = 0; i < hi[0]; ++i) {
                        std::array<int, 3> cell = {i, j, k};
                        cell[ax] = along;
                        out[plane_index(axis, i, j, k, n[0], n[1])] =
                            x[a.diag.index(cell[0], cell[1], cell[2])];
                    }
        }
    }
}

/// One red–black Gauss–Seidel half sweep over the cells of plane k with (i + j + k) % 2 ==
/// colour. Neighbours across a periodic seam are read from `seams` (take_seam_planes() of x
/// before the half sweep). `Wrap` false compiles the loop without the seam's branches.
template <bool Wrap, class T>
void smooth_plane(const BasicPoissonMatrix<T>& a, const std::vector<T>& inverse,
                  const std::vector<T>& b, std::vector<T>& x, int colour, int k,
                  const SeamPlanes<T>& seams) {
    const int ni = a.ni(), nj = a.nj(), nk = a.nk();
    const std::size_t sj = static_cast<std::size_t>(ni);
    const std::size_t sk = static_cast<std::size_t>(ni) * nj;
    const T* a_d = a.diag.data();
    const T* iv = inverse.data();
    const T* a_x = a.off_x.data();
    const T* a_y = a.off_y.data();
    const T* a_z = a.off_z.data();
    const T* bv = b.data();
    T* xv = x.data();
    const bool px = Wrap && a.periodic[0], py = Wrap && a.periodic[1], pz = Wrap && a.periodic[2];
    for (int j = 0; j < nj; ++j) {
        const std::size_t row = sk * k + sj * j;
        if (!Wrap && j > 0 && j + 1 < nj && k > 0 && k + 1 < nk) {
            // A row inside the box along y and z: past its ends the couplings are zero (off_x
            // is 0 at the far end of a bounded axis, the previous row's last included) and the
            // cells read there lie inside the array, so the x-neighbours need no test.
            // No test for inactive cells either: their inverse diagonal is 0 (and b, x are 0
            // there), and the three pairs summed apart shorten the chain of dependent adds.
            for (int i = (j + k + colour) % 2; i < ni; i += 2) {
                const std::size_t c = row + i;
                const T along_x = a_x[c] * xv[c + 1] + a_x[c - 1] * xv[c - 1];
                const T along_y = a_y[c] * xv[c + sj] + a_y[c - sj] * xv[c - sj];
                const T along_z = a_z[c] * xv[c + sk] + a_z[c - sk] * xv[c - sk];
                xv[c] = (bv[c] - (along_x + along_y + along_z)) * iv[c];
            }
            continue;
        }
        for (int i = (j + k + colour) % 2; i < ni; i += 2) {
            const std::size_t c = row + i;
            if (a_d[c] <= 0.0) {
                continue;
            }
            T sum = bv[c];
            if (i + 1 < ni)
                sum -= a_x[c] * xv[c + 1];
            else if (Wrap && px)
                sum -= a_x[c] * seams.first[0][plane_index(0, i, j, k, ni, nj)];
            if (i > 0)
                sum -= a_x[c - 1] * xv[c - 1];
            else if (Wrap && px)
                sum -= a_x[c + sj - 1] * seams.last[0][plane_index(0, i, j, k, ni, nj)];
            if (j + 1 < nj)
                sum -= a_y[c] * xv[c + sj];
            else if (Wrap && py)
                sum -= a_y[c] * seams.first[1][plane_index(1, i, j, k, ni, nj)];
            if (j > 0)
                sum -= a_y[c - sj] * xv[c - sj];
            else if (Wrap && py)
                sum -= a_y[c + sj * (nj - 1)] * seams.last[1][plane_index(1, i, j, k, ni, nj)];
            if (k + 1 < nk)
                sum -= a_z[c] * xv[c + sk];
            else if (Wrap && pz)
                sum -= a_z[c] * seams.first[2][plane_index(2, i, j, k, ni, nj)];
            if (k > 0)
                sum -= a_z[c - sk] * xv[c - sk];
            else if (Wrap && pz)
                sum -= a_z[c + sk * (nk - 1)] * seams.last[2][plane_index(2, i, j, k, ni, nj)];
            xv[c] = sum * iv[c];
        }
    }
}

template <bool Wrap, class T>
void smooth_colour_kernel(const BasicPoissonMatrix<T>& a, const std::vector<T>& inverse,
                          const std::vector<T>& b, std::vector<T>& x, int colour,
                          SeamPlanes<T>& seams) {
    if (Wrap)
        take_seam_planes(a, x, seams);
    tbb::parallel_for(tbb::blocked_range<int>(0, a.nk()),
                      [&](const tbb::blocked_range<int>& range) {
                          for (int k = range.begin(); k != range.end(); ++k)
                              smooth_plane<Wrap, T>(a, inverse, b, x, colour, k, seams);
                      });
}

/// One red–black Gauss–Seidel half sweep over cells with (i + j + k) % 2 == colour. Neighbours
/// across a periodic seam are read from `seams` (take_seam_planes() of x before the sweep).
template <class T>
void smooth_colour(const BasicPoissonMatrix<T>& a, const std::vector<T>& inverse,
                   const std::vector<T>& b, std::vector<T>& x, int colour, SeamPlanes<T>& seams) {
    if (a.any_periodic())
        smooth_colour_kernel<true, T>(a, inverse, b, x, colour, seams);
    else
        smooth_colour_kernel<false, T>(a, inverse, b, x, colour, seams);
}

/// The first red half sweep from x = 0 on plane k: x = b / A_cc on red active cells, 0
/// elsewhere (`inverse`: 1 / A_cc on active cells, 0 on the others) (same result as clearing x and
/// smoothing red, without neighbour reads).
template <class T>
void first_red_plane(const BasicPoissonMatrix<T>& a, const std::vector<T>& inverse,
                     const std::vector<T>& b, std::vector<T>& x, int k) {
    const int ni = a.ni(), nj = a.nj();
    const std::size_t sj = static_cast<std::size_t>(ni);
    const std::size_t sk = static_cast<std::size_t>(ni) * nj;
    const T* iv = inverse.data();
    const T* bv = b.data();
    T* xv = x.data();
    for (int j = 0; j < nj; ++j) {
        const std::size_t row = sk * k + sj * j;
        const int first_red = (j + k) % 2;
        for (int i = 0; i < ni; ++i) {
            const std::size_t c = row + i;
            xv[c] = (i % 2) == first_red ? bv[c] * iv[c] : T(0);
        }
    }
}

/// first_red_plane() on every plane.
template <class T>
void first_red_from_zero(const BasicPoissonMatrix<T>& a, const std::vector<T>& inverse,
                         const std::vector<T>& b, std::vector<T>& x) {
    tbb::parallel_for(tbb::blocked_range<int>(0, a.nk()),
                      [&](const tbb::blocked_range<int>& range) {
                          for (int k = range.begin(); k != range.end(); ++k)
                              first_red_plane(a, inverse, b, x, k);
                      });
}

/// Planes per task of the pipelined sweep: its extra pass touches 2 of them.
constexpr int PIPELINE_PLANES = 16;

/// Two half sweeps, `first` then the other colour, on a box without periodic axes, in one pass
/// over memory: plane k's first half sweep, then plane k−1's second, which has all its
/// neighbours' first-colour values by then. Each task takes a slab of planes; the second half
/// sweep of a slab's first and last planes (whose neighbours another task updates) waits for a
/// second pass. Same result, bit for bit, as the two half sweeps one after the other.
/// `from_zero`: the first half sweep is first_red_plane() (x = 0 before; `first` must be red).
template <class T>
void smooth_pair(const BasicPoissonMatrix<T>& a, const std::vector<T>& inverse,
                 const std::vector<T>& b, std::vector<T>& x, int first, bool from_zero) {
    const int nk = a.nk();
    const int second = 1 - first;
    const SeamPlanes<T> none;
    const int slabs = (nk + PIPELINE_PLANES - 1) / PIPELINE_PLANES;
    const auto first_half = [&](int k) {
        if (from_zero)
            first_red_plane(a, inverse, b, x, k);
        else
            smooth_plane<false, T>(a, inverse, b, x, first, k, none);
    };
    tbb::parallel_for(0, slabs, [&](int slab) {
        const int begin = slab * PIPELINE_PLANES;
        const int end = std::min(nk, begin + PIPELINE_PLANES);
        for (int k = begin; k < end; ++k) {
            first_half(k);
            if (k - 1 > begin)
                smooth_plane<false, T>(a, inverse, b, x, second, k - 1, none);
        }
    });
    tbb::parallel_for(0, slabs, [&](int slab) {
        const int begin = slab * PIPELINE_PLANES;
        const int last = std::min(nk, begin + PIPELINE_PLANES) - 1;
        smooth_plane<false, T>(a, inverse, b, x, second, begin, none);
        if (last > begin)
            smooth_plane<false, T>(a, inverse, b, x, second, last, none);
    });
}

/// coarse_b = Pᵀ fine_r on active coarse cells, one axis at a time (P is a tensor product):
/// along x into `along_x` (coarse x, fine y and z), along y into `along_xy`, then along z.
template <class T>
void restrict_residual(const AxisTransfer* t, const BasicPoissonMatrix<T>& fine,
                       const std::vector<T>& fine_r, const BasicPoissonMatrix<T>& coarse,
                       std::vector<T>& coarse_b, std::vector<T>& along_x,
                       std::vector<T>& along_xy) {
    const int fj = fine.nj(), fk = fine.nk();
    const int ci = coarse.ni(), cj = coarse.nj(), ck = coarse.nk();
    const auto ci_s = static_cast<std::size_t>(ci);
    const std::size_t fi_s = static_cast<std::size_t>(fine.ni());
    along_x.resize(ci_s * fj * fk);
    along_xy.resize(ci_s * cj * fk);
    tbb::parallel_for(tbb::blocked_range<int>(0, fk), [&](const tbb::blocked_range<int>& range) {
        for (int k = range.begin(); k != range.end(); ++k)
            for (int j = 0; j < fj; ++j) {
                const std::size_t row = static_cast<std::size_t>(k) * fj + j;
                const T* in = fine_r.data() + row * fi_s;
                T* out = along_x.data() + row * ci_s;
                for (int ii = 0; ii < ci; ++ii) {
                    T sum = T(0);
                    const std::size_t o = static_cast<std::size_t>(ii) * MAX_RESTRICT;
                    for (int s = 0; s < t[0].restrict_count[ii]; ++s)
                        sum += static_cast<T>(t[0].restrict_weight[o + s]) *
                               in[t[0].restrict_cell[o + s]];
                    out[ii] = sum;
                }
            }
    });
    tbb::parallel_for(tbb::blocked_range<int>(0, fk), [&](const tbb::blocked_range<int>& range) {
        for (int k = range.begin(); k != range.end(); ++k)
            for (int jj = 0; jj < cj; ++jj) {
                T* out = along_xy.data() + (static_cast<std::size_t>(k) * cj + jj) * ci_s;
                std::fill(out, out + ci, T(0));
                const std::size_t o = static_cast<std::size_t>(jj) * MAX_RESTRICT;
                for (int s = 0; s < t[1].restrict_count[jj]; ++s) {
                    const auto w = static_cast<T>(t[1].restrict_weight[o + s]);
                    const T* in =
                        along_x.data() +
                        (static_cast<std::size_t>(k) * fj + t[1].restrict_cell[o + s]) * ci_s;
                    for (int ii = 0; ii < ci; ++ii)
                        out[ii] += w * in[ii];
                }
            }
    });
    const std::size_t plane = ci_s * cj;
    tbb::parallel_for(tbb::blocked_range<int>(0, ck), [&](const tbb::blocked_range<int>& range) {
        for (int kk = range.begin(); kk != range.end(); ++kk) {
            T* out = coarse_b.data() + static_cast<std::size_t>(kk) * plane;
            std::fill(out, out + plane, T(0));
            const std::size_t o = static_cast<std::size_t>(kk) * MAX_RESTRICT;
            for (int s = 0; s < t[2].restrict_count[kk]; ++s) {
                const auto w = static_cast<T>(t[2].restrict_weight[o + s]);
                const T* in =
                    along_xy.data() + static_cast<std::size_t>(t[2].restrict_cell[o + s]) * plane;
                for (std::size_t p = 0; p < plane; ++p)
                    out[p] += w * in[p];
            }
            const T* d = coarse.diag.data() + static_cast<std::size_t>(kk) * plane;
            for (std::size_t p = 0; p < plane; ++p)
                if (d[p] <= 0.0)
                    out[p] = T(0);
        }
    });
}

/// fine_x += P coarse_x on active fine cells, one axis at a time: along x into `along_x` (fine
/// x, coarse y and z), along y into `along_xy`, then along z.
template <class T>
void prolong_add(const AxisTransfer* t, const BasicPoissonMatrix<T>& coarse,
                 const std::vector<T>& coarse_x, const BasicPoissonMatrix<T>& fine,
                 std::vector<T>& fine_x, std::vector<T>& along_x, std::vector<T>& along_xy) {
    const int fi = fine.ni(), fj = fine.nj(), fk = fine.nk();
    const int cj = coarse.nj(), ck = coarse.nk();
    const auto fi_s = static_cast<std::size_t>(fi);
    const auto ci_s = static_cast<std::size_t>(coarse.ni());
    along_x.resize(fi_s * cj * ck);
    along_xy.resize(fi_s * fj * ck);
    tbb::parallel_for(tbb::blocked_range<int>(0, ck), [&](const tbb::blocked_range<int>& range) {
        for (int kk = range.begin(); kk != range.end(); ++kk)
            for (int jj = 0; jj < cj; ++jj) {
                const std::size_t row = static_cast<std::size_t>(kk) * cj + jj;
                const T* in = coarse_x.data() + row * ci_s;
                T* out = along_x.data() + row * fi_s;
                for (int i = 0; i < fi; ++i)
                    out[i] =
                        static_cast<T>(t[0].prolong_weight[0][i]) * in[t[0].prolong_cell[0][i]] +
                        static_cast<T>(t[0].prolong_weight[1][i]) * in[t[0].prolong_cell[1][i]];
            }
    });
    tbb::parallel_for(tbb::blocked_range<int>(0, ck), [&](const tbb::blocked_range<int>& range) {
        for (int kk = range.begin(); kk != range.end(); ++kk)
            for (int j = 0; j < fj; ++j) {
                const auto w0 = static_cast<T>(t[1].prolong_weight[0][j]);
                const auto w1 = static_cast<T>(t[1].prolong_weight[1][j]);
                const T* in0 = along_x.data() +
                               (static_cast<std::size_t>(kk) * cj + t[1].prolong_cell[0][j]) * fi_s;
                const T* in1 = along_x.data() +
                               (static_cast<std::size_t>(kk) * cj + t[1].prolong_cell[1][j]) * fi_s;
                T* out = along_xy.data() + (static_cast<std::size_t>(kk) * fj + j) * fi_s;
                for (int i = 0; i < fi; ++i)
                    out[i] = w0 * in0[i] + w1 * in1[i];
            }
    });
    const std::size_t plane = fi_s * fj;
    tbb::parallel_for(tbb::blocked_range<int>(0, fk), [&](const tbb::blocked_range<int>& range) {
        for (int k = range.begin(); k != range.end(); ++k) {
            const auto w0 = static_cast<T>(t[2].prolong_weight[0][k]);
            const auto w1 = static_cast<T>(t[2].prolong_weight[1][k]);
            const T* in0 =
                along_xy.data() + static_cast<std::size_t>(t[2].prolong_cell[0][k]) * plane;
            const T* in1 =
                along_xy.data() + static_cast<std::size_t>(t[2].prolong_cell[1][k]) * plane;
            const T* d = fine.diag.data() + static_cast<std::size_t>(k) * plane;
            T* out = fine_x.data() + static_cast<std::size_t>(k) * plane;
            for (std::size_t p = 0; p < plane; ++p)
                if (d[p] > 0.0)
                    out[p] += w0 * in0[p] + w1 * in1[p];
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

namespace {

/// The coarse levels of a matrix and the transfers between them, in double.
struct Hierarchy {
    std::vector<PoissonMatrix> coarse;  ///< levels 1, 2, …
    /// transfers[l]: from level l to level l + 1
    std::vector<std::array<AxisTransfer, 3>> transfers;
};

Hierarchy build_hierarchy(const PoissonMatrix& fine, const MultigridOptions& options) {
    Hierarchy h;
    while (true) {
        const PoissonMatrix& current = h.coarse.empty() ? fine : h.coarse.back();
        const int largest = std::max({current.ni(), current.nj(), current.nk()});
        if (current.size() <= static_cast<std::size_t>(options.coarsest_max_cells) ||
            largest <= 2) {
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

/// Float's exponent range with a margin for the sums of the smoother and the transfers: a
/// matrix (scaled so its largest entry is about 1) whose smallest positive diagonal entry lies
/// below 2^−MIN_FLOAT_EXPONENT is cycled in double.
constexpr int MIN_FLOAT_EXPONENT = 100;

/// A right-hand side whose largest |entry| lies outside (FLOAT_RANGE_BOTTOM, FLOAT_RANGE_TOP) is
/// scaled by a power of two before the float cycle.
constexpr double FLOAT_RANGE_TOP = 0x1p100;
constexpr double FLOAT_RANGE_BOTTOM = 0x1p-100;

/// The power of two 2^−e that brings the largest |value| near 1 (1 when all are zero).
double power_of_two_scale(double largest) {
    if (!(largest > 0.0) || !std::isfinite(largest))
        return 1.0;
    int exponent = 0;
    std::frexp(largest, &exponent);
    return std::ldexp(1.0, -exponent);
}

/// The largest and the smallest positive diagonal entry of a matrix (no off-diagonal entry is
/// larger in magnitude than its row's diagonal; one that falls below float's range only drops a
/// weak coupling from the preconditioner, a diagonal would drop an unknown).
std::pair<double, double> diagonal_range(const PoissonMatrix& a) {
    using Range = std::pair<double, double>;
    const std::vector<double>& d = a.diag.storage();
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, d.size(), VECTOR_GRAIN),
        Range(0.0, std::numeric_limits<double>::infinity()),
        [&](const tbb::blocked_range<std::size_t>& range, Range found) {
            for (std::size_t c = range.begin(); c != range.end(); ++c)
                if (d[c] > 0.0) {
                    found.first = std::max(found.first, d[c]);
                    found.second = std::min(found.second, d[c]);
                }
            return found;
        },
        [](const Range& x, const Range& y) {
            return Range(std::max(x.first, y.first), std::min(x.second, y.second));
        });
}

/// v in T, clamped to T's finite range (a conversion beyond it is undefined).
template <class T>
T to_t(double v) {
    constexpr double top = static_cast<double>(std::numeric_limits<T>::max());
    return static_cast<T>(std::clamp(v, -top, top));
}

/// `a` × scale in T (scale is a power of two: exact unless T's range is left).
template <class T>
BasicPoissonMatrix<T> converted(const PoissonMatrix& a, double scale) {
    BasicPoissonMatrix<T> out;
    out.periodic = a.periodic;
    out.resize(a.ni(), a.nj(), a.nk());
    for (int axis = -1; axis < 3; ++axis) {
        const std::vector<double>& in = axis < 0 ? a.diag.storage() : a.off(axis).storage();
        std::vector<T>& to = axis < 0 ? out.diag.storage() : out.off(axis).storage();
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, in.size(), VECTOR_GRAIN),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t c = range.begin(); c != range.end(); ++c)
                                  to[c] = to_t<T>(in[c] * scale);
                          });
    }
    return out;
}

}  // namespace

class MultigridPreconditioner::Cycle {
public:
    virtual ~Cycle() = default;
    virtual void apply(const std::vector<double>& r, std::vector<double>& z) const = 0;
    virtual int levels() const = 0;
    virtual bool single_precision() const = 0;
};

namespace {

/// The V-cycle with every level in T. For double, level 0 is the caller's matrix and vectors;
/// for float, a scaled copy of the matrix and the residual (see the file comment).
template <class T>
class VCycle final : public MultigridPreconditioner::Cycle {
public:
    VCycle(const PoissonMatrix& fine, Hierarchy hierarchy, const MultigridOptions& options,
           double matrix_scale)
        : m_options(options), m_matrix_scale(matrix_scale) {
        const std::size_t count = hierarchy.coarse.size() + 1;
        m_levels.resize(count);
        if constexpr (std::is_same_v<T, double>) {
            m_fine = &fine;
            for (std::size_t l = 1; l < count; ++l)
                m_levels[l].matrix = std::move(hierarchy.coarse[l - 1]);
        } else {
            m_levels[0].matrix = converted<T>(fine, matrix_scale);
            m_fine = &m_levels[0].matrix;
            for (std::size_t l = 1; l < count; ++l) {
                m_levels[l].matrix = converted<T>(hierarchy.coarse[l - 1], matrix_scale);
                hierarchy.coarse[l - 1] = PoissonMatrix();
            }
        }
        for (std::size_t l = 0; l + 1 < count; ++l)
            for (std::size_t axis = 0; axis < 3; ++axis)
                m_levels[l].transfer[axis] = std::move(hierarchy.transfers[l][axis]);
        for (std::size_t l = 0; l < count; ++l) {
            const std::size_t n = level_matrix(l).size();
            // Level 0 of the double cycle works on the caller's r and z.
            if (l > 0 || !std::is_same_v<T, double>) {
                m_levels[l].x.assign(n, T(0));
                m_levels[l].b.assign(n, T(0));
            }
            m_levels[l].r.assign(n, T(0));
            const std::vector<T>& d = level_matrix(l).diag.storage();
            std::vector<T>& inverse = m_levels[l].inverse_diagonal;
            inverse.resize(n);
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, VECTOR_GRAIN),
                              [&](const tbb::blocked_range<std::size_t>& range) {
                                  for (std::size_t c = range.begin(); c != range.end(); ++c)
                                      inverse[c] = d[c] > T(0) ? T(1) / d[c] : T(0);
                              });
        }
    }

    void apply(const std::vector<double>& r, std::vector<double>& z) const override {
        z.resize(r.size());
        if constexpr (std::is_same_v<T, double>) {
            cycle(0, r, z);
        } else {
            // M⁻¹ r = s_A / s_r · M_f⁻¹(s_r r) for the float matrix s_A·A and a power of two
            // s_r: 1 unless r leaves float's range (its largest entry then becomes about 1).
            const Level& top = m_levels[0];
            double to_float = 1.0;
            const double largest = to_level(r, to_float, top.b);
            if (!(largest < FLOAT_RANGE_TOP && largest > FLOAT_RANGE_BOTTOM) && largest > 0.0) {
                to_float = power_of_two_scale(largest);
                to_level(r, to_float, top.b);
            }
            cycle(0, top.b, top.x);
            from_level(top.x, m_matrix_scale / to_float, z);
        }
    }
    int levels() const override { return static_cast<int>(m_levels.size()); }
    bool single_precision() const override { return !std::is_same_v<T, double>; }

private:
    struct Level {
        BasicPoissonMatrix<T> matrix;  ///< unused for level 0 of the double cycle (the caller's)
        mutable std::vector<T> x;      ///< correction on this level
        mutable std::vector<T> b;      ///< right-hand side on this level
        mutable std::vector<T> r;      ///< residual scratch
        /// 1 / the diagonal on active cells, 0 on the others: the smoother multiplies by it
        std::vector<T> inverse_diagonal;
        /// the transfers' scratch: after their x pass and after their x and y passes
        mutable std::vector<T> along_x, along_xy;
        AxisTransfer transfer[3];  ///< to the next coarser level
        /// x on the seam planes of periodic axes during a half sweep (smoother scratch)
        mutable SeamPlanes<T> seams;
    };

    const BasicPoissonMatrix<T>& level_matrix(std::size_t level) const {
        return level == 0 ? *m_fine : m_levels[level].matrix;
    }

    /// out = scale · in in T (clamped to T's range); returns the largest |scale · in|.
    static double to_level(const std::vector<double>& in, double scale, std::vector<T>& out) {
        return tbb::parallel_reduce(
            tbb::blocked_range<std::size_t>(0, in.size(), VECTOR_GRAIN), 0.0,
            [&](const tbb::blocked_range<std::size_t>& range, double largest) {
                for (std::size_t c = range.begin(); c != range.end(); ++c) {
                    const double v = in[c] * scale;
                    largest = std::max(largest, std::abs(v));
                    out[c] = to_t<T>(v);
                }
                return largest;
            },
            [](double a, double b) { return std::max(a, b); });
    }
    static void from_level(const std::vector<T>& in, double scale, std::vector<double>& out) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, in.size(), VECTOR_GRAIN),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t c = range.begin(); c != range.end(); ++c)
                                  out[c] = static_cast<double>(in[c]) * scale;
                          });
    }

    /// One V-cycle from x = 0 on `level` for right-hand side b (x is overwritten).
    void cycle(std::size_t level, const std::vector<T>& b, std::vector<T>& x) const {
        const BasicPoissonMatrix<T>& a = level_matrix(level);
        const Level& data = m_levels[level];
        const std::vector<T>& inverse = data.inverse_diagonal;
        constexpr int RED = 0;
        constexpr int BLACK = 1;
        // From x = 0 the first red half-sweep needs no neighbours; it also clears the black cells.
        if (level + 1 == m_levels.size()) {
            first_red_from_zero(a, inverse, b, x);
            // Palindromic order R (B R)^n keeps the coarsest solve a symmetric operator.
            for (int sweep = 0; sweep < m_options.coarsest_sweeps; ++sweep) {
                smooth_colour(a, inverse, b, x, BLACK, data.seams);
                smooth_colour(a, inverse, b, x, RED, data.seams);
            }
            return;
        }
        // Two half sweeps, `first` then the other colour (`from_zero`: the first from x = 0,
        // red); without periodic axes in one pass over memory (smooth_pair()).
        const bool pipelined = m_options.pipelined_sweeps && !a.any_periodic();
        const auto sweep_pair = [&](int first, bool from_zero) {
            if (pipelined) {
                smooth_pair(a, inverse, b, x, first, from_zero);
                return;
            }
            if (from_zero)
                first_red_from_zero(a, inverse, b, x);
            else
                smooth_colour(a, inverse, b, x, first, data.seams);
            smooth_colour(a, inverse, b, x, 1 - first, data.seams);
        };
        sweep_pair(RED, true);
        for (int sweep = 1; sweep < m_options.smoothing_sweeps; ++sweep)
            sweep_pair(RED, false);
        a.residual(x, b, data.r);
        const BasicPoissonMatrix<T>& coarse = level_matrix(level + 1);
        const Level& next = m_levels[level + 1];
        restrict_residual(data.transfer, a, data.r, coarse, next.b, data.along_x, data.along_xy);
        cycle(level + 1, next.b, next.x);
        prolong_add(data.transfer, coarse, next.x, a, x, data.along_x, data.along_xy);
        for (int sweep = 0; sweep < m_options.smoothing_sweeps; ++sweep)
            sweep_pair(BLACK, false);
    }

    MultigridOptions m_options;
    double m_matrix_scale = 1.0;  ///< s_A: the float matrix is s_A · A
    const BasicPoissonMatrix<T>* m_fine = nullptr;
    std::vector<Level> m_levels;
};

}  // namespace

MultigridPreconditioner::MultigridPreconditioner(const PoissonMatrix& matrix,
                                                 const MultigridOptions& options) {
    options.validate();
    Hierarchy hierarchy = build_hierarchy(matrix, options);
    bool single = options.single_precision;
    double scale = 1.0;
    if (single) {
        // Every level's entries are sums and averages of the finest's: its range decides.
        const auto [largest, smallest] = diagonal_range(matrix);
        scale = power_of_two_scale(largest);
        single = largest == 0.0 || (std::isfinite(largest) &&
                                    smallest * scale > std::ldexp(1.0, -MIN_FLOAT_EXPONENT));
    }
    if (single)
        m_cycle = std::make_unique<VCycle<float>>(matrix, std::move(hierarchy), options, scale);
    else
        m_cycle = std::make_unique<VCycle<double>>(matrix, std::move(hierarchy), options, 1.0);
}

MultigridPreconditioner::~MultigridPreconditioner() = default;

int MultigridPreconditioner::levels() const {
    return m_cycle->levels();
}

bool MultigridPreconditioner::single_precision() const {
    return m_cycle->single_precision();
}

void MultigridPreconditioner::apply(const std::vector<double>& r, std::vector<double>& z) const {
    m_cycle->apply(r, z);
}

}  // namespace meniscus::fluid
