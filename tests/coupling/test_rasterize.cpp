// Mesh → grid level set: signs by region labels (drops, bubbles, pools, several at once),
// distances in the band, |∇φ| ≈ 1, and the timing/bookkeeping of the result.
#include "coupling/rasterize.h"

#include "tracker/distance.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace meniscus::coupling {
namespace {

using Eigen::Vector3d;
using tracker::LabelPair;
using tracker::SurfaceMesh;
using tracker::Triangle;

constexpr LabelPair DROP_LABELS{1, 0};    // liquid behind the triangles (outward normals)
constexpr LabelPair BUBBLE_LABELS{0, 1};  // gas behind the triangles (outward normals)

SurfaceMesh sphere_mesh(const Vector3d& centre, double radius, double edge_length) {
    tracker::ImplicitMeshOptions options;
    options.edge_length = edge_length;
    return tracker::mesh_implicit_shape(*tracker::make_sphere(centre, radius), options);
}

/// Axis-aligned box [lo, hi] with outward normals, 12 triangles.
SurfaceMesh box_mesh(const Vector3d& lo, const Vector3d& hi) {
    std::vector<Vector3d> p;
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i)
                p.emplace_back(i ? hi.x() : lo.x(), j ? hi.y() : lo.y(), k ? hi.z() : lo.z());
    // Vertex index i + 2j + 4k. Each quad counter-clockwise seen from outside.
    const std::vector<Triangle> t = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},
                                     {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                     {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    return SurfaceMesh(p, t);
}

/// One mesh holding every part, each part's triangles labelled (and optionally reversed).
struct Part {
    const SurfaceMesh* mesh;
    LabelPair labels;
    bool reverse = false;
};

SurfaceMesh combine(const std::vector<Part>& parts) {
    std::vector<Vector3d> positions;
    std::vector<Triangle> triangles;
    std::vector<LabelPair> labels;
    for (const Part& part : parts) {
        const int base = static_cast<int>(positions.size());
        for (int vi = 0; vi < part.mesh->num_vertices(); ++vi)
            positions.push_back(part.mesh->position(vi));
        for (int ti = 0; ti < part.mesh->num_triangles(); ++ti) {
            if (!part.mesh->triangle_alive(ti))
                continue;
            Triangle t = part.mesh->triangle(ti);
            for (int& v : t)
                v += base;
            if (part.reverse)
                std::swap(t[1], t[2]);
            triangles.push_back(t);
            labels.push_back(part.labels);
        }
    }
    return SurfaceMesh(positions, triangles, labels);
}

/// Unit box of n³ cells with a grid origin that is not zero (checks the VDB placement).
fluid::MacGrid unit_grid(int n) {
    return fluid::MacGrid(n, n, n, 1.0 / n, Vector3d(-0.5, -0.5, -0.5));
}

TEST(Rasterize, SphereHasSignedDistanceInTheBandAndRightSignsEverywhere) {
    const int n = 32;
    const fluid::MacGrid grid = unit_grid(n);
    const double dx = grid.dx();
    const Vector3d centre(0.013, -0.021, 0.007);
    const double radius = 0.3;
    const SurfaceMesh mesh = sphere_mesh(centre, radius, 0.5 * dx);
    const RasterizeResult raster = rasterize_mesh(mesh, grid);

    double max_band_error = 0.0;
    int wrong_signs = 0;
    long long band = 0;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double exact = (grid.cell_centre(i, j, k) - centre).norm() - radius;
                const double phi = raster.phi(i, j, k);
                // The mesh is a polyhedron inscribed in the sphere: allow its chord error.
                if (std::abs(exact) > 0.05 * dx && (phi < 0.0) != (exact < 0.0))
                    ++wrong_signs;
                const int ti = raster.closest_triangle(i, j, k);
                if (ti != tracker::INVALID_INDEX) {
                    ++band;
                    EXPECT_TRUE(mesh.triangle_alive(ti));
                    max_band_error = std::max(max_band_error, std::abs(phi - exact));
                } else {
                    EXPECT_EQ(std::abs(phi), raster.band_value);
                    EXPECT_GE(std::abs(exact), (3.0 - 1.0) * dx);  // outside means not close
                }
            }
    EXPECT_EQ(wrong_signs, 0);
    EXPECT_EQ(band, raster.band_cells);
    EXPECT_GT(band, 0);
    EXPECT_LT(max_band_error, 0.02 * dx);
    EXPECT_LT(raster.phi(n / 2, n / 2, n / 2), 0.0);
    EXPECT_GT(raster.phi(0, 0, 0), 0.0);
    EXPECT_GT(raster.phi(n - 1, n - 1, n - 1), 0.0);

    // |∇φ| by central differences where the whole stencil is in the band, near the surface.
    double max_gradient_error = 0.0;
    for (int k = 1; k < n - 1; ++k)
        for (int j = 1; j < n - 1; ++j)
            for (int i = 1; i < n - 1; ++i) {
                if (std::abs(raster.phi(i, j, k)) > 1.5 * dx)
                    continue;
                bool in_band = true;
                for (int d = -1; d <= 1; d += 2)
                    in_band = in_band &&
                              raster.closest_triangle(i + d, j, k) != tracker::INVALID_INDEX &&
                              raster.closest_triangle(i, j + d, k) != tracker::INVALID_INDEX &&
                              raster.closest_triangle(i, j, k + d) != tracker::INVALID_INDEX;
                if (!in_band)
                    continue;
                const Vector3d gradient(raster.phi(i + 1, j, k) - raster.phi(i - 1, j, k),
                                        raster.phi(i, j + 1, k) - raster.phi(i, j - 1, k),
                                        raster.phi(i, j, k + 1) - raster.phi(i, j, k - 1));
                max_gradient_error =
                    std::max(max_gradient_error, std::abs(gradient.norm() / (2.0 * dx) - 1.0));
            }
    std::printf(
        "sphere R/dx = %.1f: %lld band cells, max |phi - exact| = %.4f dx, "
        "max ||grad phi| - 1| = %.4f, rasterize %.4f s (meshToVolume %.4f s)\n",
        radius / dx, band, max_band_error / dx, max_gradient_error, raster.timings.total,
        raster.timings.mesh_to_volume);
    EXPECT_LT(max_gradient_error, 0.03);
}

