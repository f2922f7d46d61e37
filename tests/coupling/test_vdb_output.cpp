#include "coupling/vdb_output.h"
#include "tracker/implicit_mesher.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <filesystem>

namespace meniscus::coupling {
namespace {

TEST(VdbOutput, SphereLevelSetReadsBackAsSignedDistance) {
    const Eigen::Vector3d center(0.31, 0.27, 0.42);
    const double radius = 0.2, voxel = 0.01;
    tracker::ImplicitMeshOptions mesh_options;
    mesh_options.edge_length = 0.01;
    const tracker::SurfaceMesh mesh =
        tracker::mesh_implicit_shape(*tracker::make_sphere(center, radius), mesh_options);
    const std::string path =
        (std::filesystem::temp_directory_path() / "meniscus_sphere.vdb").string();
    VdbOutputOptions options;
    options.voxel_size = voxel;
    const VdbOutputInfo info = write_surface_vdb(path, mesh, options);
    EXPECT_GT(info.surface_active_voxels, 0);
    EXPECT_FALSE(std::filesystem::exists(path + ".partial"));

    openvdb::initialize();
    openvdb::io::File file(path);
    file.open();
    auto surface = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("surface"));
    auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("density"));
    file.close();
    ASSERT_TRUE(surface);
    ASSERT_TRUE(density);
    EXPECT_EQ(surface->getGridClass(), openvdb::GRID_LEVEL_SET);
    EXPECT_EQ(density->getGridClass(), openvdb::GRID_FOG_VOLUME);
    EXPECT_NEAR(surface->voxelSize()[0], voxel, 1e-12);

    const auto acc = surface->getConstAccessor();
    const auto dacc = density->getConstAccessor();
    int checked = 0, gradient_checked = 0, gradient_close = 0;
    double worst_distance_error = 0.0;
    for (auto it = surface->cbeginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        const openvdb::Vec3d w = surface->indexToWorld(c);
        const double exact = (Eigen::Vector3d(w.x(), w.y(), w.z()) - center).norm() - radius;
        const double phi = *it;
        // Sign agrees wherever the exact distance is clearly non-zero.
        if (std::abs(exact) > 0.5 * voxel) {
            EXPECT_EQ(phi < 0, exact < 0) << "at " << w;
        }
        worst_distance_error = std::max(worst_distance_error, std::abs(phi - exact));
        // |∇φ| ≈ 1 by central differences inside the band.
        if (std::abs(phi) < 1.5 * voxel) {
            double g2 = 0.0;
            for (int a = 0; a < 3; ++a) {
                openvdb::Coord p = c, m = c;
                p[a] += 1;
                m[a] -= 1;
                const double d = (acc.getValue(p) - acc.getValue(m)) / (2 * voxel);
                g2 += d * d;
            }
            // Central differences straddle the kinks of the distance to a faceted mesh, so
            // bound every sample loosely and most samples tightly.
            EXPECT_NEAR(std::sqrt(g2), 1.0, 0.2) << "at " << w;
            gradient_close += std::abs(std::sqrt(g2) - 1.0) < 0.05 ? 1 : 0;
            ++gradient_checked;
        }
        const float rho = dacc.getValue(c);
        EXPECT_GE(rho, 0.0f);
        EXPECT_LE(rho, 1.0f);
        ++checked;
    }
    EXPECT_GT(checked, 1000);
    EXPECT_GT(gradient_checked, 100);
    EXPECT_GT(gradient_close, 0.95 * gradient_checked);
    // Zero crossing within half a voxel of the sphere: φ is within that of the exact distance.
    EXPECT_LT(worst_distance_error, 0.5 * voxel);
    // Deep inside: the background of a level set is +half width, so the interior is marked
    // by the fog being 1 and φ by its inside tiles (negative).
    const openvdb::Coord centre_coord = surface->transform().worldToIndexCellCentered(
        openvdb::Vec3d(center.x(), center.y(), center.z()));
    EXPECT_LT(acc.getValue(centre_coord), 0.0f);
    EXPECT_FLOAT_EQ(dacc.getValue(centre_coord), 1.0f);
    EXPECT_GT(acc.getValue(openvdb::Coord(200, 200, 200)), 0.0f);
    EXPECT_FLOAT_EQ(dacc.getValue(openvdb::Coord(200, 200, 200)), 0.0f);
    std::filesystem::remove(path);
}

TEST(VdbOutput, RejectsBadOptions) {
    tracker::SurfaceMesh mesh;
    VdbOutputOptions options;
    EXPECT_THROW(write_surface_vdb("x.vdb", mesh, options), std::invalid_argument);
    options.voxel_size = 0.1;
    EXPECT_THROW(write_surface_vdb("x.vdb", mesh, options), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::coupling
