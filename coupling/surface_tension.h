#pragma once
/// \file Mesh → grid, second half: the mean curvature κ of the interface mesh at the faces the
/// level set crosses, as the fluid's ghost-fluid pressure jump p_liquid − p_gas = σκ needs it.
///
/// κ comes from the mesh, not from derivatives of φ: the cotangent mean curvature at vertices
/// (tracker/flows/mean_curvature.h, Meyer et al. 2003), optionally smoothed by lazy
/// area-weighted one-ring averaging (smooth_vertex_values()), then interpolated barycentrically at
/// the point of the mesh closest to each crossing x = x_lo + θ (x_hi − x_lo), θ = φ_lo / (φ_lo −
/// φ_hi), between the centres of the two cells next to the face; the closest triangle is found by
/// walk_to_closest_triangle() from the closest triangles of those two cells.
///
/// Sign: the fluid's convention — κ > 0 for a convex liquid blob (a drop), < 0 around a gas
/// bubble. The mesh's per-vertex κ is positive where the surface is convex as seen from the side
/// its normals point into; a vertex whose triangles have the liquid behind them (labels.inside =
/// liquid region) keeps that sign, one with the liquid in front (labels.outside = liquid) flips
/// it.

#include "coupling/rasterize.h"
#include "fluid/interface_input.h"
#include "fluid/mac_grid.h"
#include "tracker/mesh.h"

#include <vector>

