#pragma once
/// \file Distance from points to a triangle mesh: the unsigned distance from a point to the
/// nearest live triangle, by exact point–triangle proximity (distance.h) over a loose grid of
/// triangle boxes (broadphase.h). For comparing two surfaces (e.g. the Hausdorff distance of
/// flow_errors.h) without an implicit form of either.

#include "tracker/broadphase.h"
#include "tracker/mesh.h"

#include <array>
#include <memory>
#include <vector>

namespace meniscus::tracker {

/// The live triangles of a mesh, indexed for nearest-triangle queries. Holds its own copy of
/// the positions: the mesh may change or go away afterwards.
class MeshDistance {
public:
    /// Indexes `mesh`'s live triangles. Throws std::invalid_argument if it has none.
    explicit MeshDistance(const SurfaceMesh& mesh);
    MeshDistance(const MeshDistance&) = delete;
    MeshDistance& operator=(const MeshDistance&) = delete;

    /// Unsigned distance (m) from p to the nearest point of the indexed triangles: exact up to
    /// the floating-point rounding of point_triangle_proximity. Grows a query box around p
    /// until the nearest triangle found lies within it, so every closer triangle's box would
    /// have met it. Read-only: safe from several threads at once. For a periodic mesh, the
    /// distance to the nearest image of the surface (p may lie outside the box).
    double distance(const Vec3& p) const;

    int triangles() const { return static_cast<int>(m_corners.size()); }

private:
    /// distance() without images: to the stored triangles, starting from a known upper bound
    /// `best` (infinity for none) that is returned if no stored triangle is closer.
    double distance_to_stored(const Vec3& p, double best) const;

    std::vector<std::array<Vec3, 3>> m_corners;  // a periodic mesh's at its minimum image
    std::vector<Box3d> m_boxes;
    Box3d m_bounds;
    double m_initial_half_width = 0.0;
    std::unique_ptr<LooseGrid> m_grid;  // refers to m_boxes
    MeshPeriods m_periods;              // the mesh's (no axis wraps for most meshes)
};

}  // namespace meniscus::tracker
