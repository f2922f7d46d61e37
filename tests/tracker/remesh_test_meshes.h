#pragma once
/// \file Test meshes for the remeshing and topology tests: generators (used once to write the
/// OBJ files in tests/data/, and by tests that need a scene built on the spot) and loading of
/// every mesh in tests/data/.

#include "tracker/mesh.h"

#include <string>
#include <vector>

namespace meniscus::tracker::testing {

/// A named test mesh with the settings it was generated for.
struct NamedMesh {
    std::string name;  ///< file stem, e.g. "sphere"
    SurfaceMesh mesh;
    bool open = false;  ///< has boundary edges (§4.4)
};

/// Closed sphere, radius 0.25, ξ ≈ 0.06.
SurfaceMesh make_test_sphere();
/// Torus, major radius 0.3, minor 0.12, ξ ≈ 0.07 (genus 1).
SurfaceMesh make_test_torus();
/// Dumbbell along x: bulbs of radius 0.2 at ±0.3, handle radius 0.08, ξ ≈ 0.05.
SurfaceMesh make_test_dumbbell();
/// Two unit-ish subdivided cubes sharing one edge (non-manifold: 4 triangles on each piece of
/// the shared edge, consistently oriented).
SurfaceMesh make_test_edge_sharing_cubes();
/// Two cubes of side 0.4 (each face a 3 × 3 grid) facing each other across `gap` along x.
SurfaceMesh make_two_cubes(double gap);
/// A sphere with a polar cap removed: an open surface with one boundary loop.
SurfaceMesh make_test_open_cap();
/// Two spheres of radius `radius` along x separated by `gap` (closest points 2·radius+gap
/// apart), edge length `edge_length`.
SurfaceMesh make_two_spheres(double radius, double gap, double edge_length);

/// The generated meshes above, named as their files in tests/data/.
std::vector<NamedMesh> generate_test_meshes();
/// Every *.obj in tests/data/ (sorted by name); `open` is true when it has boundary edges.
std::vector<NamedMesh> load_test_meshes();

/// Mean length of the live edges.
double mean_edge_length(const SurfaceMesh& mesh);

}  // namespace meniscus::tracker::testing
