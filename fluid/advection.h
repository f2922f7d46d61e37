#pragma once
/// \file Semi-Lagrangian advection on the MAC grid with an optional error-compensating
/// correction (BFECC or MacCormack), both clamped to the interpolation stencil's range.
///
/// Departure points are traced back with explicit midpoint RK2 through the face velocities
/// (trilinear interpolation of each staggered component on its own lattice). Points that leave the
/// box are sampled with constant extrapolation of the nearest samples, except for the velocity
/// components tangential to an inflow face (boundary.h): the inflow brings no tangential
/// velocity, so they fall linearly to 0 from the first sample to the face and are 0 beyond it.
/// Along the grid's periodic axes (MacGrid::periodic()) the back-traces and samples wrap around
/// the box; the face at n of a face field along such an axis is set to the one at 0.
/// Every scheme reproduces constant fields exactly and linear fields exactly wherever the departure
/// points stay in the box.

#include "fluid/array3.h"
#include "fluid/boundary.h"
#include "fluid/mac_grid.h"

namespace meniscus::fluid {

/// Advection scheme.
enum class AdvectionScheme {
    semi_lagrangian,  ///< one RK2 back-trace and trilinear interpolation (first order, dissipative)
    bfecc,            ///< back and forth error compensation and correction (three advections)
    maccormack        ///< MacCormack / modified MacCormack (two advections)
};

/// Options of the advection step.
struct AdvectionOptions {
    AdvectionScheme scheme = AdvectionScheme::maccormack;

    /// Throws std::invalid_argument naming the field when an enum holds an unknown value.
    void validate() const;
};

/// Advects `field` (samples at `location`, see mac_grid.h) through the velocity of `grid` for `dt`
/// seconds. The result replaces `field`. For corrected schemes, a corrected value outside the
/// [min, max] of the 8 samples around the forward departure point falls back to the plain
/// semi-Lagrangian value. Wall-normal faces of a face-located field are left unchanged.
/// `boundaries` (optional): the inflow faces (see the file comment; no effect on cell-centred
/// fields). `field` is overwritten while `grid`'s velocities are sampled, so it must not be one
/// of them (throws std::invalid_argument; advect_velocity() advects copies).
void advect_field(const MacGrid& grid, double dt, FieldLocation location,
                  const AdvectionOptions& options, Array3<double>& field,
                  const BoundaryOptions* boundaries = nullptr);

/// Self-advection of the face velocities of `grid` for `dt` seconds: each component is advected
/// through the velocity field at the start of the step. Wall-normal faces keep their values.
void advect_velocity(MacGrid& grid, double dt, const AdvectionOptions& options,
                     const BoundaryOptions* boundaries = nullptr);

}  // namespace meniscus::fluid
