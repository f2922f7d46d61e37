#pragma once
/// \file Topology changes of one time step (paper §3.3, §3.6, §3.7): merge proximal surfaces,
/// then separate pinched ones (degenerate tetrahedra, singular vertices).

#include "tracker/mesh.h"
#include "tracker/remesh_options.h"
#include "tracker/topology/merge.h"
#include "tracker/topology/separate.h"

namespace meniscus::tracker {

/// What change_topology() did.
struct TopologyReport {
    MergeReport merge;
    SeparationReport separation;
    double seconds = 0.0;  ///< wall time of the whole call
};

/// Merges (if options.allow_merging) and separates (if options.allow_separation) `mesh` in
/// place. With context.collision_safety an intersection-free mesh stays intersection-free.
/// Dead elements are left for the caller to compact(). Throws std::invalid_argument (naming
/// the field) when options or context are invalid.
TopologyReport change_topology(SurfaceMesh& mesh, const TopologyOptions& options,
                               const TopologyContext& context);

}  // namespace meniscus::tracker