TEST(Rasterize, PoolFillingTheDomainWithAGasBubbleInside) {
    const int n = 32;
    const fluid::MacGrid grid = unit_grid(n);
    const double dx = grid.dx();
    const Vector3d centre(0.1, 0.05, -0.08);
    const double radius = 0.2;
    const SurfaceMesh bubble = sphere_mesh(centre, radius, 0.5 * dx);
    // The pool's walls on the domain walls, then one cell outside them; cells near its edges and
    // corners test the edge and vertex pseudo-normals.
    for (double wall_offset : {0.0, dx}) {
        const SurfaceMesh pool =
            box_mesh(Vector3d::Constant(-0.5 - wall_offset), Vector3d::Constant(0.5 + wall_offset));
        // The bubble both ways: outward normals with labels {0, 1}, inward normals with {1, 0}.
        const SurfaceMesh labelled = combine({{&pool, DROP_LABELS}, {&bubble, BUBBLE_LABELS}});
        const SurfaceMesh reversed =
            combine({{&pool, DROP_LABELS}, {&bubble, DROP_LABELS, /*reverse=*/true}});
        for (const SurfaceMesh* mesh : {&labelled, &reversed}) {
            const RasterizeResult raster = rasterize_mesh(*mesh, grid);
            int wrong_signs = 0;
            for (int k = 0; k < n; ++k)
                for (int j = 0; j < n; ++j)
                    for (int i = 0; i < n; ++i) {
                        const double in_bubble =
                            radius - (grid.cell_centre(i, j, k) - centre).norm();
                        if (std::abs(in_bubble) > 0.05 * dx &&
                            (raster.phi(i, j, k) < 0.0) != (in_bubble < 0.0))
                            ++wrong_signs;
                    }
            EXPECT_EQ(wrong_signs, 0) << "wall offset " << wall_offset;
            // Deep liquid between bubble and walls, deep gas in the bubble's centre.
            const Vector3d g = grid.to_grid(centre);
            EXPECT_GT(raster.phi(static_cast<int>(g.x()), static_cast<int>(g.y()),
                                 static_cast<int>(g.z())),
                      0.0);
            EXPECT_LT(raster.phi(n - 8, n - 8, n - 8), -2.0 * dx);
            EXPECT_EQ(raster.closest_triangle(n - 8, n - 8, n - 8), tracker::INVALID_INDEX);
            // On the pool's walls the corner cell is liquid at distance ½dx from three faces.
            if (wall_offset == 0.0) {
                EXPECT_NEAR(raster.phi(0, 0, 0), -0.5 * dx, 1e-12);
            }
        }
    }
}

