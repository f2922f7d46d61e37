#include "coupling/periodic_images.h"
#include "coupling/vdb_output.h"
#include "tracker/implicit_mesher.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

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

/// The grids of a VDB file by name.
std::map<std::string, openvdb::GridBase::Ptr> read_grids(const std::string& path) {
    openvdb::initialize();
    openvdb::io::File file(path);
    file.open();
    std::map<std::string, openvdb::GridBase::Ptr> grids;
    for (auto it = file.beginName(); it != file.endName(); ++it)
        grids[it.gridName()] = file.readGrid(it.gridName());
    file.close();
    return grids;
}

openvdb::FloatGrid::Ptr float_grid(const std::map<std::string, openvdb::GridBase::Ptr>& grids,
                                   const std::string& name) {
    const auto it = grids.find(name);
    return it == grids.end() ? nullptr : openvdb::gridPtrCast<openvdb::FloatGrid>(it->second);
}

tracker::SurfaceMesh sphere_mesh(const Eigen::Vector3d& centre, double radius, double edge) {
    tracker::ImplicitMeshOptions options;
    options.edge_length = edge;
    return tracker::mesh_implicit_shape(*tracker::make_sphere(centre, radius), options);
}

/// Two separate spheres in one mesh.
tracker::SurfaceMesh two_spheres(const Eigen::Vector3d& c0, const Eigen::Vector3d& c1,
                                 double radius, double edge) {
    const tracker::SurfaceMesh a = sphere_mesh(c0, radius, edge), b = sphere_mesh(c1, radius, edge);
    std::vector<tracker::Vec3> positions = a.positions();
    std::vector<tracker::Triangle> triangles;
    for (int ti = 0; ti < a.num_triangles(); ++ti)
        triangles.push_back(a.triangle(ti));
    for (int ti = 0; ti < b.num_triangles(); ++ti) {
        tracker::Triangle t = b.triangle(ti);
        for (int& v : t)
            v += a.num_vertices();
        triangles.push_back(t);
    }
    positions.insert(positions.end(), b.positions().begin(), b.positions().end());
    return tracker::SurfaceMesh(positions, triangles);
}

std::string temp_vdb(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("meniscus_" + name + ".vdb")).string();
}

/// The grids write_surface_vdb() writes for `mesh` (through a temporary file named by `name`).
std::map<std::string, openvdb::GridBase::Ptr> written_grids(const tracker::SurfaceMesh& mesh,
                                                            const VdbOutputOptions& options,
                                                            const std::string& name) {
    const std::string path = temp_vdb(name);
    write_surface_vdb(path, mesh, options);
    auto grids = read_grids(path);
    std::filesystem::remove(path);
    return grids;
}

TEST(VdbOutput, GapNarrowerThanAVoxelStaysOutside) {
    // Two spheres whose gap is 0.3, 0.6 and 1.5 voxels wide, centred on a plane of voxel centres
    // (x = 0): inside-by-flood-fill (openvdb::tools::meshToLevelSet, used before) closed such a
    // gap, making the voxel centres in it negative. Signed from the mesh, every voxel centre
    // outside both spheres is positive and every one inside either (beyond the mesh's chord
    // error) negative.
    const double voxel = 0.01, radius = 0.1, edge = 0.01;
    for (double gap_voxels : {0.3, 0.6, 1.5}) {
        const double gap = gap_voxels * voxel;
        const Eigen::Vector3d c0(-radius - 0.5 * gap, 0.0023, -0.0017);
        const Eigen::Vector3d c1(radius + 0.5 * gap, 0.0023, -0.0017);
        const tracker::SurfaceMesh mesh = two_spheres(c0, c1, radius, edge);
        VdbOutputOptions options;
        options.voxel_size = voxel;
        const auto grids = written_grids(mesh, options, "gap");
        const auto surface = float_grid(grids, "surface");
        const auto density = float_grid(grids, "density");
        ASSERT_TRUE(surface && density);
        const auto acc = surface->getConstAccessor();
        const auto dacc = density->getConstAccessor();
        // The chord error of the inscribed mesh, ξ²/(8R), with a margin of 8.
        const double chord = edge * edge / radius;
        int in_gap = 0, wrong = 0;
        const int n = static_cast<int>(std::ceil((radius + gap) / voxel)) + 2;
        for (int i = -n; i <= n; ++i)
            for (int j = -n; j <= n; ++j)
                for (int k = -n; k <= n; ++k) {
                    const Eigen::Vector3d x = voxel * Eigen::Vector3d(i, j, k);
                    const double d0 = (x - c0).norm() - radius, d1 = (x - c1).norm() - radius;
                    const float phi = acc.getValue(openvdb::Coord(i, j, k));
                    const float fog = dacc.getValue(openvdb::Coord(i, j, k));
                    if (d0 > 0.0 && d1 > 0.0) {
                        const bool between = std::abs(x.x()) < 0.5 * gap + 1e-12;
                        in_gap += between ? 1 : 0;
                        if (!(phi > 0.0f) || !(fog < 0.5f))
                            ++wrong;
                    } else if (std::min(d0, d1) < -chord) {
                        if (!(phi < 0.0f) || !(fog > 0.5f))
                            ++wrong;
                    }
                }
        EXPECT_GT(in_gap, 0) << "gap " << gap_voxels << " voxels: no voxel centre in it";
        EXPECT_EQ(wrong, 0) << "gap " << gap_voxels << " voxels";
    }
}