namespace meniscus::coupling {

/// Options of the curvature at face crossings.
struct SurfaceTensionOptions {
    /// Lazy area-weighted one-ring averaging passes over the vertex curvature before it is
    /// interpolated (0 = raw cotangent curvature; see smooth_vertex_values()). Each pass widens
    /// the averaging stencil by one ring of edges. Trade-off with mesh edge ≈ dx, measured with
    /// the static drop (16.6 cells per diameter) and ellipsoid (dx = 1/32) of
    /// tests/coupling/test_surface_tension.cpp: spurious currents cut 2.3×, 5×, 10×, 20× by
    /// 1, 2, 3, 4 passes while the ellipsoid's rms κ error grows 0.9 % → 1.25, 1.8, 2.3, 2.85 %.
    /// Any count is stable on a moving mesh (mesh-scale patterns are damped, never reversed).
    int smoothing_passes = 0;
    /// Sub-grid damping rate β (dimensionless, ≥ 0; 0 = off) of subgrid_tension_velocities():
    /// mesh-scale wrinkles, which the grid can neither see nor restore, relax with diffusivity
    /// D = β h² / t_h, t_h = sqrt(ρ̄ h³ / (2πσ)) the capillary time of the mesh edge h. Measured
    /// on scenes/drop_merge.json (12 cells per diameter): without it the merge seam's wrinkles
    /// spread and grow (rms dihedral angle 0.10 → 0.72 rad in 30 ms); β = 0.05 keeps it within
    /// 0.09–0.12 rad, that of a smooth sphere with the same edge length. Static drop, 16 cells
    /// per diameter, raw curvature: peak max|u|·sqrt(ρD/σ) over 10 ms 0.52 (growing) → 0.020.
    /// Valid range [0, 0.2] (explicit stability: D Δt ≤ β h² with Δt ≤ t_h).
    double subgrid_rate = 0.05;
    /// Lazy smoothing passes (smooth_vertex_values()) that define the resolved part of the
    /// curvature normal; what they remove is the sub-grid part that subgrid_rate damps (≥ 1).
    int subgrid_resolved_passes = 4;
    /// Order m of the high-pass filter H = (I − S)^m, S the subgrid_resolved_passes smoothing
    /// passes (1..3). A pattern that S keeps to 1 − ε leaks through H as ε^m: a degree-3
    /// wrinkle on a sphere of 19 edges per radius feels 3.0 (m = 1) and 0.087 (m = 2) of the
    /// damping rate per unit D, the mesh-scale pattern 24000 either way. validate B4 (3 periods)
    /// at 16 / 24 / 32 cells per wavelength: −5.13 / −4.79 / −5.16 % with m = 1, −4.23 / −3.75 /
    /// −4.14 % with m = 2; drop_merge's surface after the merge: rms dihedral angle 0.108 and
    /// 0.122 rad at frame 20 (a smooth sphere of its edge length: 0.09–0.12).
    int subgrid_filter_order = 2;
    /// The largest |κ| a face takes, in 1/Δx (> 0): 8 is the mean curvature 2/r of a sphere of
    /// a quarter cell's radius, finer than anything the grid resolves. A vertex whose one-ring
    /// degenerates (zero area) has a cotangent curvature without bound; regression: 2.4e14 1/m
    /// (Δx = 7.8e-5 m) in bubble_merge at 128 cells just after the merge, a pressure jump that
    /// set the gas moving at 3e9 m/s.
    double max_curvature_cells = 8.0;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// What face_curvatures() did.
struct SurfaceTensionResult {
    long long crossed_faces = 0;  ///< interior faces whose two cells have φ of opposite sign
    /// Crossed faces neither of whose cells had a closest triangle (κ left 0; a band that is
    /// too thin or a rasterization that does not belong to this mesh).
    long long faces_without_triangle = 0;
    /// Crossed faces whose κ was limited to ±max_curvature_cells/Δx.
    long long limited_faces = 0;
    double min_kappa = 0.0;       ///< over the crossed faces, 1/m (0 when none)
    double max_kappa = 0.0;       ///< over the crossed faces, 1/m (0 when none)
    double vertex_seconds = 0.0;  ///< vertex curvature and smoothing, wall clock
    double face_seconds = 0.0;    ///< interpolation to the faces, wall clock
};

/// `passes` lazy one-ring smoothing passes over per-vertex `values` (sized num_vertices()):
/// x_v ← ½ x_v + ½ Σ_w A_w x_w / Σ_w A_w over the neighbours w (A = mixed Voronoi area).
/// Dead, isolated and boundary vertices keep their value. Being lazy, a pass damps every
/// pattern by a factor in [0, 1] and never reverses one: the closed one-ring mean (vertex weighted
/// like a neighbour) maps the mesh-scale pattern to about −0.27 times itself, which turns the
/// capillary force on mesh-scale wrinkles from restoring into driving (a moving drop blows up).
/// Throws std::invalid_argument if passes < 0 or values has the wrong size.
std::vector<double> smooth_vertex_values(const tracker::SurfaceMesh& mesh,
                                         std::vector<double> values, int passes);

/// Sub-grid surface-tension velocity of every vertex (m/s; sized num_vertices(), zero for dead,
/// isolated and boundary vertices): −D (I − S)^m K, m = `filter_order` (1 → −D (K − S(K))),
/// with K the cotangent curvature normal
/// (tracker::mean_curvature_normals(), κ n, n outward) and S `resolved_passes` lazy smoothing
/// passes applied to each of its components. S keeps what the grid resolves (on a sphere mesh with
/// 10 edges per radius |K − S(K)| ≤ 6 % of |K|), so this is mean-curvature flow restricted to
/// mesh-scale
/// patterns: a wrinkle the grid cannot see flattens instead of being carried (and, where the
/// surface contracts, sharpened) by the interpolated grid velocity, which has no restoring
/// component at that scale. Volume-neutral: a uniform normal speed per connected component is
/// subtracted so that each component's enclosed volume has zero rate of change.
/// Explicit motion: stable for D Δt ≤ 0.2 h².
/// `active` (empty = every vertex, else one flag per vertex): only flagged vertices move, and
/// the volume-neutral speed is spread over them alone. The coupled step flags the vertices
/// inside the fluid domain: parts of a surface that reach past the walls (the cut edges of the
/// capillary-wave slab, the ends of a wall-crossing jet) are not physical interface, and
/// damping their creases would shift the whole component through the volume-neutral term.
/// Throws std::invalid_argument if diffusivity < 0, resolved_passes < 1, filter_order is outside
/// 1..3 or active has the wrong
/// size.
std::vector<tracker::Vec3> subgrid_tension_velocities(const tracker::SurfaceMesh& mesh,
                                                      double diffusivity, int resolved_passes,
                                                      int filter_order,
                                                      const std::vector<char>& active = {});

/// Signed mean curvature κ (1/m, sum of principal curvatures) per vertex in the fluid's sign
/// convention (see the file comment), smoothed by `smoothing_passes` passes of
/// smooth_vertex_values(). Sized num_vertices(); zero for dead, isolated and boundary vertices.
std::vector<double> liquid_vertex_curvatures(const tracker::SurfaceMesh& mesh, int liquid_region,
                                             int smoothing_passes);

/// Fills interface.kappa_u, kappa_v and kappa_w (resized for `grid`, zero on faces that are
/// not crossed) from the mesh curvature, using φ and the closest triangles of `raster` (which
/// must come from rasterize_mesh() of the same mesh on the same grid). interface.phi is not
/// touched. Throws std::invalid_argument on invalid options or a raster of another size.
SurfaceTensionResult face_curvatures(const tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid,
                                     const RasterizeResult& raster,
                                     const SurfaceTensionOptions& options,
                                     fluid::InterfaceInput& interface);

/// Convenience for one fluid step: rasterize `mesh` (φ) and fill κ at the crossed faces.
/// Throws as rasterize_mesh() and face_curvatures().
fluid::InterfaceInput interface_from_mesh(const tracker::SurfaceMesh& mesh,
                                          const fluid::MacGrid& grid,
                                          const RasterizeOptions& raster_options = {},
                                          const SurfaceTensionOptions& tension_options = {},
                                          SurfaceTensionResult* tension_result = nullptr);

}  // namespace meniscus::coupling
