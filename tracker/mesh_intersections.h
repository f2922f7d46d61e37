#pragma once
/// \file Static whole-mesh self-intersection test (paper §3.4 "static intersection detection"),
/// exact: broad phase over triangle boxes, then the exact triangle–triangle test of
/// intersection.h on every candidate pair (shared vertices recognized by index).

#include "tracker/broadphase.h"
#include "tracker/mesh.h"

#include <vector>

namespace meniscus::tracker {

/// An edge crossing or touching a triangle it shares no vertex with.
struct EdgeTrianglePair {
    int ei, ti;
};

/// Every intersection found.
struct IntersectionReport {
    /// Triangle pairs that intersect beyond what their shared vertices/edge account for
    /// (the authoritative list: it also covers coplanar overlaps at a shared vertex).
    std::vector<TrianglePair> triangle_pairs;
    /// Witnesses: edges of one triangle of an intersecting pair that touch the other triangle,
    /// restricted to edge–triangle pairs without a common vertex.
    std::vector<EdgeTrianglePair> edge_triangle_pairs;
    bool intersection_free() const { return triangle_pairs.empty(); }
};

/// Finds all self-intersections of the live triangles at `positions` (sized
/// mesh.num_vertices(); the mesh's own positions when null).
/// A periodic mesh (issue 39) is read with its periods: the broad phase pairs triangles across
/// the box's faces and each pair is tested at the images nearest the first triangle's first
/// corner (`positions` need not be wrapped).
IntersectionReport find_self_intersections(const SurfaceMesh& mesh,
                                           const std::vector<Vec3>* positions = nullptr);

/// True when the mesh has no self-intersection (same test, stops at the first hit).
bool is_intersection_free(const SurfaceMesh& mesh, const std::vector<Vec3>* positions = nullptr);

}  // namespace meniscus::tracker
