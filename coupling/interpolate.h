#pragma once
/// \file Grid → mesh: the fluid velocity at the mesh vertices (coupling step 5).
///
/// Each velocity component is interpolated from its own staggered face lattice (u on x-faces at
/// origin + (i, j+½, k+½)·dx, etc.; see fluid/mac_grid.h), so both methods reproduce any linear
/// velocity field exactly wherever their stencil lies inside the face lattice.

#include "fluid/mac_grid.h"
#include "tracker/mesh.h"

#include <vector>

namespace meniscus::coupling {

/// How a velocity component is reconstructed between its face samples.
enum class VelocityInterpolation {
    /// 2 × 2 × 2 faces; continuous, exact for (multi)linear fields; points outside the face
    /// lattice are clamped onto it (constant extrapolation, as fluid::interpolate_trilinear).
    trilinear,
    /// 3 × 3 × 3 faces weighted by the quadratic B-spline (½(½−f)², ¾−f², ½(½+f)² around the
    /// nearest face): C¹ in space, smoother velocities for the mesh, still exact for linear
    /// fields (it is an approximation, not an interpolation: it smooths curvature at the grid
    /// scale). Where the 3-wide stencil leaves the face lattice (within about one cell of a
    /// wall) the component falls back to trilinear.
    quadratic_bspline
};

/// Options of interpolate_vertex_velocities().
struct InterpolateOptions {
    VelocityInterpolation method = VelocityInterpolation::trilinear;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Velocity (m/s) of `grid` at position `x` (m) with `method`.
Eigen::Vector3d sample_grid_velocity(const fluid::MacGrid& grid, const Eigen::Vector3d& x,
                                     VelocityInterpolation method);

/// Velocity (m/s) at every vertex of `mesh`, sized num_vertices(); zero for dead vertices.
/// Parallel over vertices (TBB). Throws std::invalid_argument on invalid options.
std::vector<tracker::Vec3> interpolate_vertex_velocities(const fluid::MacGrid& grid,
                                                         const tracker::SurfaceMesh& mesh,
                                                         const InterpolateOptions& options = {});

}  // namespace meniscus::coupling
