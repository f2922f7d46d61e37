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
/// Discretely the term adds the energy ½ Δt μ_s (S u)ᵀ K (S u) to the viscous solve's
/// (viscosity.h), with S the interpolation of the face velocities to the surface's points (three
/// components each) and K a 3P × 3P surface stiffness, symmetric positive semidefinite with the
/// uniform motions in its null space (a translation is not damped). Two forms (coupling/
/// implicit_tension.h builds them from the mesh):
///
/// - full, Hysing's: K = L ⊗ I₃, L the surface's cotangent stiffness matrix ∫_Γ ∇φ_p · ∇φ_q dA of
///   the piecewise linear hat functions. It damps every surface velocity gradient, the surface's
///   stretching along itself too: a surface viscosity μ_s = θσΔt, which beside the liquid's μ
///   over a length ℓ makes the interface immobile where μ_s ≫ μℓ.
/// - normal: K = Σ_T K_T ⊗ n_T n_Tᵀ, K_T the triangle's share of L and n_T its unit normal: the
///   energy of the gradient of the velocity's normal component n_T · u within each triangle.
///   Only a motion that changes the surface's shape changes its tension, and this is the part
///   of Hysing's term that sees such motions; the tangential motion of a flat patch is free.
///
/// The fluid solver sees only S, K and μ_s.
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
/// - `stiffness`: K, 3P × 3P, symmetric positive semidefinite, in the rows' order of `sample`
///   (entry (3p + a, 3q + b) couples component a at point p with component b at point q);
///   dimensionless (m² of area over m² of length²).
/// - `viscosity`: μ_s = θσΔt, Pa·s·m (≥ 0).
struct SurfaceViscosity {
    Eigen::SparseMatrix<double, Eigen::RowMajor> sample;
    Eigen::SparseMatrix<double> stiffness;
    double viscosity = 0.0;

    /// P, the number of surface points.
    std::ptrdiff_t points() const { return stiffness.rows() / 3; }
    /// Whether the term acts at all: a positive viscosity on at least one point.
    bool active() const { return viscosity > 0.0 && points() > 0; }

    /// Throws std::invalid_argument naming the field when the sizes do not fit `grid` or each
    /// other, or the viscosity is negative or not finite.
    void validate(const MacGrid& grid) const;

    /// y += c Sᵀ K S x on the flat face vector (sizes F).
    void add_stiffness(double c, const std::vector<double>& x, std::vector<double>& y) const;

    /// d_f += c Σ_r K_rr S_rf², an estimate of the diagonal of c Sᵀ K S that is never negative
    /// (for the full form an upper bound where S ≥ 0 and L's off-diagonal entries are ≤ 0, i.e. no
    /// obtuse angles), for the Jacobi preconditioner.
    void add_diagonal_bound(double c, std::vector<double>& d) const;
};

}  // namespace meniscus::fluid
