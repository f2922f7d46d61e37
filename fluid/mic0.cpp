#include "fluid/mic0.h"

#include <cmath>
#include <stdexcept>

namespace meniscus::fluid {

void Mic0Options::validate() const {
    if (!(tuning >= 0.0 && tuning <= 1.0)) {
        throw std::invalid_argument("Mic0Options.tuning must be in [0, 1]");
    }
    if (!(safety > 0.0 && safety < 1.0)) {
        throw std::invalid_argument("Mic0Options.safety must be in (0, 1)");
    }
}

Mic0Preconditioner::Mic0Preconditioner(const PoissonMatrix& matrix, const Mic0Options& options)
    : m_unwrapped(matrix.any_periodic() ? std::make_unique<PoissonMatrix>(matrix.without_wrap())
                                        : nullptr),
      m_matrix(m_unwrapped ? *m_unwrapped : matrix) {
    options.validate();
    const int ni = matrix.ni(), nj = matrix.nj(), nk = matrix.nk();
    const std::size_t sj = static_cast<std::size_t>(ni);
    const std::size_t sk = static_cast<std::size_t>(ni) * nj;
    const double* a_d = m_matrix.diag.data();
    const double* a_x = m_matrix.off_x.data();
    const double* a_y = m_matrix.off_y.data();
    const double* a_z = m_matrix.off_z.data();
    m_inverse_pivot.assign(matrix.size(), 0.0);
    double* pivot = m_inverse_pivot.data();
    const double tau = options.tuning;
    for (int k = 0; k < nk; ++k) {
        for (int j = 0; j < nj; ++j) {
            for (int i = 0; i < ni; ++i) {
                const std::size_t c = sk * k + sj * j + i;
                if (a_d[c] <= 0.0) {
                    continue;
                }
                double e = a_d[c];
                if (i > 0) {
                    const std::size_t m = c - 1;
                    const double lx = a_x[m] * pivot[m];
                    e -= lx * lx + tau * a_x[m] * (a_y[m] + a_z[m]) * pivot[m] * pivot[m];
                }
                if (j > 0) {
                    const std::size_t m = c - sj;
                    const double ly = a_y[m] * pivot[m];
                    e -= ly * ly + tau * a_y[m] * (a_x[m] + a_z[m]) * pivot[m] * pivot[m];
                }
                if (k > 0) {
                    const std::size_t m = c - sk;
                    const double lz = a_z[m] * pivot[m];
                    e -= lz * lz + tau * a_z[m] * (a_x[m] + a_y[m]) * pivot[m] * pivot[m];
                }
                if (e < options.safety * a_d[c]) {
                    e = a_d[c];
                }
                pivot[c] = 1.0 / std::sqrt(e);
            }
        }
    }
}

void Mic0Preconditioner::apply(const std::vector<double>& r, std::vector<double>& z) const {
    const int ni = m_matrix.ni(), nj = m_matrix.nj(), nk = m_matrix.nk();
    const std::size_t sj = static_cast<std::size_t>(ni);
    const std::size_t sk = static_cast<std::size_t>(ni) * nj;
    const double* a_x = m_matrix.off_x.data();
    const double* a_y = m_matrix.off_y.data();
    const double* a_z = m_matrix.off_z.data();
    const double* pivot = m_inverse_pivot.data();
    z.assign(r.size(), 0.0);
    double* q = z.data();
    // Forward solve L q = r (q stored in z).
    for (int k = 0; k < nk; ++k) {
        for (int j = 0; j < nj; ++j) {
            for (int i = 0; i < ni; ++i) {
                const std::size_t c = sk * k + sj * j + i;
                if (pivot[c] == 0.0) {
                    continue;
                }
                double t = r[c];
                if (i > 0)
                    t -= a_x[c - 1] * pivot[c - 1] * q[c - 1];
                if (j > 0)
                    t -= a_y[c - sj] * pivot[c - sj] * q[c - sj];
                if (k > 0)
                    t -= a_z[c - sk] * pivot[c - sk] * q[c - sk];
                q[c] = t * pivot[c];
            }
        }
    }
    // Backward solve Lᵀ z = q in place.
    for (int k = nk - 1; k >= 0; --k) {
        for (int j = nj - 1; j >= 0; --j) {
            for (int i = ni - 1; i >= 0; --i) {
                const std::size_t c = sk * k + sj * j + i;
                if (pivot[c] == 0.0) {
                    continue;
                }
                double t = q[c];
                if (i + 1 < ni)
                    t -= a_x[c] * pivot[c] * q[c + 1];
                if (j + 1 < nj)
                    t -= a_y[c] * pivot[c] * q[c + sj];
                if (k + 1 < nk)
                    t -= a_z[c] * pivot[c] * q[c + sk];
                q[c] = t * pivot[c];
            }
        }
    }
}

}  // namespace meniscus::fluid
