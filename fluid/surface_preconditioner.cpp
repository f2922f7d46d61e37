#include "fluid/surface_preconditioner.h"

#include "fluid/surface_viscosity.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace meniscus::fluid {

void SurfacePreconditioner::build(const SurfaceViscosity& surface, double scale,
                                  const std::vector<double>& diagonal,
                                  const std::vector<char>& unknown) {
    m_inverse_diagonal.resize(0);
    const Eigen::Index faces = surface.sample.cols();
    if (static_cast<Eigen::Index>(diagonal.size()) != faces ||
        static_cast<Eigen::Index>(unknown.size()) != faces)
        throw std::invalid_argument("SurfacePreconditioner: the diagonal and the unknowns need " +
                                    std::to_string(faces) + " entries, one per face");
    Eigen::VectorXd inverse(faces);
    for (Eigen::Index f = 0; f < faces; ++f) {
        const double d = diagonal[static_cast<std::size_t>(f)];
        if (!unknown[static_cast<std::size_t>(f)]) {
            inverse[f] = 0.0;
            continue;
        }
        if (!(d > 0.0))
            throw std::invalid_argument("SurfacePreconditioner: the diagonal of face " +
                                        std::to_string(f) + " is not positive");
        inverse[f] = 1.0 / d;
    }
    m_system.reset();
    m_stiffness = scale * surface.stiffness;
    if (surface.points() > 0) {
        // S keeps the fixed faces' columns (D⁻¹ is 0 there). G = S D⁻¹ Sᵀ is block diagonal by
        // component (a row of S reads one component's faces); B G couples them only where the
        // normal form's K does.
        const RowMatrix scaled = surface.sample * inverse.asDiagonal();
        const ColumnMatrix gram = scaled * surface.sample.transpose();
        ColumnMatrix system = m_stiffness * gram;
        for (Eigen::Index r = 0; r < system.rows(); ++r)
            system.coeffRef(r, r) += 1.0;
        system.makeCompressed();
        auto lu = std::make_unique<Eigen::SparseLU<ColumnMatrix>>();
        lu->compute(system);
        if (lu->info() != Eigen::Success)
            throw std::invalid_argument(
                "SurfacePreconditioner: the surface system's factorisation failed (" +
                lu->lastErrorMessage() + ")");
        m_system = std::move(lu);
        m_sample = surface.sample;
    }
    m_inverse_diagonal = std::move(inverse);
}

void SurfacePreconditioner::apply(const std::vector<double>& r, std::vector<double>& z) const {
    if (!built())
        throw std::logic_error("SurfacePreconditioner::apply before build");
    const Eigen::Index faces = m_inverse_diagonal.size();
    if (static_cast<Eigen::Index>(r.size()) != faces)
        throw std::invalid_argument("SurfacePreconditioner::apply: r needs one entry per face");
    z.resize(r.size());
    const Eigen::Map<const Eigen::VectorXd> rv(r.data(), faces);
    Eigen::Map<Eigen::VectorXd> zv(z.data(), faces);
    zv = m_inverse_diagonal.cwiseProduct(rv);  // D⁻¹ r
    if (!m_system)
        return;
    const Eigen::VectorXd sampled = m_sample * zv;  // S D⁻¹ r
    const Eigen::VectorXd solved = m_system->solve(m_stiffness * sampled);
    // z −= D⁻¹ Sᵀ (I + B G)⁻¹ B S D⁻¹ r
    for (Eigen::Index row = 0; row < m_sample.outerSize(); ++row)
        for (RowMatrix::InnerIterator it(m_sample, row); it; ++it)
            zv[it.col()] -= m_inverse_diagonal[it.col()] * it.value() * solved[row];
}

}  // namespace meniscus::fluid