TEST(VdbOutput, DensityIsAStepCentredOnTheSurface) {
    // A sphere: `density` is ½ at the mesh (sampled trilinearly at its vertices, within a
    // quarter voxel of the surface for a ramp of 1, 2 or 4 voxels), 1 deep inside, 0 outside,
    // and clamp(½ − φ/(ramp·h), 0, 1) of `surface` everywhere.
    const Eigen::Vector3d centre(0.31, 0.27, 0.42);
    const double radius = 0.2, voxel = 0.01;
    const tracker::SurfaceMesh mesh = sphere_mesh(centre, radius, 0.01);
    for (double ramp : {1.0, 2.0, 4.0}) {
        VdbOutputOptions options;
        options.voxel_size = voxel;
        options.density_ramp_voxels = ramp;
        const auto grids = written_grids(mesh, options, "density");
        const auto surface = float_grid(grids, "surface");
        const auto density = float_grid(grids, "density");
        ASSERT_TRUE(surface && density);
        EXPECT_EQ(density->getGridClass(), openvdb::GRID_FOG_VOLUME);
        const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sample(
            *density);
        double worst = 0.0;
        for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
            const tracker::Vec3& p = mesh.position(vi);
            const double fog = sample.wsSample(openvdb::Vec3d(p.x(), p.y(), p.z()));
            worst = std::max(worst, std::abs(fog - 0.5) * ramp);  // voxels off the surface
        }
        EXPECT_LT(worst, 0.25) << "ramp " << ramp;
        const auto dacc = density->getConstAccessor();
        for (auto it = surface->cbeginValueOn(); it; ++it) {
            const double expected = std::clamp(0.5 - *it / (ramp * voxel), 0.0, 1.0);
            ASSERT_NEAR(dacc.getValue(it.getCoord()), expected, 1e-6) << it.getCoord();
        }
        const openvdb::Coord middle = surface->transform().worldToIndexCellCentered(
            openvdb::Vec3d(centre.x(), centre.y(), centre.z()));
        EXPECT_FLOAT_EQ(dacc.getValue(middle), 1.0f);
        EXPECT_TRUE(dacc.isValueOn(middle));
        EXPECT_FLOAT_EQ(dacc.getValue(openvdb::Coord(200, 200, 200)), 0.0f);
        EXPECT_FALSE(dacc.isValueOn(openvdb::Coord(200, 200, 200)));
    }
}

/// A liquid block with a thin air slit cut into it, in voxels (× `voxel` m): the prism over the
/// (x, z) polygon [−3.5, 4.5]² minus the wedge from the mouth x = 4.5, z = 0.5 ± 0.3 to the tip
/// (0.5, 0.5), for y in [−3.5, 3.5] in layers one voxel apart. The slit's two sheets meet at the
/// tip at 8.6° (a fold of 171°), and the tip vertex at y = 0.5 sits at the centre of a voxel cube
/// whose eight centres are all in the liquid, 0.46 to 0.71 voxel from the mesh.
tracker::SurfaceMesh folded_slit_block(double voxel, int& tip_vertex) {
    // Counter-clockwise in (x, z); the last point is the cap fans' centre (on the edge x = −3.5).
    const std::vector<std::array<double, 2>> polygon{{-3.5, -3.5}, {4.5, -3.5}, {4.5, 0.2},
                                                     {0.5, 0.5},   {4.5, 0.8},  {4.5, 4.5},
                                                     {-3.5, 4.5},  {-3.5, 0.5}};
    const int corners = static_cast<int>(polygon.size()), layers = 8;
    std::vector<tracker::Vec3> positions;
    for (int m = 0; m < layers; ++m)
        for (const auto& p : polygon)
            positions.emplace_back(voxel * p[0], voxel * (m - 3.5), voxel * p[1]);
    auto at = [&](int m, int c) { return m * corners + c; };
    tip_vertex = at(4, 3);  // y = 0.5
    std::vector<tracker::Triangle> triangles;
    const int centre = corners - 1;
    for (int c = 0; c + 1 < centre; ++c) {
        triangles.push_back({at(0, centre), at(0, c), at(0, c + 1)});  // y = −3.5, normal −y
        triangles.push_back({at(layers - 1, centre), at(layers - 1, c + 1), at(layers - 1, c)});
    }
    for (int m = 0; m + 1 < layers; ++m)
        for (int c = 0; c < corners; ++c) {
            const int d = (c + 1) % corners;
            triangles.push_back({at(m, c), at(m + 1, d), at(m, d)});
            triangles.push_back({at(m, c), at(m + 1, c), at(m + 1, d)});
        }
    return tracker::SurfaceMesh(positions, triangles);
}

