#pragma once
/// \file Reading and writing triangle meshes: PLY (binary little-endian or ASCII) and OBJ.
///
/// Writers are atomic (temporary file + rename). Readers accept triangles and convex polygons
/// (fanned into triangles), check indices, and throw std::runtime_error naming the file, line or
/// element and what is wrong. They do not check closedness or orientation: call validate_mesh().

#include "tracker/mesh.h"

#include <string>
#include <vector>

namespace meniscus::tracker {

/// Raw triangle soup as stored in a file, before it becomes a SurfaceMesh.
struct MeshData {
    std::vector<Vec3> positions;
    std::vector<Triangle> triangles;
    std::vector<Vec3> velocities;  ///< per vertex; empty when the file has none
    /// Per triangle, the file's face (0-based, in file order) it was cut from: polygons are
    /// fanned into several triangles. Lets messages name what the user wrote.
    std::vector<int> triangle_face;
    /// OBJ: per face, the (1-based) line it is on; empty for PLY.
    std::vector<long long> face_line;
};

/// Writes binary little-endian PLY: vertex x, y, z (double) and, when `velocities` is non-null,
/// vx, vy, vz (double); faces as uchar-counted int lists. Only live elements are written, in
/// index order (dead slots removed). Throws meniscus::WriteError (naming the path and the
/// system's reason) if the file cannot be written completely; nothing is then left at `path`.
void write_ply(const std::string& path, const SurfaceMesh& mesh,
               const std::vector<Vec3>* velocities = nullptr);
/// Writes Wavefront OBJ (positions with 17 significant digits, so reading it back is exact).
void write_obj(const std::string& path, const SurfaceMesh& mesh);

/// Reads PLY (binary little/big endian or ASCII; float or double coordinates; optional vx, vy,
/// vz). Throws std::runtime_error with the file name and the problem. Element and list counts
/// are checked against the bytes the file has left before anything is allocated for them.
MeshData read_ply(const std::string& path);
/// Reads OBJ `v` and `f` records (f accepts v, v/vt, v/vt/vn, v//vn and negative indices).
MeshData read_obj(const std::string& path);
/// Dispatches on the extension (.ply, .obj, case-insensitive); throws for others and for paths
/// that are not regular files (a directory).
MeshData read_mesh_file(const std::string& path);

/// Builds a SurfaceMesh from raw data, throwing std::runtime_error (naming `source`) for
/// out-of-range or repeated vertex indices.
SurfaceMesh to_surface_mesh(const MeshData& data, const std::string& source);

}  // namespace meniscus::tracker
