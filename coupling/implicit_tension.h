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
/// those triangles, its 3 × 3 blocks I₃ (the full form) or n_T n_Tᵀ per triangle (the normal form,
/// the default; see SurfaceTermForm).
///
/// Given the level set, each point's weights are scaled by the densities ρ_f of the faces they
/// read and renormalised (to the same sum: translations stay free): the term sees the surface
/// move with the momentum of the fluid around it. With plain trilinear weights a point next to
/// air reads gas faces that carry 1/830 of the water's mass; the cheapest way for the backward-
/// Euler step to smooth the sampled surface velocity is then to move those faces, and past the
/// capillary limit they took speeds of 0.36 m/s (64 cells) and 0.80 m/s (128 cells) on
/// bubble_merge, where the explicit run's largest is 0.05, so the CFL limit, not the capillary
/// one, set the step. Weighted, 0.040 at 64 cells; the static drop's (validate B1) peak current
/// falls from 2.3× to 0.3× the explicit run's.
///
/// In two_phase mode the mesh moves with those same weights (term_vertex_velocities(); the
/// coupling uses it in place of interpolate_vertex_velocities() when the term is on): the
/// backward-Euler step assumes x⁽ⁿ⁺¹⁾ = x⁽ⁿ⁾ + Δt S u⁽ⁿ⁺¹⁾ for the S it damps, and a mesh moved
/// by the plain weights reads gas faces that the term hardly sees.

#include "coupling/interpolate.h"
#include "fluid/mac_grid.h"
#include "fluid/surface_viscosity.h"
#include "tracker/mesh.h"

#include <memory>

namespace meniscus::coupling {

/// The surface stiffness K of the term (fluid/surface_viscosity.h).
///
/// - `normal`: the gradient, within each triangle, of the velocity's component along the
///   triangle's normal. Shape changes are damped as by `full`; translations and the tangential
///   motion of a flat patch are free.
/// - `full`: Hysing's ∫ ∇_Γ u : ∇_Γ v over all three components. It damps the surface's
///   stretching along itself as well, a surface viscosity θσΔt that made bubble_merge's
///   interfaces immobile: the film between the bubbles did not drain (30 cells: the bubbles did
///   not merge in 24 ms at the explicit step nor in 40 ms at 3.5× it, against 10–12 ms explicit;
///   128 cells: merged 8 ms late).
enum class SurfaceTermForm { normal, full };

/// The term with μ_s = `viscosity` (Pa·s·m; θσΔt) for `mesh` on `grid`, its sampling weighted
/// by face density when `phi` (cell centres, m, negative in the liquid) is given: ρ_liquid > 0 and
/// ρ_gas ≥ 0 (kg/m³; 0 in free-surface mode, whose gas faces carry no mass). Empty (no points)
/// when no triangle lies inside the box. Throws std::invalid_argument for a negative or
/// non-finite viscosity, a φ of other dimensions than the grid's cells, densities out of range or
/// an unknown form.
std::shared_ptr<const fluid::SurfaceViscosity> build_surface_viscosity(
    const tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid, double viscosity,
    const InterpolateOptions& interpolate, const fluid::BoundaryOptions& walls,
    const fluid::Array3<double>* phi = nullptr, double rho_liquid = 1.0, double rho_gas = 1.0,
    SurfaceTermForm form = SurfaceTermForm::normal);

/// The velocity (m/s) of every vertex of `mesh` as the term samples it: the weights of
/// vertex_velocity_weights() scaled by the densities of the faces they read and renormalised, as
/// build_surface_viscosity() does with `phi`, applied to the face velocities of `grid`; sized
/// num_vertices(), zero for dead vertices. The backward-Euler step damps the surface's motion as
/// these weights see it, so the surface must move with them: with the plain interpolated
/// velocities the gas faces next to the interface, which carry 1/830 of the water's mass and
/// which the term hardly sees, moved the mesh undamped (bubble_merge at 64 cells, 4× the
/// capillary limit, the grid's largest speed at 2, 4 and 6 ms: 0.08, 0.30 and 0.33 m/s, the
/// explicit run's 0.10, 0.21 and 0.73 (merged); moved with these weights 0.10, 0.20 and 0.42).
/// Same arguments and exceptions as build_surface_viscosity() (`phi` required here).
std::vector<tracker::Vec3> term_vertex_velocities(const tracker::SurfaceMesh& mesh,
                                                  const fluid::MacGrid& grid,
                                                  const InterpolateOptions& interpolate,
                                                  const fluid::BoundaryOptions& walls,
                                                  const fluid::Array3<double>& phi,
                                                  double rho_liquid, double rho_gas);

}  // namespace meniscus::coupling