TEST(VdbOutput, VertexPinningBringsAFoldedSlitTipToTheSurfaceKeepingSigns) {
    // At the tip of a slit folded more sharply than a voxel all eight voxel centres around the
    // vertex are in the liquid: exact distances interpolate to −0.58 voxel there (drop_merge's
    // frame 9 had the same at 0.58). Vertex pinning shrinks those magnitudes until every vertex
    // samples `surface` and `density` within a quarter voxel of the surface, without changing a
    // sign and only at voxels of the vertices' stencils.
    const double voxel = 0.01;
    int tip = -1;
    const tracker::SurfaceMesh mesh = folded_slit_block(voxel, tip);
    ASSERT_GT(tracker::enclosed_volume(mesh), 0.0);  // outward normals: the block is liquid
    VdbOutputOptions options;
    options.voxel_size = voxel;
    auto offsets = [&](const std::map<std::string, openvdb::GridBase::Ptr>& grids, int vi) {
        const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> phi(
            *float_grid(grids, "surface")),
            fog(*float_grid(grids, "density"));
        const tracker::Vec3& p = mesh.position(vi);
        const openvdb::Vec3d w(p.x(), p.y(), p.z());
        return std::array<double, 2>{phi.wsSample(w) / voxel,
                                     (0.5 - fog.wsSample(w)) * options.density_ramp_voxels};
    };
    options.pin_vertices = false;
    const std::string path = temp_vdb("slit");
    const VdbOutputInfo exact_info = write_surface_vdb(path, mesh, options);
    const auto exact = read_grids(path);
    const std::array<double, 2> tip_exact = offsets(exact, tip);
    EXPECT_LT(tip_exact[0], -0.5);  // the fold: every value around the tip is negative
    EXPECT_LT(tip_exact[1], -0.5);
    EXPECT_EQ(exact_info.vertex_offset_after_voxels, exact_info.vertex_offset_before_voxels);
    EXPECT_EQ(exact_info.voxels_pinned, 0);

    options.pin_vertices = true;
    const VdbOutputInfo info = write_surface_vdb(path, mesh, options);
    const auto pinned = read_grids(path);
    std::filesystem::remove(path);
    std::printf("[ measured ] folded slit: tip sampled at %.3f voxel exact, %.3f pinned; worst "
                "vertex %.3f -> %.3f voxel; %lld vertices, %lld voxels pinned\n",
                tip_exact[0], offsets(pinned, tip)[0], info.vertex_offset_before_voxels,
                info.vertex_offset_after_voxels, info.vertices_pinned, info.voxels_pinned);
    EXPECT_NEAR(info.vertex_offset_before_voxels, std::abs(exact_info.vertex_offset_before_voxels),
                1e-9);
    EXPECT_LE(info.vertex_offset_after_voxels, 0.25);
    EXPECT_GT(info.vertices_pinned, 0);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        const std::array<double, 2> o = offsets(pinned, vi);
        EXPECT_LE(std::abs(o[0]), 0.25) << "vertex " << vi << ": surface";
        EXPECT_LE(std::abs(o[1]), 0.25) << "vertex " << vi << ": density";
    }
    // Signs kept, magnitudes only shrunk, and only within a voxel (per axis) of a vertex.
    const auto before = float_grid(exact, "surface"), after = float_grid(pinned, "surface");
    const auto after_acc = after->getConstAccessor();
    int changed = 0;
    for (auto it = before->cbeginValueOn(); it; ++it) {
        const float a = after_acc.getValue(it.getCoord()), b = *it;
        ASSERT_TRUE(after_acc.isValueOn(it.getCoord()));
        ASSERT_EQ(a < 0.0f, b < 0.0f) << it.getCoord();
        ASSERT_LE(std::abs(a), std::abs(b)) << it.getCoord();
        if (a == b)
            continue;
        ++changed;
        const openvdb::Vec3d x = before->indexToWorld(it.getCoord());
        bool near_vertex = false;
        for (int vi = 0; vi < mesh.num_vertices() && !near_vertex; ++vi) {
            const tracker::Vec3& p = mesh.position(vi);
            near_vertex = std::abs(x.x() - p.x()) < voxel && std::abs(x.y() - p.y()) < voxel &&
                          std::abs(x.z() - p.z()) < voxel;
        }
        EXPECT_TRUE(near_vertex) << it.getCoord();
    }
    EXPECT_EQ(changed, info.voxels_pinned);
    EXPECT_EQ(after->activeVoxelCount(), before->activeVoxelCount());
}

