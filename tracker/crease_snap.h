#pragma once
/// \file Putting a mesh of an implicit shape's surface onto the shape's creases (sharp edges
/// where ∇φ jumps, e.g. a slot cut into a ball): vertices near a crease move onto it, and edges
/// that cut across it are flipped to run along it, so that the mesh has the edge instead of a
/// chamfer whose triangles leave the surface by a good part of their size.
///
/// Snapping (in the spirit of dual contouring's feature points, Kobbelt et al. 2001; Ju et al.
/// 2002): a vertex whose one-ring normals (unit ∇φ at the ring's vertices) fall into two or
/// three groups turned by more than `angle` from each other sees a crease or a corner; it moves
/// to the point nearest to it of the intersection of the groups' tangent planes (the
/// least-squares solution of nᵢ · (x − pᵢ) = 0 in the span of the normals), then onto φ = 0.
/// Vertices nearest to their crease move first; a move that would turn a triangle by more than
/// `max_normal_turn_degrees`, shrink it below `min_area_fraction` of its area or its smallest
/// angle below `min_angle_degrees`, carry the vertex farther than `max_move_fraction` of its
/// shortest edge, or take an edge out of [min_edge_fraction, max_edge_fraction] of the mean edge
/// length is not made.
///
/// Flipping: an edge whose midpoint leaves the surface by more than twice as much as the other
/// diagonal of its two triangles is flipped when both new triangles lie along the surface
/// (normal within `max_normal_turn_degrees` of ∇φ at their centroids), keep their angles and
/// the new edge's length within the same bounds.

#include "tracker/implicit_shape.h"
#include "tracker/mesh.h"

namespace meniscus::tracker {

/// Options of snap_to_creases().
struct CreaseSnapOptions {
    double angle = 0.35;  ///< radians, in (0, π/2): normals turning by more mark a crease
    int passes = 8;       ///< rounds of snapping then flipping (≥ 1)
    double max_normal_turn_degrees = 60.0;  ///< in (0, 90)
    double min_area_fraction = 0.05;        ///< in [0, 1)
    /// A move or flip may not make a triangle's smallest angle smaller than this or than it was.
    double min_angle_degrees = 15.0;  ///< in [0, 60)
    double max_move_fraction = 1.0;   ///< of the vertex's shortest edge, > 0
    /// Moves and flips keep edges within these fractions of the mesh's mean edge length (or
    /// where they were): inside the tracker's default β = 0.5ξ and α = 1.5ξ, so that its first
    /// steps neither split nor collapse them (a butterfly split across a crease leaves it).
    double min_edge_fraction = 0.52;  ///< in (0, 1)
    double max_edge_fraction = 1.45;  ///< > 1
    int projection_iterations = 8;    ///< Newton steps onto φ = 0 (≥ 0)
    void validate() const;            ///< throws std::invalid_argument naming the field
};

/// What snap_to_creases() did.
struct CreaseSnapReport {
    int snaps = 0;            ///< vertex moves onto creases (a vertex may move in several passes)
    int flips = 0;            ///< edges flipped to run along creases
    int splits = 0;           ///< edges a snap stretched beyond max_edge_fraction, split
    int crease_vertices = 0;  ///< vertices left on a crease or corner after the last pass
};

/// Snaps `mesh` (closed, consistently oriented, its vertices on the surface of `shape`) onto
/// the shape's creases in place. Throws std::invalid_argument on invalid options.
CreaseSnapReport snap_to_creases(SurfaceMesh& mesh, const ImplicitShape& shape,
                                 const CreaseSnapOptions& options = {});

}  // namespace meniscus::tracker
