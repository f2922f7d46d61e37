#pragma once
/// \file Meshing an implicit shape into a closed, consistently oriented triangle mesh.
///
/// Marching tetrahedra on a regular grid (each cube cut into six tetrahedra around its main
/// diagonal, so neighbouring cubes agree and the surface is watertight), crossings located by
/// root finding on φ, then isotropic remeshing with projection onto φ = 0 to reach the
/// requested mean edge length without slivers. Normals point outward (towards φ > 0).

#include "tracker/implicit_shape.h"
#include "tracker/mesh.h"

namespace meniscus::tracker {

/// Options of mesh_implicit_shape().
struct ImplicitMeshOptions {
    double edge_length = 0.0;       ///< requested mean edge length (metres, > 0)
    int remesh_iterations = 8;      ///< isotropic remeshing iterations after marching tetrahedra
    int projection_iterations = 8;  ///< Newton steps onto φ = 0 per projected point
    void validate() const;          ///< throws std::invalid_argument naming the field
};

/// Quality of the produced mesh, for reports and checks.
struct ImplicitMeshReport {
    int vertices = 0;
    int triangles = 0;
    double mean_edge_length = 0.0;
    double min_angle_degrees = 0.0;
    double max_angle_degrees = 0.0;
    double max_abs_phi = 0.0;  ///< largest |φ| over vertices (how far off the surface)
};

/// Meshes `shape`. Throws std::invalid_argument on bad options or an unbounded shape (a
/// half-space not intersected with a box), std::runtime_error if the shape produces no surface
/// at this resolution (e.g. smaller than the edge length).
SurfaceMesh mesh_implicit_shape(const ImplicitShape& shape, const ImplicitMeshOptions& options,
                                ImplicitMeshReport* report = nullptr);

/// Moves x onto φ = 0 by Newton steps along the gradient (at most `iterations`).
Vec3 project_to_zero_set(const ImplicitShape& shape, const Vec3& x, int iterations);

}  // namespace meniscus::tracker
