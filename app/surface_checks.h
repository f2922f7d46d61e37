#pragma once
/// \file The initial surface as the user gave it: loading /surface/mesh_file with every problem
/// named in the file's own terms (OBJ vertex numbers from 1 and line numbers; PLY element
/// indices from 0), and the checks a mesh must pass before a run starts — orientation
/// (counter-clockwise seen from outside; nested surfaces alternate), coordinates double
/// precision can resolve, and, for fluid scenes, a surface that meets the fluid box.

#include "app/scene.h"
#include "tracker/mesh.h"
#include "tracker/mesh_io.h"

#include <string>
#include <vector>

namespace meniscus::app {

/// Reads /surface/mesh_file (counts checked against the file's size before allocating).
/// Throws InputError naming the file and the problem, including a file without faces and a
/// face that refers to a vertex the file does not have.
tracker::MeshData read_surface_file(const Scene& scene);

/// Builds the mesh of `data` (as read_surface_file() returns it) and checks it: closed (unless
/// /surface/open), consistently oriented, no degenerate or duplicate faces, no
/// self-intersection, outward orientation and alternating nesting (closed surfaces),
/// coordinates within what doubles resolve at its edge lengths. Throws InputError listing the
/// first problems with the faces and vertices as the file numbers them.
tracker::SurfaceMesh checked_surface_mesh(const tracker::MeshData& data, const Scene& scene);

/// Fluid scenes: throws InputError when the box `surface_min`–`surface_max` around the initial
/// surface does not meet the fluid box (/domain).
void check_surface_meets_fluid_box(const Scene& scene, const Eigen::Vector3d& surface_min,
                                   const Eigen::Vector3d& surface_max, const std::string& what);

}  // namespace meniscus::app
