#pragma once
/// \file Periodic test meshes (issue 39): a liquid column wrapping around a periodic axis and a
/// liquid layer whose surface wraps around two. Both are closed surfaces of the periodic box
/// with no seam in their connectivity; their vertices lie in the fundamental box.

#include "tracker/mesh.h"

#include <functional>

namespace meniscus::tracker::testing {

/// A cylinder of `radius` about the line through `centre` along `axis`, periodic along that axis
/// with period `length` (box origin 0 along it): `around` vertices per ring, `along` (even) rings,
/// odd rings turned by half a step. Normals point out of the column (inside label 1, liquid).
/// `radius_at(s)` (optional) multiplies the radius at the ring at arc position s ∈ [0, length).
SurfaceMesh periodic_tube(double radius, const Vec3& centre, int axis, double length, int around,
                          int along, const std::function<double(double)>& radius_at = {});

/// The surface z = height(x, y) of a layer of liquid below gas, periodic in x and y with periods
/// lx, ly (box origin 0): nx × ny vertices. Normals point up (inside label 1 below).
SurfaceMesh periodic_sheet(double lx, double ly, int nx, int ny,
                           const std::function<double(double, double)>& height);

}  // namespace meniscus::tracker::testing
