#include "fluid/poisson_matrix.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <functional>
#include <utility>

namespace meniscus::fluid {

namespace {

/// Elements per task in flat vector kernels: large enough to amortise scheduling.
constexpr std::size_t VECTOR_GRAIN = 16384;

}  // namespace

template <class T>
void BasicPoissonMatrix<T>::resize(int ni, int nj, int nk) {
    diag.resize(ni, nj, nk, T(0));
    off_x.resize(ni, nj, nk, T(0));
    off_y.resize(ni, nj, nk, T(0));
    off_z.resize(ni, nj, nk, T(0));
}

template <class T>
std::size_t BasicPoissonMatrix<T>::active_count() const {
    std::size_t count = 0;
    for (T d : diag.storage()) {
        count += d > 0.0 ? 1 : 0;
    }
    return count;
}

namespace {

/// Planes per task of apply_dot(): a fixed split, so its sum does not depend on the threads.
constexpr int DOT_PLANES = 2;

/// y = A x on planes [k_begin, k_end); `Wrap` false compiles the loop without the seam's
/// branches. With `Dot`, returns Σ x·y over those planes (row by row, in order; each row's x and
/// y are still in cache), else 0.
template <bool Wrap, bool Dot, class T>
double apply_planes(const BasicPoissonMatrix<T>& a, const std::vector<T>& x, std::vector<T>& y,
                    int k_begin, int k_end) {
    const int n_i = a.ni(), n_j = a.nj(), n_k = a.nk();
    const std::size_t sj = static_cast<std::size_t>(n_i);
    const std::size_t sk = static_cast<std::size_t>(n_i) * n_j;
    const T* a_d = a.diag.data();
    const T* a_x = a.off_x.data();
    const T* a_y = a.off_y.data();
    const T* a_z = a.off_z.data();
    const T* xv = x.data();
    T* yv = y.data();
    // Distance back to the first cell from the last along each axis (the periodic seam).
    const std::size_t wrap_x = sj - 1, wrap_y = sj * (n_j - 1), wrap_z = sk * (n_k - 1);
    const bool px = Wrap && a.periodic[0], py = Wrap && a.periodic[1], pz = Wrap && a.periodic[2];
    double dot = 0.0;
    for (int k = k_begin; k != k_end; ++k) {
        for (int j = 0; j < n_j; ++j) {
            const std::size_t row = sk * k + sj * j;
            if (!Wrap && j > 0 && j + 1 < n_j && k > 0 && k + 1 < n_k) {
                // A row inside the box along y and z: past its ends the couplings are zero
                // (off_x is 0 at the far end of a bounded axis, the previous row's last
                // included) and the cells read there lie inside the array: no tests, so the
                // loop vectorises.
                for (int i = 0; i < n_i; ++i) {
                    const std::size_t c = row + i;
                    T sum = a_d[c] * xv[c];
                    sum += a_x[c] * xv[c + 1];
                    sum += a_x[c - 1] * xv[c - 1];
                    sum += a_y[c] * xv[c + sj];
                    sum += a_y[c - sj] * xv[c - sj];
                    sum += a_z[c] * xv[c + sk];
                    sum += a_z[c - sk] * xv[c - sk];
                    yv[c] = a_d[c] > 0.0 ? sum : T(0);
                }
            } else {
                for (int i = 0; i < n_i; ++i) {
                    const std::size_t c = row + i;
                    if (a_d[c] <= 0.0) {
                        yv[c] = T(0);
                        continue;
                    }
                    T sum = a_d[c] * xv[c];
                    if (i + 1 < n_i)
                        sum += a_x[c] * xv[c + 1];
                    else if (Wrap && px)
                        sum += a_x[c] * xv[c - wrap_x];
                    if (i > 0)
                        sum += a_x[c - 1] * xv[c - 1];
                    else if (Wrap && px)
                        sum += a_x[c + wrap_x] * xv[c + wrap_x];
                    if (j + 1 < n_j)
                        sum += a_y[c] * xv[c + sj];
                    else if (Wrap && py)
                        sum += a_y[c] * xv[c - wrap_y];
                    if (j > 0)
                        sum += a_y[c - sj] * xv[c - sj];
                    else if (Wrap && py)
                        sum += a_y[c + wrap_y] * xv[c + wrap_y];
                    if (k + 1 < n_k)
                        sum += a_z[c] * xv[c + sk];
                    else if (Wrap && pz)
                        sum += a_z[c] * xv[c - wrap_z];
                    if (k > 0)
                        sum += a_z[c - sk] * xv[c - sk];
                    else if (Wrap && pz)
                        sum += a_z[c + wrap_z] * xv[c + wrap_z];
                    yv[c] = sum;
                }
            }
            if (Dot)
                for (int i = 0; i < n_i; ++i)
                    dot += static_cast<double>(xv[row + i]) * static_cast<double>(yv[row + i]);
        }
    }
    return dot;
}

template <bool Wrap, class T>
void apply_kernel(const BasicPoissonMatrix<T>& a, const std::vector<T>& x, std::vector<T>& y) {
    tbb::parallel_for(tbb::blocked_range<int>(0, a.nk()),
                      [&](const tbb::blocked_range<int>& range) {
                          apply_planes<Wrap, false>(a, x, y, range.begin(), range.end());
                      });
}

template <bool Wrap, class T>
double apply_dot_kernel(const BasicPoissonMatrix<T>& a, const std::vector<T>& x,
                        std::vector<T>& y) {
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<int>(0, a.nk(), DOT_PLANES), 0.0,
        [&](const tbb::blocked_range<int>& range, double sum) {
            return sum + apply_planes<Wrap, true>(a, x, y, range.begin(), range.end());
        },
        std::plus<double>());
}

}  // namespace

