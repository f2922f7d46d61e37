#pragma once
/// \file Collision-safe mesh improvement (paper §3.3, §3.5, §3.6): one call per time step runs
/// null-space smoothing → split → flip → collapse → (separation, when topology changes are
/// allowed), each operation only if enabled in RemeshOptions. Smoothing comes first (the paper
/// lists it last) so that the edge-length operations have the last word.

#include "tracker/mesh.h"
#include "tracker/remesh/collapse.h"
#include "tracker/remesh/flip.h"
#include "tracker/remesh/smooth.h"
#include "tracker/remesh/split.h"
#include "tracker/remesh_options.h"
#include "tracker/topology/separate.h"

namespace meniscus::tracker {

/// Everything improve_mesh() did, per operation, with refusals and their reasons.
struct ImproveReport {
    SplitReport split;
    FlipReport flip;
    CollapseReport collapse;
    /// Cleanup after collapses and flips (only with topology changes allowed).
    SeparationReport separation;
    SmoothReport smooth;
    double seconds = 0.0;  ///< wall time of the whole call
};

/// Improves `mesh` in place. Precondition for the collision-safety guarantee: the mesh is
/// intersection-free on entry; it then stays so after every operation (with
/// context.collision_safety). On return every edge with two triangles is at most α long, and
/// every such edge not touching the open boundary at least β, except where a collapse was
/// refused (report.collapse) or the pass limits ran out; separation nudges may shift the edges at
/// split singular vertices by a tiny fraction. Dead elements are left for the caller to compact().
/// Throws std::invalid_argument (naming the field) when options or context are invalid.
ImproveReport improve_mesh(SurfaceMesh& mesh, const RemeshOptions& options,
                           const ImproveContext& context);

}  // namespace meniscus::tracker
