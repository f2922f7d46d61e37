#pragma once
/// \file A periodic surface mesh (tracker/periods.h) laid out in ordinary space, for the code
/// that sees the mesh on the grid: every image of every triangle that comes within a margin of
/// the fundamental box, as a plain (non-periodic) mesh whose vertices are images of the periodic
/// mesh's vertices. Within the box and the margin it is the periodic surface exactly; its open
/// rim lies beyond the margin. The signed band (mesh_band.h), the face curvatures
/// (surface_tension.h) and the frame output read this mesh and need no knowledge of periods:
/// a point near a face of the box finds the triangles beyond that face at their images.

#include "tracker/mesh.h"

#include <vector>

namespace meniscus::coupling {

/// The unrolled mesh and where each of its elements comes from.
struct UnrolledMesh {
    tracker::SurfaceMesh mesh;         ///< not periodic; live triangles only, no dead slots
    std::vector<int> source_triangle;  ///< per triangle of `mesh`: the periodic mesh's triangle
    std::vector<int> source_vertex;    ///< per vertex of `mesh`: the periodic mesh's vertex
};

/// The images of `mesh`'s live triangles whose bounding boxes reach into the fundamental box
/// grown by `margin` (≥ 0, m) along each wrapping axis, each image's corners joined where the
/// periodic mesh joins them. Along an axis that does not wrap nothing is cut or copied. A mesh
/// that is not periodic comes back whole, as it is (its live triangles, renumbered). Throws
/// std::invalid_argument on a negative or non-finite margin.
UnrolledMesh unroll_periodic_mesh(const tracker::SurfaceMesh& mesh, double margin);

/// `mesh` (an unrolled mesh) cut at the faces of the fundamental box of `periods` along each axis
/// that wraps: triangles beyond a face are removed and those across it cut along it, each crossing
/// edge getting one new vertex that the triangles on both of its sides share. The surface ends
/// open exactly at the faces, where the box's copies continue it (what a renderer tiles).
/// `values` (optional, one per vertex of `mesh`) are interpolated linearly along the cut edges and
/// come back one per vertex of the result. A triangle the cut leaves a quadrilateral of becomes
/// two; orientation and labels are kept.
tracker::SurfaceMesh cut_at_box(const tracker::SurfaceMesh& mesh,
                                const tracker::MeshPeriods& periods,
                                std::vector<tracker::Vec3>* values = nullptr);

/// Per vertex of `unrolled`, the value the periodic mesh's source vertex has in `values`.
template <typename T>
std::vector<T> unrolled_values(const UnrolledMesh& unrolled, const std::vector<T>& values) {
    std::vector<T> out(unrolled.source_vertex.size());
    for (size_t v = 0; v < out.size(); ++v)
        out[v] = values[static_cast<size_t>(unrolled.source_vertex[v])];
    return out;
}

}  // namespace meniscus::coupling
