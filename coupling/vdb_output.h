#pragma once
/// \file Per-frame OpenVDB output of the surface and, for fluid scenes, the fluid's fields.
///
/// Grids written (float unless noted; lengths in output units = metres × length_scale):
///  - `surface`: narrow-band signed distance to the mesh (class level set), negative inside the
///    surface — in VdbOutputOptions::inside_region, the region the mesh encloses. Band voxels are
///    signed by the exact inside/outside test against the mesh (signed_band(), mesh_band.h, the
///    same rule as the coupling step's φ; no flood fill, so a gap narrower than a voxel stays
///    outside); values outside the band keep the sign of the band next to them (±background).
///    Vertex pinning (VdbOutputOptions::pin_vertices, on by default): the band holds exact
///    distances, but where the mesh folds more sharply than a voxel (e.g. the tip of a thin air
///    slit a merge has just zipped, all eight voxel centres around a vertex on one side) no grid
///    of exact distances interpolates to 0 at the mesh. So, for each mesh vertex whose trilinear
///    sample of `surface` — or of `density`'s clamped ramp — is more than vertex_pin_voxels off
///    zero, the magnitudes of those of its eight voxel values that have the sample's sign are
///    scaled down until the sample is vertex_pin_voxels off (a few sweeps, since vertices share
///    voxels). Signs never change (they stay the exact inside/outside test) and magnitudes only
///    shrink, so values within about a voxel of such folds are no longer exact distances;
///    elsewhere (all vertices already within vertex_pin_voxels) nothing changes;
///  - `density`: fog volume in [0, 1] centred on the surface: an anti-aliased step
///    clamp(½ − φ / (ramp · h), 0, 1) (h the voxel size), whose ½ isosurface is the mesh, 1
///    deep inside, 0 (inactive) outside: the grid renderers such as Blender shade by default;
///  - `vel` (Vec3s, output units per second) and `pressure` (Pa): the fluid's velocity averaged
///    from the faces to the cell centres and its pressure, dense over the fluid box, with a
///    transform whose voxel centres are the fluid's cell centres (voxel size Δx, translated by
///    origin + ½Δx).
///
/// Voxel convention: OpenVDB's — the value of voxel (i, j, k) sits at world point
/// (i, j, k) · voxel_size for `surface` and `density` (a linear transform with no offset).
/// Blender draws voxel (i, j, k) as the cube [i, i+1] · voxel_size, half a voxel off; see the
/// README's "Rendering" and the run's meniscus.json.

#include "fluid/array3.h"
#include "fluid/mac_grid.h"
#include "tracker/mesh.h"

#include <string>

namespace meniscus::coupling {

/// Options of the VDB writer.
struct VdbOutputOptions {
    double voxel_size = 0.0;         ///< of `surface` and `density`, metres, > 0
    double half_width_voxels = 3.0;  ///< narrow band half width of `surface`, in voxels (≥ 1)
    bool density = true;             ///< also write the `density` fog grid
    /// Width of the `density` ramp across the surface, in voxels, in (0, 2 · half_width_voxels].
    double density_ramp_voxels = 2.0;
    bool velocity = true;  ///< write `vel` when fluid fields are given
    bool pressure = true;  ///< write `pressure` when fluid fields are given
    /// Output length units per metre (1000 writes millimetres): scales the transforms, the
    /// distances of `surface` and the velocities of `vel`; > 0.
    double length_scale = 1.0;
    /// Vertex pinning (see the file comment): every mesh vertex's trilinear sample of `surface`
    /// and of `density` ends within vertex_pin_voxels of the surface, at the price of exact
    /// distances near folds sharper than a voxel.
    bool pin_vertices = true;
    /// Target of the pinning, in voxels, in (0, 0.5].
    double vertex_pin_voxels = 0.2;
    /// The region label (tracker::LabelPair) the surface encloses: `surface` is negative and
    /// `density` 1 there.
    int inside_region = 1;
    /// A periodic scene's box (issue 39): along each axis with a length > 0 the `density` fog
    /// holds only the voxels whose centres lie in [origin, origin + length), so that a drop across
    /// a face of the box shows cut there at both ends and copies of the box tile without doubled
    /// fog. `surface` keeps its whole band (its distances near a face see the surface beyond it).
    tracker::MeshPeriods density_cut;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// What was written, for logs and stats.
struct VdbOutputInfo {
    long long surface_active_voxels = 0;
    long long density_active_voxels = 0;
    /// Largest offset from the surface of a mesh vertex's trilinear samples (of `surface`, and
    /// of `density`'s ramp when written), in voxels, before / after vertex pinning (equal when
    /// pinning is off).
    double vertex_offset_before_voxels = 0.0;
    double vertex_offset_after_voxels = 0.0;
    long long vertices_pinned = 0;  ///< vertices whose samples were pinned
    long long voxels_pinned = 0;    ///< `surface` voxels whose magnitude pinning shrank
    bool velocity_written = false;
    bool pressure_written = false;
};

/// Fluid fields to add to the file (fluid scenes).
struct FluidFields {
    const fluid::MacGrid* grid = nullptr;
    const fluid::Array3<double>* pressure = nullptr;  ///< nx × ny × nz, may be null
};

/// Writes `path` atomically (temporary file + rename) with the grids above for the live
/// triangles of `mesh` (positions in metres). Throws std::invalid_argument on bad options or an
/// empty mesh, std::runtime_error if the file cannot be written.
VdbOutputInfo write_surface_vdb(const std::string& path, const tracker::SurfaceMesh& mesh,
                                const VdbOutputOptions& options, const FluidFields& fluid = {});

}  // namespace meniscus::coupling
