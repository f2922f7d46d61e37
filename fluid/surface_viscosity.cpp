#include "fluid/surface_viscosity.h"

#include "fluid/mac_grid.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace meniscus::fluid {

void SurfaceViscosity::validate(const MacGrid& grid) const {
    const std::ptrdiff_t faces = static_cast<std::ptrdiff_t>(
        grid.u().size() + grid.v().size() + grid.w().size());
    if (stiffness.rows() != stiffness.cols() || stiffness.rows() % 3 != 0)
        throw std::invalid_argument(
            "SurfaceViscosity.stiffness must be square with 3 rows per surface point");
    if (sample.rows() != stiffness.rows())
        throw std::invalid_argument("SurfaceViscosity.sample must have the stiffness's " +
                                    std::to_string(stiffness.rows()) + " rows");
    if (sample.cols() != faces)
        throw std::invalid_argument("SurfaceViscosity.sample must have one column per face (" +
                                    std::to_string(faces) + ")");
    if (!(viscosity >= 0.0) || !std::isfinite(viscosity))
        throw std::invalid_argument("SurfaceViscosity.viscosity must be a finite number >= 0");
}

void SurfaceViscosity::add_stiffness(double c, const std::vector<double>& x,
                                     std::vector<double>& y) const {
    const std::ptrdiff_t p = points();
    if (p == 0 || c == 0.0)
        return;
    const Eigen::Map<const Eigen::VectorXd> xv(x.data(), static_cast<Eigen::Index>(x.size()));
    // s = S x (the point velocities), t = K s.
    const Eigen::VectorXd s = sample * xv;
    const Eigen::VectorXd t = stiffness * s;
    // y += c Sᵀ t, scattered row by row: Sᵀ t as an expression would build a dense temporary of
    // all F faces (8 M entries at 128 cells, every CG iteration) to fill a few per point.
    for (Eigen::Index row = 0; row < sample.outerSize(); ++row) {
        const double scaled = c * t[row];
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(sample, row); it;
             ++it)
            y[static_cast<std::size_t>(it.col())] += scaled * it.value();
    }
}

void SurfaceViscosity::add_diagonal_bound(double c, std::vector<double>& d) const {
    if (points() == 0 || c == 0.0)
        return;
    const Eigen::VectorXd diagonal = stiffness.diagonal();
    for (Eigen::Index row = 0; row < sample.outerSize(); ++row) {
        const double l = diagonal[row];
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(sample, row); it;
             ++it)
            d[static_cast<std::size_t>(it.col())] += c * l * it.value() * it.value();
    }
}

}  // namespace meniscus::fluid
