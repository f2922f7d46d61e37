#include "fluid/surface_preconditioner.h"

#include "fluid/surface_viscosity.h"

#include <tbb/parallel_for.h>

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
    const Eigen::Index points = surface.points();
    m_stiffness = scale * surface.laplacian;
    const auto build_component = [&](std::size_t a) {
        // The rows 3p + a of S, with the fixed faces' columns kept (D⁻¹ is 0 there).
        std::vector<Eigen::Triplet<double>> entries;
        for (Eigen::Index p = 0; p < points; ++p)
            for (RowMatrix::InnerIterator it(surface.sample, 3 * p + static_cast<Eigen::Index>(a));
                 it; ++it)
                entries.emplace_back(static_cast<int>(p), static_cast<int>(it.col()), it.value());
        RowMatrix& sample = m_sample[a];
        sample.resize(points, faces);
        sample.setFromTriplets(entries.begin(), entries.end());
        m_system[a].reset();
        if (points == 0)
            return;
        const RowMatrix scaled = sample * inverse.asDiagonal();
        const ColumnMatrix gram = scaled * sample.transpose();  // G = S D⁻¹ Sᵀ
        ColumnMatrix system = m_stiffness * gram;
        for (Eigen::Index p = 0; p < points; ++p)
            system.coeffRef(p, p) += 1.0;
        system.makeCompressed();
        auto lu = std::make_unique<Eigen::SparseLU<ColumnMatrix>>();
        lu->compute(system);
        if (lu->info() != Eigen::Success)
            throw std::invalid_argument(
                "SurfacePreconditioner: the surface system's factorisation failed (" +
                lu->lastErrorMessage() + ")");
        m_system[a] = std::move(lu);
    };
    tbb::parallel_for(std::size_t{0}, std::size_t{3}, build_component);
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
    // Each component's correction reads z = D⁻¹ r on its own faces and writes there only, so
    // the three run side by side on z.
    tbb::parallel_for(std::size_t{0}, std::size_t{3}, [&](std::size_t a) {
        if (!m_system[a])
            return;
        const RowMatrix& sample = m_sample[a];
        const Eigen::VectorXd sampled = sample * zv;  // S D⁻¹ r
        const Eigen::VectorXd solved = m_system[a]->solve(m_stiffness * sampled);
        for (Eigen::Index p = 0; p < sample.outerSize(); ++p)  // z −= D⁻¹ Sᵀ (I + B G)⁻¹ B S D⁻¹ r
            for (RowMatrix::InnerIterator it(sample, p); it; ++it)
                zv[it.col()] -= m_inverse_diagonal[it.col()] * it.value() * solved[p];
    });
}

}  // namespace meniscus::fluid
