#include "remesh_test_meshes.h"

#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_io.h"
#include "tracker/mesh_measures.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

namespace meniscus::tracker::testing {

namespace {

SurfaceMesh mesh_shape(const ShapePtr& shape, double edge_length) {
    ImplicitMeshOptions options;
    options.edge_length = edge_length;
    SurfaceMesh m = mesh_implicit_shape(*shape, options);
    m.compact();
    return m;
}

/// Closed cube [lo, lo + size]³ with each face an n × n grid of quads cut in two, outward.
void append_cube(std::vector<Vec3>& positions, std::vector<Triangle>& triangles, const Vec3& lo,
                 double size, int n) {
    // Faces as (origin corner, u axis, v axis) with u × v outward.
    const Vec3 ex = Vec3::UnitX(), ey = Vec3::UnitY(), ez = Vec3::UnitZ();
    struct Face {
        Vec3 origin, u, v;
    };
    const Face faces[6] = {
        {lo, ey, ex},              // z = lo (normal −z)
        {lo + size * ez, ex, ey},  // z = hi
        {lo, ex, ez},              // y = lo (normal −y)
        {lo + size * ey, ez, ex},  // y = hi
        {lo, ez, ey},              // x = lo (normal −x)
        {lo + size * ex, ey, ez},  // x = hi
    };
    for (const Face& f : faces) {
        const int base = static_cast<int>(positions.size());
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i)
                positions.push_back(f.origin + size * (f.u * i + f.v * j) / n);
        auto id = [&](int i, int j) { return base + j * (n + 1) + i; };
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
                triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
            }
    }
}

/// Welds vertices that coincide up to rounding (on a 1e-9 grid).
SurfaceMesh weld(const std::vector<Vec3>& positions, const std::vector<Triangle>& triangles) {
    constexpr double WELD_GRID = 1e9;
    std::map<std::array<long long, 3>, int> index;
    std::vector<int> remap(positions.size());
    std::vector<Vec3> welded;
    for (size_t i = 0; i < positions.size(); ++i) {
        const std::array<long long, 3> key{std::llround(positions[i].x() * WELD_GRID),
                                           std::llround(positions[i].y() * WELD_GRID),
                                           std::llround(positions[i].z() * WELD_GRID)};
        auto [it, inserted] = index.insert({key, static_cast<int>(welded.size())});
        if (inserted)
            welded.push_back(positions[i]);
        remap[i] = it->second;
    }
    std::vector<Triangle> out;
    for (const Triangle& t : triangles)
        out.push_back({remap[static_cast<size_t>(t[0])], remap[static_cast<size_t>(t[1])],
                       remap[static_cast<size_t>(t[2])]});
    return SurfaceMesh(welded, out);
}

}  // namespace

SurfaceMesh make_test_sphere() {
    return mesh_shape(make_sphere({0, 0, 0}, 0.25), 0.06);
}

SurfaceMesh make_test_torus() {
    return mesh_shape(make_torus({0, 0, 0}, {0, 0, 1}, 0.3, 0.12), 0.07);
}

SurfaceMesh make_test_dumbbell() {
    return mesh_shape(make_dumbbell({0, 0, 0}, 0.2, 0.6, 0.08, 0.05), 0.05);
}

SurfaceMesh make_test_edge_sharing_cubes() {
    std::vector<Vec3> positions;
    std::vector<Triangle> triangles;
    constexpr int SUBDIVISIONS = 4;
    append_cube(positions, triangles, {0, 0, 0}, 0.4, SUBDIVISIONS);
    append_cube(positions, triangles, {0.4, 0.4, 0}, 0.4, SUBDIVISIONS);
    return weld(positions, triangles);
}

SurfaceMesh make_two_cubes(double gap) {
    std::vector<Vec3> positions;
    std::vector<Triangle> triangles;
    constexpr int SUBDIVISIONS = 3;
    constexpr double SIDE = 0.4;
    append_cube(positions, triangles, {0, 0, 0}, SIDE, SUBDIVISIONS);
    append_cube(positions, triangles, {SIDE + gap, 0, 0}, SIDE, SUBDIVISIONS);
    return weld(positions, triangles);
}

SurfaceMesh make_test_open_cap() {
    SurfaceMesh sphere = make_test_sphere();
    constexpr double CUT_HEIGHT = 0.15;
    for (int ti = 0; ti < sphere.num_triangles(); ++ti) {
        if (!sphere.triangle_alive(ti))
            continue;
        const Triangle& t = sphere.triangle(ti);
        const double z =
            (sphere.position(t[0]).z() + sphere.position(t[1]).z() + sphere.position(t[2]).z()) /
            3.0;
        if (z > CUT_HEIGHT)
            sphere.remove_triangle(ti);
    }
    for (int vi = 0; vi < sphere.num_vertices(); ++vi)
        if (sphere.vertex_alive(vi) && sphere.vertex_triangles(vi).empty())
            sphere.remove_vertex(vi);
    sphere.compact();
    return sphere;
}

SurfaceMesh make_two_spheres(double radius, double gap, double edge_length) {
    const double offset = radius + 0.5 * gap;
    SurfaceMesh a = mesh_shape(make_sphere({-offset, 0, 0}, radius), edge_length);
    // The second sphere is the mirror image of the first (x → −x, orientation restored), so the
    // two closest vertices face each other exactly across the gap.
    std::vector<Vec3> positions = a.positions();
    std::vector<Triangle> triangles;
    for (int ti = 0; ti < a.num_triangles(); ++ti)
        triangles.push_back(a.triangle(ti));
    const int n = a.num_vertices();
    for (int vi = 0; vi < n; ++vi) {
        Vec3 p = a.position(vi);
        p.x() = -p.x();
        positions.push_back(p);
    }
    const int m = static_cast<int>(triangles.size());
    for (int k = 0; k < m; ++k) {
        const Triangle& t = triangles[static_cast<size_t>(k)];
        triangles.push_back({t[0] + n, t[2] + n, t[1] + n});
    }
    return SurfaceMesh(positions, triangles);
}

std::vector<NamedMesh> generate_test_meshes() {
    std::vector<NamedMesh> out;
    out.push_back({"sphere", make_test_sphere(), false});
    out.push_back({"torus", make_test_torus(), false});
    out.push_back({"dumbbell", make_test_dumbbell(), false});
    out.push_back({"edge_sharing_cubes", make_test_edge_sharing_cubes(), false});
    out.push_back({"open_cap", make_test_open_cap(), true});
    return out;
}

std::vector<NamedMesh> load_test_meshes() {
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(MENISCUS_TEST_DATA_DIR))
        if (entry.path().extension() == ".obj")
            files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    std::vector<NamedMesh> out;
    for (const auto& path : files) {
        SurfaceMesh mesh = to_surface_mesh(read_obj(path.string()), path.string());
        bool open = false;
        for (int ei = 0; ei < mesh.num_edges(); ++ei)
            open = open || (mesh.edge_alive(ei) && mesh.is_boundary_edge(ei));
        out.push_back({path.stem().string(), std::move(mesh), open});
    }
    return out;
}

double mean_edge_length(const SurfaceMesh& mesh) {
    return edge_length_stats(mesh).mean;
}

}  // namespace meniscus::tracker::testing