template <class T>
void BasicPoissonMatrix<T>::apply(const std::vector<T>& x, std::vector<T>& y) const {
    y.resize(size());
    if (any_periodic())
        apply_kernel<true>(*this, x, y);
    else
        apply_kernel<false>(*this, x, y);
}

template <class T>
double BasicPoissonMatrix<T>::apply_dot(const std::vector<T>& x, std::vector<T>& y) const {
    y.resize(size());
    return any_periodic() ? apply_dot_kernel<true>(*this, x, y)
                          : apply_dot_kernel<false>(*this, x, y);
}

template <class T>
BasicPoissonMatrix<T> BasicPoissonMatrix<T>::without_wrap() const {
    BasicPoissonMatrix copy = *this;
    for (int axis = 0; axis < 3; ++axis) {
        if (!periodic[static_cast<std::size_t>(axis)])
            continue;
        Array3<T>& entries = copy.off(axis);
        const int last = (axis == 0 ? ni() : (axis == 1 ? nj() : nk())) - 1;
        for (int k = 0; k < nk(); ++k)
            for (int j = 0; j < nj(); ++j)
                for (int i = 0; i < ni(); ++i)
                    if ((axis == 0 ? i : (axis == 1 ? j : k)) == last)
                        entries(i, j, k) = T(0);
    }
    copy.periodic = {false, false, false};
    return copy;
}

template <class T>
void BasicPoissonMatrix<T>::residual(const std::vector<T>& x, const std::vector<T>& b,
                                     std::vector<T>& r) const {
    apply(x, r);
    const T* bv = b.data();
    const T* a_d = diag.data();
    T* rv = r.data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, r.size(), VECTOR_GRAIN),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t c = range.begin(); c != range.end(); ++c) {
                              rv[c] = a_d[c] > T(0) ? bv[c] - rv[c] : T(0);
                          }
                      });
}

template struct BasicPoissonMatrix<double>;
template struct BasicPoissonMatrix<float>;

double dot(const std::vector<double>& a, const std::vector<double>& b) {
    const double* av = a.data();
    const double* bv = b.data();
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, a.size(), VECTOR_GRAIN), 0.0,
        [&](const tbb::blocked_range<std::size_t>& range, double sum) {
            for (std::size_t c = range.begin(); c != range.end(); ++c) {
                sum += av[c] * bv[c];
            }
            return sum;
        },
        std::plus<double>());
}

