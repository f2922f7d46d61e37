#pragma once
/// \file The signed narrow band of a surface mesh on a voxel lattice: every voxel centre within
/// a half width of the mesh gets its exact distance to the mesh, its closest triangle and the
/// sign of an exact inside/outside test against the mesh. One implementation serves the coupling
/// step (rasterize.h: φ at the fluid's cell centres) and the per-frame VDB output
/// (vdb_output.h: the `surface` and `density` grids), so both classify space the same way.
///
/// Band: OpenVDB's meshToVolume (unsigned mode) supplies the band voxels and a closest polygon
/// per voxel, but that index is approximate (its band dilation hands polygons from voxel to
/// voxel: distances from it were off by up to 0.9 voxel on a meshed sphere). Each band voxel
/// therefore starts from OpenVDB's triangles of itself and its six face neighbours and walks to
/// any triangle sharing a vertex with the current best while that one is closer; its distance is
/// the exact (double precision) distance to the triangle found.
///
/// Sign rule (several drops and bubbles at once, never a flood fill): a voxel takes the region of
/// the side of its closest triangle it lies on — `labels(ti).outside` if it lies in front of the
/// triangle (along its normal), `labels(ti).inside` if behind — where "side" is decided by the
/// angle-weighted pseudo-normal of the closest feature (face, edge or vertex; Bærentzen and Aanæs
/// 2005), which is exact for closed, consistently oriented, non-self-intersecting meshes. Its
/// distance is negative iff that region is SignedBandOptions::inside_region. A gap between two
/// surfaces narrower than a voxel therefore stays outside, however the voxel centres fall.
/// A drop (labels {1, 0}, outward normals), a bubble in liquid (labels {0, 1} with outward
/// normals, or {1, 0} with inward normals) and a pool filling the domain are all classified by
/// their labels, not by winding parity.
///
/// This translation unit and vdb_output.cpp are the only ones of the library that instantiate
/// OpenVDB's mesh tools; this header does not include OpenVDB.

#include "tracker/mesh.h"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace meniscus::coupling {

/// A regular lattice of voxel centres: voxel (i, j, k) is centred at origin + (i, j, k)·voxel_size.
struct VoxelLattice {
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< centre of voxel (0, 0, 0), m
    double voxel_size = 0.0;                           ///< m, > 0
    Eigen::Vector3d centre(int i, int j, int k) const {
        return origin + voxel_size * Eigen::Vector3d(i, j, k);
    }
};

/// Inclusive voxel index bounds [lo, hi] per axis (e.g. the fluid's cells 0 … n − 1).
struct VoxelBounds {
    std::array<int, 3> lo{0, 0, 0};
    std::array<int, 3> hi{0, 0, 0};
    bool contains(int i, int j, int k) const {
        return i >= lo[0] && j >= lo[1] && k >= lo[2] && i <= hi[0] && j <= hi[1] && k <= hi[2];
    }
};

/// Options of signed_band().
struct SignedBandOptions {
    /// Voxels whose centre lies within this many voxels of the mesh are in the band (OpenVDB's
    /// band, so a few just beyond may be included; > 0).
    double half_width_voxels = 3.0;
    /// The region label (of tracker::LabelPair) whose voxels get a negative distance.
    int inside_region = 1;
    void validate() const;  ///< throws std::invalid_argument naming the field
};

/// One voxel of the band.
struct BandVoxel {
    std::array<int, 3> ijk{0, 0, 0};
    double phi = 0.0;  ///< exact distance of the voxel centre to the mesh, m; negative inside
    int closest_triangle = tracker::INVALID_INDEX;  ///< mesh triangle index (live)
};

/// The band and the wall-clock seconds of its two phases.
struct SignedBand {
    std::vector<BandVoxel> voxels;        ///< in no particular order, each voxel once
    double seconds_mesh_to_volume = 0.0;  ///< packing the mesh + openvdb::tools::meshToVolume
    double seconds_exact = 0.0;           ///< exact closest triangles, distances and signs
};

/// The signed band of the live triangles of `mesh` on `lattice` (see the file comment), limited
/// to `bounds` when given. Empty for a mesh without live triangles. Throws
/// std::invalid_argument on invalid options or a lattice with voxel_size ≤ 0.
SignedBand signed_band(const tracker::SurfaceMesh& mesh, const VoxelLattice& lattice,
                       const SignedBandOptions& options, const VoxelBounds* bounds = nullptr);

/// The region of point `x` (m) as seen from its closest live triangle over the whole mesh
/// (brute force, with the sign rule of the file comment); `ambient_region` for a mesh without
/// live triangles.
int region_at(const tracker::SurfaceMesh& mesh, const Eigen::Vector3d& x, int ambient_region);

/// Local closest-triangle search: from live triangle `start_ti`, repeatedly moves to the live
/// triangle sharing a vertex with the current one that is closest to `x` (m) while it is
/// strictly closer (at most 64 moves), and returns where it stops — the closest triangle of the
/// sheet around `start_ti` unless another sheet lies nearer. INVALID_INDEX for an INVALID start.
int walk_to_closest_triangle(const tracker::SurfaceMesh& mesh, int start_ti,
                             const Eigen::Vector3d& x);

}  // namespace meniscus::coupling
