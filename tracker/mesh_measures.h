#pragma once
/// \file Geometric and topological measures of a SurfaceMesh: volume, area, edge lengths,
/// triangle angles, connected components and Euler characteristic. Dead elements are skipped.
///
/// A periodic mesh (mesh.periodic(), periods.h) is read by the minimum image: each triangle's
/// corners at the images nearest its first corner, each edge's second end at the image nearest
/// its first. Its volume is the flux of F = (x_a − origin_a) e_a through the surface, a being the
/// first axis that does not wrap: exact for a surface closed in the periodic box (a column
/// around a periodic axis, a drop), and for a layer periodic along the two other axes (no closed
/// region) the volume between the surface and the plane x_a = origin_a below it.

#include "tracker/mesh.h"

#include <vector>

namespace meniscus::tracker {

/// Signed volume enclosed by the live triangles (divergence theorem; positive when normals
/// point outward of the enclosed region). Meaningful for closed surfaces; units: length³.
/// Periodic meshes: see the file comment; throws std::invalid_argument if all three axes wrap.
double enclosed_volume(const SurfaceMesh& mesh);
/// The same with the vertices at `positions` (sized mesh.num_vertices(); throws
/// std::invalid_argument otherwise): the volume a motion would give, without moving the mesh.
/// On a periodic mesh the positions need not be wrapped: each triangle is read at the images of
/// its corners nearest its first corner's position.
double enclosed_volume(const SurfaceMesh& mesh, const std::vector<Vec3>& positions);
/// Total area of live triangles (length²).
double surface_area(const SurfaceMesh& mesh);

/// Edge length statistics over live edges (length units).
struct EdgeLengthStats {
    int count = 0;
    double min = 0.0, max = 0.0, mean = 0.0;
};
EdgeLengthStats edge_length_stats(const SurfaceMesh& mesh);

/// Triangle angle statistics over live triangles (degrees).
struct AngleStats {
    double min_degrees = 0.0, max_degrees = 0.0;
};
AngleStats angle_stats(const SurfaceMesh& mesh);

/// Connected components of live triangles (triangles sharing an edge are connected).
struct Components {
    int count = 0;
    /// Component id of each triangle slot (INVALID_INDEX for dead triangles).
    std::vector<int> triangle_component;
};
Components triangle_components(const SurfaceMesh& mesh);

/// Signed enclosed volume of each component in `components` (indexed by component id).
/// Periodic meshes as enclosed_volume() (throws if all three axes wrap).
std::vector<double> component_volumes(const SurfaceMesh& mesh, const Components& components);

/// Area-weighted unit vertex normals: for each live vertex the normalized sum of the
/// (b − a) × (c − a) vectors of its live incident triangles, i.e. unit triangle normals
/// weighted by twice the triangle area. Dead vertices, vertices without live triangles and
/// vertices whose weighted sum vanishes get the zero vector. Sized num_vertices().
std::vector<Vec3> area_weighted_vertex_normals(const SurfaceMesh& mesh);

/// V − E + F over live elements (2 per sphere-like closed component, 0 per torus).
int euler_characteristic(const SurfaceMesh& mesh);

}  // namespace meniscus::tracker
