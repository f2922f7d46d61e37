#pragma once
/// \file Mesh → fluid for semi-implicit surface tension (Hysing 2006): the surface viscosity
/// term of fluid/surface_viscosity.h, built from the mesh at the start of a step.
///
/// The surface's points are the vertices of the triangles that lie inside the fluid box (all
/// three vertices within it); parts of a closed mesh beyond a wall (a slab or a column cut by
/// the walls) are left out, so the term ends at the wall with a free (natural) boundary, which
/// is what a free-slip wall's mirror symmetry asks of it. Each point samples the velocity as the
/// mesh moves with it (vertex_velocity_weights() with the coupling's interpolation method,
/// trilinear: see SimulationOptions::implicit_tension). L is the cotangent stiffness matrix of
/// those triangles.

#include "coupling/interpolate.h"
#include "fluid/mac_grid.h"
#include "fluid/surface_viscosity.h"
#include "tracker/mesh.h"

#include <memory>

namespace meniscus::coupling {

/// The term with μ_s = `viscosity` (Pa·s·m; θσΔt) for `mesh` on `grid`. Empty (no points) when
/// no triangle lies inside the box. Throws std::invalid_argument for a negative or non-finite
/// viscosity.
std::shared_ptr<const fluid::SurfaceViscosity> build_surface_viscosity(
    const tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid, double viscosity,
    const InterpolateOptions& interpolate, const fluid::BoundaryOptions& walls);

}  // namespace meniscus::coupling
