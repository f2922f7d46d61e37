#pragma once
/// \file Compact storage of a symmetric 7-point cell-centred matrix (the pressure Poisson operator
/// and its multigrid coarsenings) and the parallel vector kernels the Krylov solvers use.
///
/// Vectors are std::vector<double> over all ni·nj·nk cells with the Array3 flat index
/// i + ni·(j + nj·k). A cell is an unknown ("active") iff its diagonal is > 0; inactive rows and
/// columns are entirely zero and the kernels keep inactive entries of their outputs at zero.

#include <array>
#include <cstddef>
#include <vector>

#include "fluid/array3.h"

namespace meniscus::fluid {

/// Symmetric 7-point matrix with one diagonal and three off-diagonal arrays (one T each per
/// cell). off_x(i, j, k) = A(cell(i,j,k), cell(i+1,j,k)) ≤ 0, likewise off_y and off_z. Along a
/// `periodic` axis the last cell's entry couples it to the first (off_x(ni−1, j, k) =
/// A(cell(ni−1,j,k), cell(0,j,k)): the face across the periodic seam); along the other axes
/// entries pointing outside the grid are 0. T is double (PoissonMatrix, the systems the solvers
/// solve) or float (the single-precision V-cycles of multigrid.h).
template <class T>
struct BasicPoissonMatrix {
    Array3<T> diag;
    Array3<T> off_x;
    Array3<T> off_y;
    Array3<T> off_z;
    /// Per axis: does the last cell's off-diagonal entry wrap around to the first cell?
    std::array<bool, 3> periodic = {false, false, false};

    /// Zero matrix on ni × nj × nk cells (`periodic` is kept).
    void resize(int ni, int nj, int nk);
    int ni() const { return diag.ni(); }
    int nj() const { return diag.nj(); }
    int nk() const { return diag.nk(); }
    /// Number of cells (rows, including inactive ones).
    std::size_t size() const { return diag.size(); }
    /// Number of active cells (diagonal > 0).
    std::size_t active_count() const;

    /// y = A x (TBB-parallel over z-slabs). x and y have size(); y is resized if needed.
    void apply(const std::vector<T>& x, std::vector<T>& y) const;
    /// y = A x as apply(), returning x·y from the same pass (summed in a fixed order).
    double apply_dot(const std::vector<T>& x, std::vector<T>& y) const;
    /// The off-diagonal array of `axis` (0 → off_x, 1 → off_y, 2 → off_z).
    Array3<T>& off(int axis) { return axis == 0 ? off_x : (axis == 1 ? off_y : off_z); }
    const Array3<T>& off(int axis) const { return axis == 0 ? off_x : (axis == 1 ? off_y : off_z); }
    /// True if some axis is periodic.
    bool any_periodic() const { return periodic[0] || periodic[1] || periodic[2]; }
    /// A copy without the couplings across periodic seams (those entries zeroed, no axis
    /// periodic): the same diagonal, so it stays positive definite where A is semidefinite.
    BasicPoissonMatrix without_wrap() const;

    /// r = b − A x.
    void residual(const std::vector<T>& x, const std::vector<T>& b, std::vector<T>& r) const;
};

// Defined in poisson_matrix.cpp for these two.
extern template struct BasicPoissonMatrix<double>;
extern template struct BasicPoissonMatrix<float>;

using PoissonMatrix = BasicPoissonMatrix<double>;

/// Σ a_i b_i, TBB-parallel with a deterministic reduction order.
double dot(const std::vector<double>& a, const std::vector<double>& b);
/// y += alpha x (TBB-parallel).
void axpy(double alpha, const std::vector<double>& x, std::vector<double>& y);
/// y = x + beta y (TBB-parallel).
void xpby(const std::vector<double>& x, double beta, std::vector<double>& y);
/// r·r and r·z after a conjugate-gradient update.
struct ResidualDots {
    double rr = 0.0;
    double rz = 0.0;
};
/// One Jacobi-preconditioned CG update in a single pass: x += alpha p, r −= alpha q, z = r / d,
/// returning r·r and r·z (summed in dot()'s order, so the same values as separate calls).
ResidualDots jacobi_cg_update(double alpha, const std::vector<double>& p,
                              const std::vector<double>& q, const std::vector<double>& d,
                              std::vector<double>& x, std::vector<double>& r,
                              std::vector<double>& z);
/// The start of a Jacobi-preconditioned CG in a single pass: r = b − q (q = A x₀), z = r / d,
/// p = z, returning r·r and r·z (summed in dot()'s order). Resizes r, z and p to b's size.
ResidualDots jacobi_cg_start(const std::vector<double>& b, const std::vector<double>& q,
                             const std::vector<double>& d, std::vector<double>& r,
                             std::vector<double>& z, std::vector<double>& p);
/// Subtracts the mean over active cells of `matrix` from x on those cells (projection onto the
/// complement of the constant null space of a pure-Neumann operator).
void remove_active_mean(const PoissonMatrix& matrix, std::vector<double>& x);

}  // namespace meniscus::fluid
