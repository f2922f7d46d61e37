#pragma once
/// \file Butterfly subdivision point of an edge (Dyn, Levin & Gregory 1990; paper §3.5.1,
/// Fig. 3.5): P = (8 (P₁ + P₂) + 2 (Q₁ + Q₂) − (R₁ + R₂ + R₃ + R₄)) / 16.

#include "tracker/mesh.h"

#include <optional>

namespace meniscus::tracker {

/// Butterfly point of live edge `ei`: P₁, P₂ its endpoints, Q₁, Q₂ the vertices opposite it in
/// its two triangles, R₁…R₄ the vertices opposite the four other edges of those triangles in
/// their neighbouring triangles. Returns nullopt when the stencil does not exist: the edge or
/// one of those four edges does not have exactly two triangles (boundary or non-manifold).
std::optional<Vec3> butterfly_point(const SurfaceMesh& mesh, int ei);

/// Midpoint of edge `ei`.
///
/// On a periodic mesh both points are computed at the minimum image of the edge's first vertex
/// (the whole stencil unwrapped around it) and returned there, not wrapped: callers wrap a
/// point before storing it as a vertex position.
Vec3 edge_midpoint(const SurfaceMesh& mesh, int ei);

}  // namespace meniscus::tracker
