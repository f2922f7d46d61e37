#pragma once
/// \file Per-frame OpenVDB output of the surface (and, when given, fluid fields).
///
/// Grids written (float, world units = metres):
///  - `surface`: narrow-band signed distance to the mesh (class level set; negative inside,
///    i.e. behind the triangles' normals), built with openvdb::tools::meshToLevelSet;
///  - `density`: fog volume in [0, 1] derived from `surface` (1 inside, 0 outside, a linear
///    ramp across the inner half band): the grid renderers such as Blender shade by default.
///
/// Voxel convention: OpenVDB's — the value of voxel (i, j, k) sits at world point
/// (i, j, k) · voxel_size (a linear transform with no offset). Blender draws voxel (i, j, k)
/// as the cube [i, i+1] · voxel_size, half a voxel off; see README "Rendering".
///
/// OpenVDB's mesh tools are instantiated only here (output) and in rasterize.cpp (coupling).

#include "fluid/array3.h"
#include "fluid/mac_grid.h"
#include "tracker/mesh.h"

#include <string>

namespace meniscus::coupling {

/// Options of the VDB writer.
struct VdbOutputOptions {
    double voxel_size = 0.0;         ///< metres, > 0
    double half_width_voxels = 3.0;  ///< narrow band half width of `surface`, in voxels (≥ 1)
    bool density = true;             ///< also write the `density` fog grid
    void validate() const;           ///< throws std::invalid_argument naming the field
};

/// What was written, for logs and stats.
struct VdbOutputInfo {
    long long surface_active_voxels = 0;
    long long density_active_voxels = 0;
};

/// Fluid fields to add to the file (fluid scenes): grids `vel` (Vec3s, m/s, the face
/// velocities averaged to cell centres) and `pressure` (float, Pa), dense over the fluid box,
/// with a transform whose voxel centres are the fluid's cell centres (voxel size Δx, translated
/// by origin + ½Δx).
struct FluidFields {
    const fluid::MacGrid* grid = nullptr;
    const fluid::Array3<double>* pressure = nullptr;  ///< nx × ny × nz, may be null
};

/// Writes `path` atomically (temporary file + rename) with the grids above for the live
/// triangles of `mesh`. Throws std::invalid_argument on bad options or an empty mesh,
/// std::runtime_error if the file cannot be written.
VdbOutputInfo write_surface_vdb(const std::string& path, const tracker::SurfaceMesh& mesh,
                                const VdbOutputOptions& options, const FluidFields& fluid = {});

}  // namespace meniscus::coupling
