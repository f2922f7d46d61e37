#include "common/atomic_file.h"
#include "tracker/implicit_mesher.h"
#include "tracker/mesh_io.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <cstdint>
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
        // Three vertices of three doubles need 72 bytes; 3 follow the header.
        EXPECT_NE(std::string(e.what()).find(path + ": the header declares 3 'vertex' elements"),
                  std::string::npos)
            << e.what();
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

/// The message of the runtime_error `read` throws ("" if none).
template <typename Read>
std::string error_of(Read read) {
    try {
        read();
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return "";
}

TEST(MeshIo, PlyCountsBeyondTheFileAreRefusedBeforeReading) {
    // A 9 kB binary PLY whose face count says 2·10⁹ (the reader used to allocate for the claim).
    const std::string path = temp_file("huge_count.ply").string();
    {
        std::ofstream out(path, std::ios::binary);
        out << "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
               "property float y\nproperty float z\nelement face 2000000000\n"
               "property list uchar int vertex_indices\nend_header\n"
            << std::string(9000, '\0');
    }
    const std::string e = error_of([&] { read_ply(path); });
    EXPECT_NE(e.find("the header declares 2000000000 'face' elements of at least 13 bytes each, "
                     "but only 9000 bytes follow the header"),
              std::string::npos)
        << e;
    // ASCII: a value takes at least two characters.
    std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 1000000\nproperty float x\n"
                           "property float y\nproperty float z\nend_header\n0 0 0\n";
    EXPECT_NE(error_of([&] { read_ply(path); }).find("1000000 'vertex' elements"),
              std::string::npos);
    fs::remove(path);
}

TEST(MeshIo, PlyListLongerThanTheFileIsRefused) {
    const std::string path = temp_file("long_list.ply").string();
    {
        std::ofstream out(path, std::ios::binary);
        out << "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
               "property float y\nproperty float z\nelement face 1\n"
               "property list uint int vertex_indices\nend_header\n";
        const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        out.write(reinterpret_cast<const char*>(v), sizeof v);
        const std::uint32_t count = 4000000000u;
        out.write(reinterpret_cast<const char*>(&count), 4);
        const std::int32_t indices[3] = {0, 1, 2};
        out.write(reinterpret_cast<const char*>(indices), sizeof indices);
    }
    EXPECT_NE(error_of([&] { read_ply(path); })
                  .find("face 0: a list of 4000000000 entries is longer than the file"),
              std::string::npos);
    fs::remove(path);
}

TEST(MeshIo, ObjTrianglesRememberTheFaceAndLineTheyCameFrom) {
    const std::string path = temp_file("quad.obj").string();
    std::ofstream(path) << "# a quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                           "v 0 0 1\nf 1 2 3 4\n\nf 1 2 5\n";
    const MeshData d = read_obj(path);
    ASSERT_EQ(d.triangles.size(), 3u);
    EXPECT_EQ(d.triangle_face, (std::vector<int>{0, 0, 1}));
    EXPECT_EQ(d.face_line, (std::vector<long long>{7, 9}));
    fs::remove(path);
}

TEST(MeshIo, DirectoriesAreNotMeshFiles) {
    const fs::path dir = temp_file("folder.obj");
    fs::create_directories(dir);
    EXPECT_NE(error_of([&] { read_mesh_file(dir.string()); }).find("is a directory"),
              std::string::npos);
    fs::remove_all(dir);
}

TEST(AtomicFile, CommitChecksTheSizeOnDiskAndLeavesNothingOnFailure) {
    const std::string path = temp_file("checked.bin").string();
    std::ofstream out = open_temporary(path, std::ios::binary);
    out << std::string(100, 'x');
    out.flush();
    // What a lost write looks like afterwards: fewer bytes on disk than were written.
    fs::resize_file(temporary_path_for(path), 10);
    try {
        commit_stream(out, path);
        FAIL() << "a short file was committed";
    } catch (const WriteError& e) {
        EXPECT_NE(std::string(e.what()).find(path + ": write failed: the file holds 10 of 100 bytes"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fs::exists(path));
    EXPECT_FALSE(fs::exists(temporary_path_for(path)));
    // A good write is committed.
    std::ofstream good = open_temporary(path, std::ios::binary);
    good << std::string(100, 'y');
    commit_stream(good, path);
    EXPECT_EQ(fs::file_size(path), 100u);
    fs::remove(path);
}

}  // namespace
}  // namespace meniscus::tracker