TEST(VdbOutput, BubbleIsNegativeInsideAndLengthsAreScaled) {
    // A bubble (gas inside, labels {0, 1}) written with inside_region 0 (the region the surface
    // encloses) and lengths in millimetres: negative inside, density 1 inside, voxel size and
    // distances × 1000.
    const Eigen::Vector3d centre(0.0021, 0.0017, 0.0033);
    const double radius = 0.001, voxel = 1e-4;
    tracker::SurfaceMesh mesh = sphere_mesh(centre, radius, 1e-4);
    for (int ti = 0; ti < mesh.num_triangles(); ++ti)
        mesh.set_labels(ti, tracker::LabelPair{0, 1});
    VdbOutputOptions options;
    options.voxel_size = voxel;
    options.inside_region = 0;
    options.length_scale = 1000.0;
    const auto grids = written_grids(mesh, options, "bubble");
    const auto surface = float_grid(grids, "surface");
    const auto density = float_grid(grids, "density");
    ASSERT_TRUE(surface && density);
    EXPECT_NEAR(surface->voxelSize()[0], 0.1, 1e-12);
    const openvdb::Vec3d centre_mm(1000 * centre.x(), 1000 * centre.y(), 1000 * centre.z());
    const openvdb::Coord middle = surface->transform().worldToIndexCellCentered(centre_mm);
    EXPECT_LT(surface->getConstAccessor().getValue(middle), 0.0f);
    EXPECT_FLOAT_EQ(density->getConstAccessor().getValue(middle), 1.0f);
    double worst = 0.0;
    for (auto it = surface->cbeginValueOn(); it; ++it) {
        const openvdb::Vec3d w = surface->indexToWorld(it.getCoord());
        const double exact = (w - centre_mm).length() - 1000 * radius;  // mm
        if (std::abs(exact) > 0.05) {
            EXPECT_EQ(*it < 0.0f, exact < 0.0) << w;
        }
        worst = std::max(worst, std::abs(*it - exact));
    }
    EXPECT_LT(worst, 0.05);  // half a voxel, in mm
}

