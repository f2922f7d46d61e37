#pragma once
/// \file Collision-safety checks shared by the local mesh operations (paper §3.5, §3.7):
/// CCD of a pseudo-motion of a few vertices against the static rest of the mesh, and exact
/// intersection tests of triangles about to be created.

#include "tracker/mesh.h"
#include "tracker/remesh/element_hash.h"

#include <utility>
#include <vector>

namespace meniscus::tracker {

/// A few vertices moving linearly from their current positions to `x_t1` while every other
/// vertex stays put.
struct PseudoMotion {
    std::vector<int> vertices;  ///< moving vertices (live, distinct)
    std::vector<Vec3> x_t1;     ///< their end positions, same order
    /// For an edge collapse: {kept, removed}. Primitives that share a vertex once `removed` is
    /// identified with `kept` are not tested against each other (they touch by construction at
    /// t = 1). {INVALID_INDEX, INVALID_INDEX} for none.
    std::pair<int, int> identified{INVALID_INDEX, INVALID_INDEX};
};

/// True when some vertex–triangle or edge–edge pair may collide during the pseudo-motion
/// (exact broad phase via `hash`, which must hold the current static boxes, then CCD: moving
/// vertex vs static and moving triangles; static vertices vs moving triangles; moving edges vs
/// static and moving edges). Never a false negative.
bool pseudo_motion_collides(const SurfaceMesh& mesh, const ElementHash& hash,
                            const PseudoMotion& motion);

/// Triangles that do not exist yet, with optional positions for vertices that do not exist yet
/// or will have moved (`overrides`: vertex index → position; indices ≥ mesh.num_vertices()
/// name new vertices).
struct CandidateTriangles {
    std::vector<Triangle> triangles;
    std::vector<std::pair<int, Vec3>> overrides;
};

/// True when a candidate triangle is degenerate (collinear vertices, exact) or intersects an
/// existing live triangle (other than those in `replaced`, which the operation removes) or
/// another candidate, by the exact shared-vertex-aware test of intersection.h (touching
/// counts). Existing triangles must not contain an overridden existing vertex unless they are
/// in `replaced`.
bool candidate_triangles_intersect(const SurfaceMesh& mesh, const ElementHash& hash,
                                   const CandidateTriangles& candidates,
                                   const std::vector<int>& replaced);

}  // namespace meniscus::tracker