namespace {

/// The join of the Jacobi-CG passes' reductions.
ResidualDots add_dots(const ResidualDots& a, const ResidualDots& b) {
    return ResidualDots{a.rr + b.rr, a.rz + b.rz};
}

}  // namespace

ResidualDots jacobi_cg_update(double alpha, const std::vector<double>& p,
                              const std::vector<double>& q, const std::vector<double>& d,
                              std::vector<double>& x, std::vector<double>& r,
                              std::vector<double>& z) {
    const double* pv = p.data();
    const double* qv = q.data();
    const double* dv = d.data();
    double* xv = x.data();
    double* rv = r.data();
    double* zv = z.data();
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, r.size(), VECTOR_GRAIN), ResidualDots{},
        [&](const tbb::blocked_range<std::size_t>& range, ResidualDots sums) {
            for (std::size_t c = range.begin(); c != range.end(); ++c) {
                xv[c] += alpha * pv[c];
                rv[c] -= alpha * qv[c];
                zv[c] = rv[c] / dv[c];
                sums.rr += rv[c] * rv[c];
                sums.rz += rv[c] * zv[c];
            }
            return sums;
        },
        add_dots);
}

ResidualDots jacobi_cg_start(const std::vector<double>& b, const std::vector<double>& q,
                             const std::vector<double>& d, std::vector<double>& r,
                             std::vector<double>& z, std::vector<double>& p) {
    r.resize(b.size());
    z.resize(b.size());
    p.resize(b.size());
    const double* bv = b.data();
    const double* qv = q.data();
    const double* dv = d.data();
    double* rv = r.data();
    double* zv = z.data();
    double* pv = p.data();
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, b.size(), VECTOR_GRAIN), ResidualDots{},
        [&](const tbb::blocked_range<std::size_t>& range, ResidualDots sums) {
            for (std::size_t c = range.begin(); c != range.end(); ++c) {
                rv[c] = bv[c] - qv[c];
                zv[c] = rv[c] / dv[c];
                pv[c] = zv[c];
                sums.rr += rv[c] * rv[c];
                sums.rz += rv[c] * zv[c];
            }
            return sums;
        },
        add_dots);
}

void axpy(double alpha, const std::vector<double>& x, std::vector<double>& y) {
    const double* xv = x.data();
    double* yv = y.data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, y.size(), VECTOR_GRAIN),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t c = range.begin(); c != range.end(); ++c) {
                              yv[c] += alpha * xv[c];
                          }
                      });
}

void xpby(const std::vector<double>& x, double beta, std::vector<double>& y) {
    const double* xv = x.data();
    double* yv = y.data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, y.size(), VECTOR_GRAIN),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t c = range.begin(); c != range.end(); ++c) {
                              yv[c] = xv[c] + beta * yv[c];
                          }
                      });
}

void remove_active_mean(const PoissonMatrix& matrix, std::vector<double>& x) {
    const double* a_d = matrix.diag.data();
    double* xv = x.data();
    using SumCount = std::pair<double, std::size_t>;
    const SumCount total = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, x.size(), VECTOR_GRAIN), SumCount(0.0, 0),
        [&](const tbb::blocked_range<std::size_t>& range, SumCount partial) {
            for (std::size_t c = range.begin(); c != range.end(); ++c) {
                if (a_d[c] > 0.0) {
                    partial.first += xv[c];
                    ++partial.second;
                }
            }
            return partial;
        },
        [](const SumCount& a, const SumCount& b) {
            return SumCount(a.first + b.first, a.second + b.second);
        });
    if (total.second == 0) {
        return;
    }
    const double mean = total.first / static_cast<double>(total.second);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, x.size(), VECTOR_GRAIN),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t c = range.begin(); c != range.end(); ++c) {
                              if (a_d[c] > 0.0) {
                                  xv[c] -= mean;
                              }
                          }
                      });
}

}  // namespace meniscus::fluid
