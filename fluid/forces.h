#pragma once
/// \file Body forces on the face velocities.

#include <Eigen/Core>

#include "fluid/mac_grid.h"

namespace meniscus::fluid {

/// Adds dt·g to every face velocity that is not on a wall (wall-normal faces keep their
/// prescribed value): u += dt·g_x, v += dt·g_y, w += dt·g_z. `gravity` in m/s², `dt` in s.
void apply_gravity(MacGrid& grid, const Eigen::Vector3d& gravity, double dt);

}  // namespace meniscus::fluid
