#include "coupling/implicit_tension.h"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace meniscus::coupling {

namespace {

using Eigen::Vector3d;
using Triplet = Eigen::Triplet<double>;

}  // namespace

std::shared_ptr<const fluid::SurfaceViscosity> build_surface_viscosity(
    const tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid, double viscosity,
    const InterpolateOptions& interpolate, const fluid::BoundaryOptions& walls) {
    if (!(viscosity >= 0.0) || !std::isfinite(viscosity))
        throw std::invalid_argument("build_surface_viscosity: viscosity must be finite and >= 0");
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
    std::vector<Triplet> entries;
    // Cotangent stiffness: each triangle adds ½ cot θ_i to the edge opposite its corner i.
    entries.reserve(triangles.size() * 12);
    for (int t : triangles) {
        const tracker::Triangle& tri = mesh.triangle(t);
        for (int c = 0; c < 3; ++c) {
            const int i = tri[static_cast<size_t>(c)];
            const int j = tri[static_cast<size_t>((c + 1) % 3)];
            const int k = tri[static_cast<size_t>((c + 2) % 3)];
            const Vector3d a = mesh.position(j) - mesh.position(i);
            const Vector3d b = mesh.position(k) - mesh.position(i);
            const double sine = a.cross(b).norm();
            if (!(sine > 1e-12 * a.norm() * b.norm()))
                continue;  // a degenerate corner: no gradient to penalise, cot unbounded
            const double w = 0.5 * a.dot(b) / sine;
            const Eigen::Index pj = point[static_cast<size_t>(j)];
            const Eigen::Index pk = point[static_cast<size_t>(k)];
            entries.emplace_back(pj, pk, -w);
            entries.emplace_back(pk, pj, -w);
            entries.emplace_back(pj, pj, w);
            entries.emplace_back(pk, pk, w);
        }
    }
    term->laplacian.resize(points, points);
    term->laplacian.setFromTriplets(entries.begin(), entries.end());
    return term;
}

}  // namespace meniscus::coupling
