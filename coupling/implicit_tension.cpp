#include "coupling/implicit_tension.h"

#include "fluid/interface_input.h"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace meniscus::coupling {

namespace {

using Eigen::Vector3d;
using Triplet = Eigen::Triplet<double>;
using RowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

/// ρ_f of the face at flat index `column` of [u | v | w]: ρ_g + (ρ_l − ρ_g) θ, θ the liquid
/// fraction of the segment between its cells (a face on the box's boundary: its one cell's).
double face_density(const fluid::MacGrid& grid, const fluid::Array3<double>& phi,
                    std::size_t column, double rho_liquid, double rho_gas) {
    int axis = 0;
    while (column >= grid.velocity(axis).size()) {
        column -= grid.velocity(axis).size();
        ++axis;
    }
    const fluid::Array3<double>& faces = grid.velocity(axis);
    const std::size_t ni = static_cast<std::size_t>(faces.ni());
    const std::size_t nj = static_cast<std::size_t>(faces.nj());
    std::array<int, 3> above = {static_cast<int>(column % ni), static_cast<int>((column / ni) % nj),
                                static_cast<int>(column / (ni * nj))};
    std::array<int, 3> below = above;
    --below[static_cast<std::size_t>(axis)];
    const int cells = axis == 0 ? grid.nx() : axis == 1 ? grid.ny() : grid.nz();
    if (below[static_cast<std::size_t>(axis)] < 0)
        below = above;
    if (above[static_cast<std::size_t>(axis)] >= cells)
        above = below;
    const double theta = fluid::liquid_fraction(phi(below[0], below[1], below[2]),
                                                phi(above[0], above[1], above[2]));
    return rho_gas + (rho_liquid - rho_gas) * theta;
}

/// Throws std::invalid_argument, naming `caller`, unless `phi` has the grid's cells and the
/// densities weight_by_face_density() reads are valid (ρ_liquid > 0, ρ_gas ≥ 0, both finite).
void check_density_weighting(const fluid::MacGrid& grid, const fluid::Array3<double>& phi,
                             double rho_liquid, double rho_gas, const std::string& caller) {
    if (phi.ni() != grid.nx() || phi.nj() != grid.ny() || phi.nk() != grid.nz())
        throw std::invalid_argument(caller + ": phi must have the grid's cells");
    if (!(rho_liquid > 0.0 && rho_gas >= 0.0) || !std::isfinite(rho_liquid) ||
        !std::isfinite(rho_gas))
        throw std::invalid_argument(caller + ": rho_liquid must be > 0 and rho_gas >= 0");
}

/// Scales each row of `sample` by the densities of the faces it reads and rescales it to its
/// old sum (a row that reads only massless faces is left as it was).
void weight_by_face_density(RowMatrix& sample, const fluid::MacGrid& grid,
                            const fluid::Array3<double>& phi, double rho_liquid, double rho_gas) {
    std::vector<double> density;  // of the row's faces, in the row's order
    for (Eigen::Index row = 0; row < sample.outerSize(); ++row) {
        double sum = 0.0, weighted = 0.0;
        density.clear();
        for (RowMatrix::InnerIterator it(sample, row); it; ++it) {
            density.push_back(face_density(grid, phi, static_cast<std::size_t>(it.col()),
                                           rho_liquid, rho_gas));
            sum += it.value();
            weighted += it.value() * density.back();
        }
        if (!(weighted > 0.0))
            continue;
        std::size_t entry = 0;
        for (RowMatrix::InnerIterator it(sample, row); it; ++it)
            it.valueRef() *= density[entry++] * sum / weighted;
    }
}

}  // namespace

