#pragma once
/// \file The viscous CG's Jacobi preconditioner made exact for the semi-implicit tension's surface
/// term (surface_viscosity.h).
///
/// With the surface viscosity the viscous operator is A = D + R + Sᵀ B S: D its grid part's
/// diagonal, R the grid part's off-diagonal couplings, B = c K the surface stiffness on the
/// sampled point velocities (c = Δt μ_s / Δx³). Past the capillary limit the surface term
/// can outweigh the faces' mass by far, and only along the surface: with the term sampled
/// trilinearly (gas faces and all) the plain diagonal left bubble_merge's coupled step at 3× the
/// limit with 300 iterations, against 76 with this preconditioner; sampled by face density, as
/// coupling/ builds it, the term is milder (100 against 70). This preconditioner is the exact
/// inverse of D + Sᵀ B S (Woodbury):
///
///   M⁻¹ = D⁻¹ − D⁻¹ Sᵀ (I + B G)⁻¹ B S D⁻¹,  G = S D⁻¹ Sᵀ,
///
/// a 3P × 3P sparse system (G is block diagonal by component, since a row of S samples one
/// component's faces; K couples the components only in its normal form), factorised once per
/// operator with a sparse LU.
/// I + B G is invertible (B G ~ G^½ B G^½ ⪰ 0), and M⁻¹ is symmetric positive definite, being
/// the inverse of D + Sᵀ B S. Where R is small beside D (water and air: ρ/Δt ≫ μ/Δx²), M⁻¹ is
/// close to A⁻¹ itself.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <memory>
#include <vector>

namespace meniscus::fluid {

struct SurfaceViscosity;

class SurfacePreconditioner {
public:
    /// Builds M⁻¹ for `surface` scaled by `scale` (c above) and the diagonal `diagonal` of the
    /// grid part of the operator over the flat face vector [u | v | w], on the faces where
    /// `unknown` is 1 (elsewhere M⁻¹ is 0). Throws std::invalid_argument when the sizes do not
    /// fit, a diagonal entry of an unknown is not positive, or the factorisation fails.
    void build(const SurfaceViscosity& surface, double scale, const std::vector<double>& diagonal,
               const std::vector<char>& unknown);

    /// z = M⁻¹ r (sizes F).
    void apply(const std::vector<double>& r, std::vector<double>& z) const;

    /// Whether build() has succeeded.
    bool built() const { return m_inverse_diagonal.size() > 0; }

private:
    using RowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
    using ColumnMatrix = Eigen::SparseMatrix<double>;
    Eigen::VectorXd m_inverse_diagonal;  ///< D⁻¹, 0 on fixed faces
    RowMatrix m_sample;                  ///< S (3P × F)
    ColumnMatrix m_stiffness;            ///< B = c K (3P × 3P)
    /// I + B G, factorised (a null pointer when there are no points)
    std::unique_ptr<Eigen::SparseLU<ColumnMatrix>> m_system;
};

}  // namespace meniscus::fluid
