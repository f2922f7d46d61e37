#include "fluid/multigrid.h"

#include "fluid/multigrid_hierarchy.h"

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

/// Elements per task in flat conversions and reductions.
constexpr std::size_t VECTOR_GRAIN = 16384;

using AxisTransfer = MultigridPreconditioner::AxisTransfer;

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

/// Cells per chunk of smooth_plane()'s vectorised rows (even, so that a chunk starts on the
/// row's parity).
constexpr int SMOOTH_CHUNK = 256;
static_assert(SMOOTH_CHUNK % 2 == 0, "a chunk must start on an even cell");

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
            // The update is computed for every cell of a chunk of the row into `fresh` (a loop
            // over contiguous cells that vectorises; a stride-2 loop does not), then only this
            // colour's cells are stored: they read only the other colour, which this half sweep
            // leaves as it is, so the result is that of the stride-2 loop, bit for bit.
            const int first = (j + k + colour) % 2;
            for (int i0 = 0; i0 < ni; i0 += SMOOTH_CHUNK) {
                const int len = std::min(SMOOTH_CHUNK, ni - i0);
                const std::size_t c0 = row + static_cast<std::size_t>(i0);
                T fresh[SMOOTH_CHUNK];
                for (int t = 0; t < len; ++t) {
                    const std::size_t c = c0 + static_cast<std::size_t>(t);
                    const T along_x = a_x[c] * xv[c + 1] + a_x[c - 1] * xv[c - 1];
                    const T along_y = a_y[c] * xv[c + sj] + a_y[c - sj] * xv[c - sj];
                    const T along_z = a_z[c] * xv[c + sk] + a_z[c - sk] * xv[c - sk];
                    fresh[t] = (bv[c] - (along_x + along_y + along_z)) * iv[c];
                }
                for (int t = first; t < len; t += 2)  // i0 is even: the colour's parity holds
                    xv[c0 + static_cast<std::size_t>(t)] = fresh[t];
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
                    const std::size_t o = static_cast<std::size_t>(ii) * AXIS_TRANSFER_SLOTS;
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
                const std::size_t o = static_cast<std::size_t>(jj) * AXIS_TRANSFER_SLOTS;
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
            const std::size_t o = static_cast<std::size_t>(kk) * AXIS_TRANSFER_SLOTS;
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
    VCycle(const PoissonMatrix& fine, MultigridHierarchy hierarchy, const MultigridOptions& options,
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
    MultigridHierarchy hierarchy = build_multigrid_hierarchy(matrix, options.coarsest_max_cells);
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
