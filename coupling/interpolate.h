#pragma once
/// \file Grid → mesh: the fluid velocity at the mesh vertices (coupling step 5).
///
/// Each velocity component is interpolated from its own staggered face lattice (u on x-faces at
/// origin + (i, j+½, k+½)·dx, etc.; see fluid/mac_grid.h), so every method reproduces any linear
/// velocity field exactly wherever its stencil lies inside the face lattice.

#include "fluid/boundary.h"
#include "fluid/mac_grid.h"
#include "tracker/mesh.h"

#include <Eigen/SparseCore>

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
    quadratic_bspline,
    /// Interface-aware: the velocity has a kink (inviscid: a jump in its normal derivative) at the
    /// interface, which trilinear interpolation smears over a cell — at a vertex midway between
    /// two faces a mode decaying as e^{−k|z|} comes out low by k·dx/2, so a capillary wave's
    /// frequency depends on where its surface sits in the cell (B4 at 16 cells per wavelength,
    /// sub-grid tension off: −4.3 % with the surface on a face, −11.7 % with it 0.4 cell above;
    /// with this method −2.9 % and −4.2 %). Along the grid axis
    /// closest to the vertex normal each of the 2 × 2 face columns is evaluated where the
    /// vertex's tangent plane crosses it, by the linear extrapolations from the two faces on
    /// either side of that point, blended by nearness ((1−d)·below + d·above, d the
    /// crossing's fraction of the face spacing); the four column values are blended bilinearly.
    /// Exact for linear fields and for fields linear on each side of a planar interface. The
    /// default: `meniscus validate` quick, against trilinear — Lamb's l = 2 frequency at 12 cells
    /// per diameter −4.9 % → −0.3 %, Rayleigh–Plateau growth at R = 3 cells −5.5 % → −0.6 %,
    /// static-drop spurious currents +7 %. Points outside the face lattice are clamped onto it
    /// (as trilinear); where the 4-face column leaves the lattice (within about one cell of a
    /// wall) it falls back to linear interpolation along the column, extrapolated where the
    /// tangent plane crosses the column beyond its end faces (at most about two face spacings).
    one_sided
};

/// The velocity of a vertex outside the domain (a closed mesh made to cross a wall, as the cut
/// ends of a column through its end walls or a slab reaching past the side walls).
enum class OutsideVelocity {
    /// The velocity at the nearest point of the face lattice: the part beyond the wall moves as
    /// the surface at the wall does, so a wave or bulge is not continued past it (the surface
    /// kinks at the wall as the inside moves, and the kink's curvature feeds back). B4's capillary
    /// wave at 32 cells per wavelength, half periods over 3 periods: 0.245–0.414 s against
    /// 0.2826 s, the half-period amplitude peaks 0.69–1.32× the start.
    clamp,
    /// Across free-slip walls, the mirror image: the velocity at the point reflected into the
    /// domain, its wall-normal component negated — the flow a free-slip wall (a symmetry plane of
    /// inviscid flow) continues into, so the mesh outside stays the mirror of the mesh inside.
    /// Across no-slip walls, as `clamp`. The default: the same B4 run's half periods are
    /// 0.2806–0.2851 s (within 0.9 %), the amplitude peaks 0.99–1.06× the start.
    mirror
};

/// Options of interpolate_vertex_velocities().
struct InterpolateOptions {
    VelocityInterpolation method = VelocityInterpolation::one_sided;
    OutsideVelocity outside = OutsideVelocity::mirror;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Velocity (m/s) of `grid` at position `x` (m) with `method`. `normal` (any length; only its
/// direction is used) is the interface normal at `x`, which `one_sided` needs; with a zero
/// normal, or for the other methods, it is ignored (`one_sided` then samples trilinearly).
Eigen::Vector3d sample_grid_velocity(const fluid::MacGrid& grid, const Eigen::Vector3d& x,
                                     VelocityInterpolation method,
                                     const Eigen::Vector3d& normal = Eigen::Vector3d::Zero());

/// Velocity (m/s) at every vertex of `mesh`, sized num_vertices(); zero for dead vertices.
/// `one_sided` takes each vertex's normal from tracker::area_weighted_vertex_normals().
/// `walls` are the domain's walls (which of them OutsideVelocity::mirror reflects across).
/// Parallel over vertices (TBB). Throws std::invalid_argument on invalid options.
std::vector<tracker::Vec3> interpolate_vertex_velocities(const fluid::MacGrid& grid,
                                                         const tracker::SurfaceMesh& mesh,
                                                         const InterpolateOptions& options = {},
                                                         const fluid::BoundaryOptions& walls = {});

/// The weights behind interpolate_vertex_velocities(): row 3p + a holds the weights of the face
/// velocities whose sum is component a of the velocity of vertex `vertices[p]` — the same method,
/// normals and mirroring, so S u reproduces the vertex velocities of any grid `u`. Columns index
/// the flat face vector [u | v | w] (offset_a + MacGrid::velocity(a).index(i, j, k)). Throws
/// std::invalid_argument on invalid options or a vertex that is not live.
Eigen::SparseMatrix<double, Eigen::RowMajor> vertex_velocity_weights(
    const fluid::MacGrid& grid, const tracker::SurfaceMesh& mesh, const std::vector<int>& vertices,
    const InterpolateOptions& options = {}, const fluid::BoundaryOptions& walls = {});

}  // namespace meniscus::coupling
