#pragma once
/// \file Triangulation of a planar polygon with holes by ear clipping, every decision taken by the
/// exact orient2d (predicates.h), so the triangles cover the polygon exactly, never overlap and
/// never leave it, whatever the rounding of the coordinates.
///
/// Holes are first joined to the outer boundary by bridges (a pair of coincident edges from a
/// hole vertex to a visible boundary vertex; Eberly, "Triangulation by ear clipping", 2002), the
/// hole with the rightmost vertex first; the bridge to each hole is the shortest segment from its
/// rightmost vertex to a vertex of the boundary built so far that crosses no edge and leaves both
/// vertices into the polygon's interior. The joined boundary is then clipped ear by ear: a
/// strictly convex corner whose triangle holds no other boundary vertex (a vertex coinciding with
/// a corner — a bridge's copy — may touch it but not lead into it).
///
/// Used to close the surface mesh where a plane cuts it (topology/clip.h); the loops there have
/// tens to a few hundred vertices, and the clipping is O(n²) in the boundary's vertex count.

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace meniscus::tracker {

/// A polygon with holes over a shared point list: `outer` counter-clockwise, each hole clockwise,
/// all loops simple, the holes strictly inside `outer` and disjoint from each other (indices into
/// the point list; a loop lists each vertex once, without repeating the first).
struct PolygonWithHoles {
    std::vector<int> outer;
    std::vector<std::vector<int>> holes;
};

/// Result of triangulate_polygon(): the triangles (point indices, counter-clockwise) or why not.
struct PolygonTriangulation {
    bool ok = false;
    std::vector<std::array<int, 3>> triangles;  ///< n − 2 + 2·holes triangles when ok
    std::string failure;                        ///< what went wrong when !ok
};

/// Signed area of loop `loop` over `points` (> 0 counter-clockwise), in floating point.
double loop_signed_area(const std::vector<Eigen::Vector2d>& points, const std::vector<int>& loop);

/// True if `q` lies strictly inside the simple loop `loop` (crossing parity with exact
/// orientation tests; a point on the loop is not inside).
bool point_in_loop(const std::vector<Eigen::Vector2d>& points, const std::vector<int>& loop,
                   const Eigen::Vector2d& q);

/// Triangulates `polygon` (see the file comment). Fails (ok false, nothing thrown) when a loop
/// has fewer than three vertices, has the wrong orientation, when no bridge or no ear can be
/// found (a loop that is not simple, or collinear runs the clipping cannot get past). Throws
/// std::invalid_argument on an index outside `points`.
PolygonTriangulation triangulate_polygon(const std::vector<Eigen::Vector2d>& points,
                                         const PolygonWithHoles& polygon);

}  // namespace meniscus::tracker
