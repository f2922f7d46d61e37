#pragma once
/// \file Velocity extrapolation from the liquid into the void (free-surface mode).

#include "fluid/interface_input.h"
#include "fluid/mac_grid.h"

namespace meniscus::fluid {

/// Extends the face velocities of faces next to a liquid cell (φ < 0 on either side) into the
/// other faces, one layer of face neighbours (same component, ±1 along each axis) at a time: an
/// unknown face takes the mean of its known neighbours and becomes known for the next layer.
/// Wall-normal faces are neither read nor written. Along the grid's periodic axes neighbours wrap
/// around, the face at 0 is extrapolated like an interior face and the one at n repeats it. Faces further than `layers` from the liquid
/// are set to zero (they carry no information and must not pollute the CFL limit). Throws
/// std::invalid_argument when `layers` < 0 or the interface does not fit.
void extrapolate_velocity(MacGrid& grid, const InterfaceInput& interface, int layers);

}  // namespace meniscus::fluid