TEST(Rasterize, DropCutByTheDomainWalls) {
    const int n = 24;
    const fluid::MacGrid grid = unit_grid(n);
    const double dx = grid.dx();
    const Vector3d centre(0.45, -0.47, 0.02);  // mostly outside the box through two walls
    const double radius = 0.3;
    const SurfaceMesh drop = sphere_mesh(centre, radius, 0.5 * dx);
    const RasterizeResult raster = rasterize_mesh(drop, grid);
    int wrong_signs = 0;
    long long liquid = 0;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double exact = (grid.cell_centre(i, j, k) - centre).norm() - radius;
                liquid += raster.phi(i, j, k) < 0.0;
                if (std::abs(exact) > 0.05 * dx && (raster.phi(i, j, k) < 0.0) != (exact < 0.0))
                    ++wrong_signs;
            }
    EXPECT_EQ(wrong_signs, 0);
    EXPECT_GT(liquid, 0);
}

TEST(Rasterize, DropInsideABubbleInsideAPool) {
    const int n = 32;
    const fluid::MacGrid grid = unit_grid(n);
    const double dx = grid.dx();
    const Vector3d centre(0.02, -0.03, 0.01);
    const double bubble_radius = 0.35;
    const double drop_radius = 0.15;
    const SurfaceMesh pool = box_mesh(Vector3d::Constant(-0.5 - dx), Vector3d::Constant(0.5 + dx));
    const SurfaceMesh bubble = sphere_mesh(centre, bubble_radius, 0.5 * dx);
    const SurfaceMesh drop = sphere_mesh(centre, drop_radius, 0.5 * dx);
    const SurfaceMesh mesh =
        combine({{&pool, DROP_LABELS}, {&bubble, BUBBLE_LABELS}, {&drop, DROP_LABELS}});
    const RasterizeResult raster = rasterize_mesh(mesh, grid);
    int wrong_signs = 0;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double r = (grid.cell_centre(i, j, k) - centre).norm();
                // Liquid in the drop and outside the bubble: φ = min(r − r_d, r_b − r).
                const double exact = std::min(r - drop_radius, bubble_radius - r);
                if (std::abs(exact) > 0.05 * dx && (raster.phi(i, j, k) < 0.0) != (exact < 0.0))
                    ++wrong_signs;
            }
    EXPECT_EQ(wrong_signs, 0);
}

TEST(Rasterize, PoolWhollyOutsideTheBandIsLiquidAndEmptyMeshIsGas) {
    const int n = 16;
    const fluid::MacGrid grid = unit_grid(n);
    const SurfaceMesh pool = box_mesh(Vector3d::Constant(-2.0), Vector3d::Constant(2.0));
    const RasterizeResult liquid = rasterize_mesh(pool, grid);
    EXPECT_EQ(liquid.band_cells, 0);
    EXPECT_TRUE(std::all_of(liquid.phi.storage().begin(), liquid.phi.storage().end(),
                            [](double phi) { return phi < 0.0; }));
    // The same box labelled {0, 1}: gas behind its triangles, so every cell is gas.
    const SurfaceMesh cavity = combine({{&pool, BUBBLE_LABELS}});
    const RasterizeResult gas = rasterize_mesh(cavity, grid);
    EXPECT_TRUE(std::all_of(gas.phi.storage().begin(), gas.phi.storage().end(),
                            [](double phi) { return phi > 0.0; }));
    const RasterizeResult empty = rasterize_mesh(SurfaceMesh(), grid);
    EXPECT_TRUE(std::all_of(empty.phi.storage().begin(), empty.phi.storage().end(),
                            [](double phi) { return phi > 0.0; }));
}

