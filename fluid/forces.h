#pragma once
/// \file Body forces on the face velocities.

#include <Eigen/Core>

#include "fluid/boundary.h"
#include "fluid/mac_grid.h"

namespace meniscus::fluid {

/// Adds dt·g to every face velocity that is not on a wall or inflow of `boundaries` (those keep
/// their prescribed normal value; outflow faces take it): u += dt·g_x, v += dt·g_y, w += dt·g_z.
/// `gravity` in m/s², `dt` in s.
void apply_gravity(MacGrid& grid, const Eigen::Vector3d& gravity, double dt,
                   const BoundaryOptions& boundaries = {});

}  // namespace meniscus::fluid
