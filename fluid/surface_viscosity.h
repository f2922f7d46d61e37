#pragma once
/// \file The implicit part of semi-implicit surface tension (Hysing 2006), as a surface viscosity
/// in the backward-Euler viscous solve.
///
/// Surface tension in weak form is −∫_Γ σ ∇_Γ x : ∇_Γ v dA (the Laplace–Beltrami identity
/// κ n = Δ_Γ x). Evaluating it on the surface a fraction θ of the step ahead,
/// x + θ Δt u⁽ⁿ⁺¹⁾, splits it into the explicit tension of the surface at the start of the step
/// (the ghost-fluid jump σκ, pressure.h) and −θΔt ∫_Γ σ ∇_Γ u⁽ⁿ⁺¹⁾ : ∇_Γ v dA: a surface viscosity
/// μ_s = θσΔt acting on the new velocity. It damps the capillary waves of the grid scale instead of
/// letting them grow, so Δt may exceed the explicit capillary limit (a capillary mode with
/// a = (ωΔt)² is amplified by 1/sqrt(1 + θa) per step, unconditionally stable for θ > 0, at a
/// frequency error of O(a)).
///
/// Discretely the term adds the energy ½ Δt μ_s Σ_axes (S_a u)ᵀ L (S_a u) to the viscous solve's
/// (viscosity.h), with S_a the interpolation of face velocity component a to the surface's
/// points and L the surface's cotangent stiffness matrix, ∫_Γ ∇φ_p · ∇φ_q dA of the piecewise
/// linear hat functions (dimensionless, symmetric positive semidefinite, constants in its null
/// space, so a uniform motion is not damped). The fluid solver sees only S, L and μ_s: coupling/
/// builds them from the mesh.

#include <Eigen/SparseCore>

#include <cstddef>
#include <vector>

namespace meniscus::fluid {

class MacGrid;

/// The surface-viscosity term of one step.
///
/// - `sample`: (3P) × F, row 3p + a the weights of face velocity component a at point p, over
///   the flat face vector [u | v | w] of the grid (column offset_a + MacGrid::velocity(a).index(i,
///   j, k), offset_0 = 0, offset_1 = |u|, offset_2 = |u| + |v|).
/// - `laplacian`: P × P, symmetric, L_pq = ∫_Γ ∇φ_p · ∇φ_q dA.
/// - `viscosity`: μ_s = θσΔt, Pa·s·m (≥ 0).
struct SurfaceViscosity {
    Eigen::SparseMatrix<double, Eigen::RowMajor> sample;
    Eigen::SparseMatrix<double> laplacian;
    double viscosity = 0.0;

    /// P, the number of surface points.
    std::ptrdiff_t points() const { return laplacian.rows(); }
    /// Whether the term acts at all: a positive viscosity on at least one point.
    bool active() const { return viscosity > 0.0 && points() > 0; }

    /// Throws std::invalid_argument naming the field when the sizes do not fit `grid` or each
    /// other, or the viscosity is negative or not finite.
    void validate(const MacGrid& grid) const;

    /// y += c Sᵀ (L ⊗ I₃) S x on the flat face vector (sizes F).
    void add_stiffness(double c, const std::vector<double>& x, std::vector<double>& y) const;

    /// d_f += c Σ_p L_pp S_(p,a),f², an estimate of the diagonal of c Sᵀ (L ⊗ I₃) S that is
    /// never negative (an upper bound where S ≥ 0 and L's off-diagonal entries are ≤ 0, i.e. no
    /// obtuse angles), for the Jacobi preconditioner.
    void add_diagonal_bound(double c, std::vector<double>& d) const;
};

}  // namespace meniscus::fluid