TEST(Rasterize, TwoSeparateDropsAtOnce) {
    const int n = 32;
    const fluid::MacGrid grid = unit_grid(n);
    const double dx = grid.dx();
    const Vector3d a(-0.2, 0.0, 0.01);
    const Vector3d b(0.22, 0.03, -0.02);
    const double ra = 0.17;
    const double rb = 0.12;
    const SurfaceMesh drop_a = sphere_mesh(a, ra, 0.5 * dx);
    const SurfaceMesh drop_b = sphere_mesh(b, rb, 0.5 * dx);
    const SurfaceMesh mesh = combine({{&drop_a, DROP_LABELS}, {&drop_b, DROP_LABELS}});
    const RasterizeResult raster = rasterize_mesh(mesh, grid);
    int wrong_signs = 0;
    double max_band_error = 0.0;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const Vector3d x = grid.cell_centre(i, j, k);
                const double exact = std::min((x - a).norm() - ra, (x - b).norm() - rb);
                if (std::abs(exact) > 0.05 * dx && (raster.phi(i, j, k) < 0.0) != (exact < 0.0))
                    ++wrong_signs;
                if (raster.closest_triangle(i, j, k) != tracker::INVALID_INDEX)
                    max_band_error =
                        std::max(max_band_error, std::abs(raster.phi(i, j, k) - exact));
            }
    EXPECT_EQ(wrong_signs, 0);
    EXPECT_LT(max_band_error, 0.03 * dx);
}

TEST(Rasterize, DeadTrianglesAreSkippedAndOptionsValidated) {
    const int n = 16;
    const fluid::MacGrid grid = unit_grid(n);
    SurfaceMesh mesh = sphere_mesh(Vector3d::Zero(), 0.3, 1.0 / n);
    const RasterizeResult before = rasterize_mesh(mesh, grid);
    // A far-away extra tetrahedron, then deleted: the raster must not change.
    const int v0 = mesh.add_vertex(Vector3d(0.4, 0.4, 0.4));
    const int v1 = mesh.add_vertex(Vector3d(0.45, 0.4, 0.4));
    const int v2 = mesh.add_vertex(Vector3d(0.4, 0.45, 0.4));
    const int t = mesh.add_triangle({v0, v2, v1});
    mesh.remove_triangle(t);
    const RasterizeResult after = rasterize_mesh(mesh, grid);
    EXPECT_EQ(before.phi.storage(), after.phi.storage());
    EXPECT_EQ(before.closest_triangle.storage(), after.closest_triangle.storage());

    RasterizeOptions options;
    options.half_width_cells = 1.0;
    EXPECT_THROW(rasterize_mesh(mesh, grid, options), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::coupling

namespace meniscus::coupling {
namespace {

TEST(Rasterize, WalkToClosestTriangleMatchesBruteForceOnASphere) {
    const SurfaceMesh mesh = sphere_mesh(Vector3d::Zero(), 0.3, 0.05);
    int mismatches = 0;
    for (const Vector3d& x : {Vector3d(0.31, 0.02, -0.01), Vector3d(-0.05, 0.28, 0.1),
                              Vector3d(0.1, -0.1, -0.25), Vector3d(0.0, 0.0, 0.2)}) {
        int brute = tracker::INVALID_INDEX;
        double brute_distance = 1e300;
        for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
            const tracker::Triangle& t = mesh.triangle(ti);
            const double d = tracker::point_triangle_proximity(
                                 x, mesh.position(t[0]), mesh.position(t[1]), mesh.position(t[2]))
                                 .distance;
            if (d < brute_distance) {
                brute_distance = d;
                brute = ti;
            }
        }
        // Start a quarter of the sphere away (the triangle closest to the rotated point).
        const int start = walk_to_closest_triangle(mesh, 0, Vector3d(-x.y(), x.x(), x.z()));
        if (walk_to_closest_triangle(mesh, start, x) != brute)
            ++mismatches;
    }
    EXPECT_EQ(mismatches, 0);
    EXPECT_EQ(walk_to_closest_triangle(mesh, tracker::INVALID_INDEX, Vector3d::Zero()),
              tracker::INVALID_INDEX);
}

}  // namespace
}  // namespace meniscus::coupling
