#pragma once
/// \file Mesh → grid: the signed distance φ of the interface mesh at the fluid's cell centres
/// (paper's coupling step 2), built each step with OpenVDB's meshToVolume.
///
/// Placement: the VDB voxel (i, j, k) is the fluid cell (i, j, k); its centre is
/// origin + (i+½, j+½, k+½)·dx (voxel size dx, transform translated by origin + ½dx), so no
/// resampling is needed.
///
/// Band and signs: signed_band() (mesh_band.h), shared with the VDB writer — exact distances and
/// closest triangles in the band, the sign of the region each cell centre lies in by the
/// pseudo-normal side of its closest triangle and that triangle's labels. The cell is liquid iff
/// that region is RasterizeOptions::liquid_region (1 by default, the tracker's convention:
/// 0 = ambient gas, 1 = liquid).
///
/// Cells outside the band get the sign of the band cells they are connected to (a breadth-first
/// fill over face neighbours) and the magnitude of the band half width (they are not distances).
/// With no band cell in the domain at all, the region of one cell centre is found from its
/// closest triangle over the whole mesh (or is the ambient region 0 for an empty mesh) and
/// given to every cell.

#include "coupling/mesh_band.h"
#include "fluid/array3.h"
#include "fluid/mac_grid.h"
#include "tracker/mesh.h"

namespace meniscus::coupling {

/// Options of rasterize_mesh().
struct RasterizeOptions {
    /// Half width of the narrow band in cells (≥ 2: the sign fill needs the band to reach more
    /// than one cell from the surface). Band cells carry exact distances and closest triangles;
    /// the curvature step needs them on both cells next to each crossed face (≤ 1 cell away).
    double half_width_cells = 3.0;
    /// The region label (of LabelPair) that is liquid; every other region is gas.
    int liquid_region = 1;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// Wall-clock seconds of each phase of rasterize_mesh().
struct RasterizeTimings {
    double mesh_to_volume = 0.0;  ///< packing the mesh + openvdb::tools::meshToVolume
    double band = 0.0;            ///< exact distances and signs of the band cells
    double sign_fill = 0.0;       ///< signs of the cells outside the band
    double total = 0.0;
};

/// φ at cell centres and, in the band, the closest triangle of every cell.
struct RasterizeResult {
    /// Signed distance (m) at cell centres, nx × ny × nz, NEGATIVE IN THE LIQUID (the fluid's
    /// InterfaceInput::phi). Exact point–mesh distance in the band; ±band_value outside it.
    fluid::Array3<double> phi;
    /// Index of the mesh triangle closest to each band cell's centre (the mesh's own triangle
    /// indices, dead slots never appear), tracker::INVALID_INDEX outside the band.
    fluid::Array3<int> closest_triangle;
    long long band_cells = 0;  ///< cells with a closest triangle
    double band_value = 0.0;   ///< |φ| given to cells outside the band, m (≥ every band |φ|)
    int liquid_region = 1;     ///< the liquid region used (RasterizeOptions::liquid_region)
    RasterizeTimings timings;
};

/// Rasterizes the live triangles of `mesh` onto the cell centres of `grid` (see the file
/// comment for placement and signs). Dead vertices and triangles are skipped. Throws
/// std::invalid_argument on invalid options.
RasterizeResult rasterize_mesh(const tracker::SurfaceMesh& mesh, const fluid::MacGrid& grid,
                               const RasterizeOptions& options = {});

}  // namespace meniscus::coupling
