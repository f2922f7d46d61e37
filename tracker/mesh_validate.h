#pragma once
/// \file Admissibility checks for a SurfaceMesh (paper §3.2): list every violation, not just
/// the first, so a user loading a broken file learns everything that is wrong at once.

#include "tracker/mesh.h"

#include <string>
#include <vector>

namespace meniscus::tracker {

/// What kind of rule a violation breaks.
enum class ViolationKind {
    InvalidVertexIndex,       ///< a triangle refers to a missing or dead vertex
    RepeatedVertex,           ///< a triangle uses one vertex twice ("collapsed" triangle)
    DuplicateTriangle,        ///< two triangles on the same three vertices (degenerate tetrahedron)
    BoundaryEdge,             ///< an edge with one triangle on a surface required to be closed
    OddEdgeValence,           ///< an edge with an odd number (≥ 3) of triangles
    InconsistentOrientation,  ///< an edge not used equally often in both directions
    DegenerateTriangle,       ///< a triangle of (numerically) zero area
    AdjacencyMismatch,        ///< internal adjacency tables disagree (a bug, never user input)
};

/// One broken rule, with the element it concerns and a sentence for people.
struct MeshViolation {
    ViolationKind kind;
    int index = INVALID_INDEX;  ///< triangle index, or edge index for edge rules
    std::string message;
};

/// What to require of the mesh.
struct ValidationOptions {
    bool allow_boundary = false;        ///< open surfaces (§4.4) may have boundary edges
    bool check_degenerate_area = true;  ///< flag triangles with area ≤ relative tolerance
    /// A triangle is degenerate when its doubled area is below this fraction of its longest
    /// edge squared (≈ the sine of its smallest angle).
    double degenerate_area_fraction = 1e-12;
    /// Stop after this many violations (0 = list all).
    int max_violations = 0;
};

/// Checks connectivity (and, optionally, zero-area triangles). Returns every violation found
/// (empty when the mesh is admissible). Dead elements are skipped.
std::vector<MeshViolation> validate_mesh(const SurfaceMesh& mesh,
                                         const ValidationOptions& options = {});

/// Short name of a violation kind, e.g. "odd edge valence".
const char* to_string(ViolationKind kind);

}  // namespace meniscus::tracker