TEST(VdbOutput, FluidFieldsSitOnCellCentresInOutputUnits) {
    // `vel` is the face velocities averaged to the cell centres (× length_scale), `pressure` the
    // solver's array; voxel (i, j, k) of both is centred on fluid cell (i, j, k).
    fluid::MacGrid grid(4, 3, 2, 0.5e-3, Eigen::Vector3d(1e-3, -2e-3, 0.5e-3));
    for (int axis = 0; axis < 3; ++axis) {
        fluid::Array3<double>& u = grid.velocity(axis);
        for (int k = 0; k < u.nk(); ++k)
            for (int j = 0; j < u.nj(); ++j)
                for (int i = 0; i < u.ni(); ++i)
                    u(i, j, k) = 0.01 * (axis + 1) * (i + 2 * j + 3 * k);
    }
    fluid::Array3<double> pressure(4, 3, 2, 0.0);
    for (size_t n = 0; n < pressure.size(); ++n)
        pressure[n] = 100.0 + static_cast<double>(n);
    const tracker::SurfaceMesh mesh = sphere_mesh(Eigen::Vector3d(2e-3, -1.2e-3, 1e-3), 4e-4, 1e-4);
    VdbOutputOptions options;
    options.voxel_size = 1e-4;
    options.length_scale = 1000.0;
    const std::string path = temp_vdb("fluid_fields");
    const VdbOutputInfo info = write_surface_vdb(path, mesh, options, {&grid, &pressure});
    EXPECT_TRUE(info.velocity_written);
    EXPECT_TRUE(info.pressure_written);
    const auto grids = read_grids(path);
    const auto vel = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grids.at("vel"));
    const auto p = float_grid(grids, "pressure");
    ASSERT_TRUE(vel && p);
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 4; ++i) {
                const openvdb::Coord c(i, j, k);
                const Eigen::Vector3d x = 1000.0 * grid.cell_centre(i, j, k);
                const openvdb::Vec3d w = vel->indexToWorld(c);
                EXPECT_NEAR((Eigen::Vector3d(w.x(), w.y(), w.z()) - x).norm(), 0.0, 1e-9);
                const openvdb::Vec3s v = vel->getConstAccessor().getValue(c);
                EXPECT_NEAR(v.x(), 500.0 * (grid.u()(i, j, k) + grid.u()(i + 1, j, k)), 1e-4);
                EXPECT_NEAR(v.y(), 500.0 * (grid.v()(i, j, k) + grid.v()(i, j + 1, k)), 1e-4);
                EXPECT_NEAR(v.z(), 500.0 * (grid.w()(i, j, k) + grid.w()(i, j, k + 1)), 1e-4);
                EXPECT_FLOAT_EQ(p->getConstAccessor().getValue(c),
                                static_cast<float>(pressure(i, j, k)));
                EXPECT_EQ(p->indexToWorld(c), w);
            }
    // Each can be turned off.
    options.velocity = false;
    options.pressure = false;
    write_surface_vdb(path, mesh, options, {&grid, &pressure});
    const auto without = read_grids(path);
    EXPECT_EQ(without.count("vel"), 0u);
    EXPECT_EQ(without.count("pressure"), 0u);
    EXPECT_EQ(without.count("surface"), 1u);
    std::filesystem::remove(path);
}

/// A periodic scene's fog is cut at the box (VdbOutputOptions::density_cut): a sphere across the
/// x faces of a box periodic along x shows at both ends, cut there, and nowhere beyond; the
/// surface grid keeps its band beyond the faces. The mesh is given unrolled, as the frame
/// output gives it.
TEST(VdbOutput, PeriodicDensityIsCutAtTheBox) {
    tracker::ImplicitMeshOptions mesh_options;
    mesh_options.edge_length = 0.02;
    mesh_options.periods.length.x() = 1.0;
    // Centred on the face x = 0, with its image at x = 1 (the shape must be periodic): half of
    // it on each side of the box.
    std::vector<tracker::ShapePtr> spheres;
    spheres.push_back(tracker::make_sphere(Eigen::Vector3d(0.0, 0.5, 0.5), 0.2));
    spheres.push_back(tracker::make_sphere(Eigen::Vector3d(1.0, 0.5, 0.5), 0.2));
    const tracker::SurfaceMesh periodic =
        tracker::mesh_implicit_shape(*tracker::make_union(std::move(spheres)), mesh_options);
    ASSERT_TRUE(periodic.periodic());
    const double voxel = 0.02;
    const tracker::SurfaceMesh unrolled = unroll_periodic_mesh(periodic, 5 * voxel).mesh;
    VdbOutputOptions options;
    options.voxel_size = voxel;
    options.density_cut = periodic.periods();
    auto grids = written_grids(unrolled, options, "periodic_cut");
    auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(grids.at("density"));
    auto surface = openvdb::gridPtrCast<openvdb::FloatGrid>(grids.at("surface"));
    const openvdb::CoordBBox fog = density->evalActiveVoxelBoundingBox();
    const openvdb::CoordBBox band = surface->evalActiveVoxelBoundingBox();
    EXPECT_EQ(fog.min().x(), 0);    // voxel centres from x = 0 …
    EXPECT_EQ(fog.max().x(), 49);   // … to x = 0.98
    EXPECT_LT(band.min().x(), -5);  // the band reaches past both faces
    EXPECT_GT(band.max().x(), 55);
    // Both halves are there: full fog just inside each face, on the sphere's axis.
    auto acc = density->getConstAccessor();
    EXPECT_FLOAT_EQ(acc.getValue(openvdb::Coord(0, 25, 25)), 1.0f);
    EXPECT_FLOAT_EQ(acc.getValue(openvdb::Coord(49, 25, 25)), 1.0f);
    EXPECT_FLOAT_EQ(acc.getValue(openvdb::Coord(25, 25, 25)), 0.0f);
}

}  // namespace
}  // namespace meniscus::coupling