std::shared_ptr<const fluid::SurfaceViscosity> build_surface_viscosity(
    const tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid, double viscosity,
    const InterpolateOptions& interpolate, const fluid::BoundaryOptions& walls,
    const fluid::Array3<double>* phi, double rho_liquid, double rho_gas, SurfaceTermForm form) {
    if (!(viscosity >= 0.0) || !std::isfinite(viscosity))
        throw std::invalid_argument("build_surface_viscosity: viscosity must be finite and >= 0");
    if (form != SurfaceTermForm::normal && form != SurfaceTermForm::full)
        throw std::invalid_argument("build_surface_viscosity: unknown form");
    if (phi)
        check_density_weighting(grid, *phi, rho_liquid, rho_gas, "build_surface_viscosity");
    const Vector3d lo = grid.origin();
    const Vector3d hi = lo + grid.dx() * Vector3d(grid.nx(), grid.ny(), grid.nz());
    const auto inside = [&](const Vector3d& x) {
        return (x.array() >= lo.array()).all() && (x.array() <= hi.array()).all();
    };
    // Points: the vertices of the triangles inside the box, numbered in vertex order.
    std::vector<int> point(static_cast<size_t>(mesh.num_vertices()), -1);
    std::vector<int> triangles;
    for (int t = 0; t < mesh.num_triangles(); ++t) {
        if (!mesh.triangle_alive(t))
            continue;
        const tracker::Triangle& tri = mesh.triangle(t);
        if (inside(mesh.position(tri[0])) && inside(mesh.position(tri[1])) &&
            inside(mesh.position(tri[2]))) {
            triangles.push_back(t);
            for (int v : tri)
                point[static_cast<size_t>(v)] = 0;
        }
    }
    std::vector<int> vertices;
    for (int v = 0; v < mesh.num_vertices(); ++v)
        if (point[static_cast<size_t>(v)] == 0) {
            point[static_cast<size_t>(v)] = static_cast<int>(vertices.size());
            vertices.push_back(v);
        }
    const Eigen::Index points = static_cast<Eigen::Index>(vertices.size());
    auto term = std::make_shared<fluid::SurfaceViscosity>();
    term->viscosity = viscosity;
    // The surface moves with the interpolated vertex velocities: the term must see them.
    term->sample = vertex_velocity_weights(grid, mesh, vertices, interpolate, walls);
    if (phi)
        weight_by_face_density(term->sample, grid, *phi, rho_liquid, rho_gas);
    // Cotangent stiffness: each triangle adds ½ cot θ_i to the edge opposite its corner i, as the
    // 3 × 3 block I₃ (full) or n_T n_Tᵀ (normal) on the two points' velocities.
    std::vector<Triplet> entries;
    entries.reserve(triangles.size() * 3 * 4 * (form == SurfaceTermForm::full ? 3 : 9));
    const auto add_block = [&](Eigen::Index p, Eigen::Index q, double w, const Vector3d& n) {
        for (Eigen::Index a = 0; a < 3; ++a) {
            if (form == SurfaceTermForm::full) {
                entries.emplace_back(3 * p + a, 3 * q + a, w);
                continue;
            }
            for (Eigen::Index b = 0; b < 3; ++b)
                entries.emplace_back(3 * p + a, 3 * q + b, w * n[a] * n[b]);
        }
    };
    for (int t : triangles) {
        const tracker::Triangle& tri = mesh.triangle(t);
        const Vector3d area_normal = (mesh.position(tri[1]) - mesh.position(tri[0]))
                                         .cross(mesh.position(tri[2]) - mesh.position(tri[0]));
        const double twice_area = area_normal.norm();
        if (!(twice_area > 0.0))
            continue;  // degenerate: no gradient to penalise, no normal
        const Vector3d n = area_normal / twice_area;
        for (int c = 0; c < 3; ++c) {
            const int i = tri[static_cast<size_t>(c)];
            const int j = tri[static_cast<size_t>((c + 1) % 3)];
            const int k = tri[static_cast<size_t>((c + 2) % 3)];
            const Vector3d a = mesh.position(j) - mesh.position(i);
            const Vector3d b = mesh.position(k) - mesh.position(i);
            const double sine = a.cross(b).norm();
            if (!(sine > 1e-12 * a.norm() * b.norm()))
                continue;  // a degenerate corner: cot unbounded
            const double w = 0.5 * a.dot(b) / sine;
            const Eigen::Index pj = point[static_cast<size_t>(j)];
            const Eigen::Index pk = point[static_cast<size_t>(k)];
            add_block(pj, pk, -w, n);
            add_block(pk, pj, -w, n);
            add_block(pj, pj, w, n);
            add_block(pk, pk, w, n);
        }
    }
    term->stiffness.resize(3 * points, 3 * points);
    term->stiffness.setFromTriplets(entries.begin(), entries.end());
    return term;
}

std::vector<tracker::Vec3> term_vertex_velocities(const tracker::SurfaceMesh& mesh,
                                                  const fluid::MacGrid& grid,
                                                  const InterpolateOptions& interpolate,
                                                  const fluid::BoundaryOptions& walls,
                                                  const fluid::Array3<double>& phi,
                                                  double rho_liquid, double rho_gas) {
    check_density_weighting(grid, phi, rho_liquid, rho_gas, "term_vertex_velocities");
    std::vector<int> vertices;
    for (int v = 0; v < mesh.num_vertices(); ++v)
        if (mesh.vertex_alive(v))
            vertices.push_back(v);
    RowMatrix sample = vertex_velocity_weights(grid, mesh, vertices, interpolate, walls);
    weight_by_face_density(sample, grid, phi, rho_liquid, rho_gas);
    // The flat face vector [u | v | w] the columns index.
    Eigen::VectorXd faces(sample.cols());
    Eigen::Index offset = 0;
    for (int axis = 0; axis < 3; ++axis) {
        const std::vector<double>& u = grid.velocity(axis).storage();
        faces.segment(offset, static_cast<Eigen::Index>(u.size())) =
            Eigen::Map<const Eigen::VectorXd>(u.data(), static_cast<Eigen::Index>(u.size()));
        offset += static_cast<Eigen::Index>(u.size());
    }
    const Eigen::VectorXd sampled = sample * faces;
    std::vector<tracker::Vec3> velocities(static_cast<std::size_t>(mesh.num_vertices()),
                                          tracker::Vec3::Zero());
    for (std::size_t p = 0; p < vertices.size(); ++p)
        velocities[static_cast<std::size_t>(vertices[p])] =
            sampled.segment<3>(3 * static_cast<Eigen::Index>(p));
    return velocities;
}

}  // namespace meniscus::coupling
