#pragma once
/// \file Neighbourhood sizes for tests of the vertex fits (remesh/surface_fit.h), which fit a
/// vertex's two-ring and fall back a degree where too few vertices constrain it.

#include "tracker/mesh.h"

namespace meniscus::tracker::testing {

/// Distinct vertices of the triangles around vi's neighbours, vi included: the two-ring that
/// vertex_patch() fits.
int two_ring_size(const SurfaceMesh& mesh, int vi);

}  // namespace meniscus::tracker::testing
