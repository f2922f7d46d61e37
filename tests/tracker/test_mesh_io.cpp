#include "tracker/implicit_mesher.h"
#include "tracker/mesh_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

namespace meniscus::tracker {
namespace {

namespace fs = std::filesystem;

fs::path temp_file(const std::string& name) {
    return fs::temp_directory_path() / ("meniscus_io_" + name);
}

SurfaceMesh jittered_sphere() {
    ImplicitMeshOptions o;
    o.edge_length = 0.1;
    SurfaceMesh m = mesh_implicit_shape(*make_sphere({0.1, 0.2, 0.3}, 0.5), o);
    // Values that do not round-trip through short decimal text.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1e-3, 1e-3);
    for (int vi = 0; vi < m.num_vertices(); ++vi)
        m.set_position(vi, m.position(vi) + Vec3(u(rng), u(rng), u(rng)) / 3.0);
    return m;
}

void expect_identical(const SurfaceMesh& m, const MeshData& d) {
    ASSERT_EQ(d.positions.size(), static_cast<size_t>(m.num_vertices()));
    ASSERT_EQ(d.triangles.size(), static_cast<size_t>(m.num_triangles()));
    for (int vi = 0; vi < m.num_vertices(); ++vi)
        EXPECT_EQ(d.positions[static_cast<size_t>(vi)], m.position(vi));  // bit-exact
    for (int ti = 0; ti < m.num_triangles(); ++ti)
        EXPECT_EQ(d.triangles[static_cast<size_t>(ti)], m.triangle(ti));
}

TEST(MeshIo, PlyRoundTripIsExact) {
    const SurfaceMesh m = jittered_sphere();
    std::vector<Vec3> velocity(static_cast<size_t>(m.num_vertices()));
    for (size_t i = 0; i < velocity.size(); ++i)
        velocity[i] = Vec3(i * 0.1, -1.0 / (i + 3.0), 1e-300);
    const std::string path = temp_file("round.ply").string();
    write_ply(path, m, &velocity);
    const MeshData d = read_ply(path);
    expect_identical(m, d);
    ASSERT_EQ(d.velocities.size(), velocity.size());
    for (size_t i = 0; i < velocity.size(); ++i)
        EXPECT_EQ(d.velocities[i], velocity[i]);
    EXPECT_FALSE(fs::exists(path + ".partial"));
    fs::remove(path);
}

TEST(MeshIo, ObjRoundTripIsExact) {
    const SurfaceMesh m = jittered_sphere();
    const std::string path = temp_file("round.obj").string();
    write_obj(path, m);
    expect_identical(m, read_obj(path));
    expect_identical(m, read_mesh_file(path));
    fs::remove(path);
}

TEST(MeshIo, WritersSkipDeadElements) {
    SurfaceMesh m({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {5, 5, 5}},
                  {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
    m.remove_vertex(4);
    const std::string path = temp_file("dead.ply").string();
    write_ply(path, m);
    const MeshData d = read_ply(path);
    EXPECT_EQ(d.positions.size(), 4u);
    EXPECT_EQ(d.triangles.size(), 4u);
    fs::remove(path);
}

TEST(MeshIo, ReadsAsciiPlyWithQuads) {
    const std::string path = temp_file("ascii.ply").string();
    std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                           "property float y\nproperty float z\nelement face 1\n"
                           "property list uchar int vertex_indices\nend_header\n"
                           "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
    const MeshData d = read_ply(path);
    ASSERT_EQ(d.triangles.size(), 2u);  // the quad is fanned
    EXPECT_EQ(d.triangles[1], (Triangle{0, 2, 3}));
    EXPECT_EQ(d.positions[2], Vec3(1, 1, 0));
    fs::remove(path);
}

TEST(MeshIo, ErrorsNameFileAndProblem) {
    const std::string path = temp_file("bad.ply").string();
    std::ofstream(path)
        << "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\n"
           "property double y\nproperty double z\nend_header\nabc";
    try {
        read_ply(path);
        FAIL() << "truncated PLY accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(path + ": truncated binary PLY data"),
                  std::string::npos);
    }
    EXPECT_THROW(read_mesh_file("mesh.stl"), std::runtime_error);
    EXPECT_THROW(read_ply(temp_file("missing.ply").string()), std::runtime_error);
    MeshData d;
    d.positions = {{0, 0, 0}, {1, 0, 0}};
    d.triangles = {{0, 1, 2}};
    try {
        to_surface_mesh(d, "soup");
        FAIL() << "out-of-range index accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("soup: triangle 0 refers to vertex 2"),
                  std::string::npos);
    }
    fs::remove(path);
}

}  // namespace
}  // namespace meniscus::tracker
