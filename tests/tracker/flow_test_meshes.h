#pragma once
/// \file Meshes and small helpers shared by the geometric-flow tests (paper §4): spheres,
/// cubes, a valley, an icosphere, a peanut, and the observed order of convergence.

#include "tracker/mesh.h"

#include <vector>

namespace meniscus::tracker::testing {

/// The implicit mesher's sphere at the given edge length.
SurfaceMesh meshed_sphere(const Vec3& center, double radius, double edge_length);

/// Moves each vertex onto the sphere exactly (the mesher leaves |φ| ≲ 1e-3 ℓ).
void project_to_sphere(SurfaceMesh& mesh, const Vec3& center, double radius);

/// The mesh's positions moved by `d` (one per vertex slot).
std::vector<Vec3> moved(const SurfaceMesh& mesh, const std::vector<Vec3>& d);

/// Moves the mesh's vertices by `d`.
void displace(SurfaceMesh& mesh, const std::vector<Vec3>& d);

/// Cube [−a, a]³ with n × n quads per face, two triangles per quad, outward normals, shared
/// vertices along edges and corners: sharp edges by construction.
SurfaceMesh cube_mesh(double a, int n);

/// Open V-shaped valley z = slope·|x| over [−1, 1] × [0, 1] (n × n quads per side), normals
/// up (+z side): a concave crease along x = 0 seen from the side the normals point to.
SurfaceMesh valley_mesh(double slope, int n);

/// Subdivided icosahedron: `levels` midpoint subdivisions, every vertex projected onto the
/// sphere. Nearly regular (valence 6 except 12 valence-5 vertices), unlike the mesher's output.
SurfaceMesh icosphere(const Vec3& center, double radius, int levels);

/// Two overlapping balls of radius r around (∓a, 0, 0) (a < r) meshed as two latitude–longitude
/// caps sharing the ring where the spheres meet: every vertex on the exact union's boundary, a
/// concave crease exactly on the ring. Spacing ≈ ξ along latitude lines and at the equator.
SurfaceMesh peanut_mesh(double a, double r, double xi);

/// log(e_coarse / e_fine) / log(h_coarse / h_fine).
double observed_order(double coarse_error, double fine_error, double coarse_h, double fine_h);

}  // namespace meniscus::tracker::testing
