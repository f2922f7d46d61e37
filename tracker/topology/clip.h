#pragma once
/// \file Cutting the surface mesh with an axis-aligned plane: the part beyond the plane is removed
/// and the cut is closed with flat caps, so every component stays a closed surface (the outflow
/// faces of a fluid box: what leaves through them is clipped off).
///
/// Where the cut goes: within the range given, at the middle of the widest gap between the
/// vertices' coordinates along the axis, so no vertex lies on the plane and the new vertices are
/// at least half that gap (along the axis) from the old ones. Where the cut cannot be made
/// cleanly there (below), the next widest gaps are tried, then gaps further out, over twice the
/// range's width beyond it. Components wholly beyond ClipPlane::gone go whole.
///
/// How: every edge crossing the plane is split there (the new vertex exactly on the plane), the
/// triangles beyond it are deleted with the vertices left without triangles, and the loops in
/// which the remaining surface meets the plane are filled by ear clipping
/// (polygon_triangulation.h). The regions inside an odd number of loops are capped — an outer
/// loop with the loops directly inside it as holes — each cap oriented and labelled like the
/// surface along its loops. The half-space beyond thus takes the region that surrounds the loops
/// in the plane: gas around drops that leave, liquid around bubbles that leave.
///
/// Intersection-free: the remaining triangles lie in the closed near half-space and touch the
/// plane only at the new vertices and the loop edges between them; the caps lie in the plane,
/// inside the loops, which are disjoint. A cut that cannot be made cleanly — an edge crossing the
/// plane with other than two triangles, loops whose orientations or labels do not nest as two
/// regions, a polygon the ear clipping cannot do — is not made: the next position is tried, and
/// when none will do the mesh is left as it was, the report says why, and the caller tries again
/// on a later step.

#include "tracker/mesh.h"

#include <limits>
#include <string>
#include <vector>

namespace meniscus::tracker {

/// The plane and which side of it goes.
struct ClipPlane {
    int axis = 0;  ///< 0 = x, 1 = y, 2 = z
    /// 1: the part with x[axis] > cut goes; 0: the part with x[axis] < cut goes.
    int side = 1;
    /// The cut lies in [near, far] along the axis (length units; near is the end on the side
    /// that stays, near ≠ far).
    double near = 0.0;
    double far = 0.0;
    /// A connected component lying wholly beyond this coordinate goes whole, even where it does
    /// not reach the cut (what has left a box through its face; NaN: `near`). Taken as `near`
    /// where it lies beyond it.
    double gone = std::numeric_limits<double>::quiet_NaN();
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// What the clip took from one connected component of the mesh.
struct ClippedComponent {
    /// A vertex of the component that existed before the clip and survives it (INVALID_INDEX
    /// when the whole component went): names the component to per-component bookkeeping.
    int kept_vertex = INVALID_INDEX;
    /// Signed volume of the part removed (length³), with the sign of component_volumes(): the
    /// component's enclosed volume before the clip minus after it.
    double removed_volume = 0.0;
    LabelPair labels;  ///< of the component's triangles
};

/// What clip_mesh() did.
struct ClipReport {
    bool clipped = false;  ///< the mesh reached beyond the cut and was cut
    /// Why nothing was done although the mesh reaches past the range's near end, as the first
    /// position tried failed (empty if a cut was made or there was nothing to do).
    std::string deferred;
    double position = std::numeric_limits<double>::quiet_NaN();  ///< the cut, along the axis
    int edges_split = 0;         ///< edges crossing the plane, split on it
    int triangles_removed = 0;   ///< triangles beyond the plane (after the splits), deleted
    int vertices_removed = 0;    ///< vertices beyond the plane, deleted
    int cap_triangles = 0;       ///< triangles added to close the cut
    int components_removed = 0;  ///< components that went whole
    std::vector<ClippedComponent> components;  ///< one per component cut or removed
};

/// Removes the part of `mesh` beyond the plane and caps the cut (see the file comment).
/// Throws std::invalid_argument on an invalid plane.
ClipReport clip_mesh(SurfaceMesh& mesh, const ClipPlane& plane);

}  // namespace meniscus::tracker
