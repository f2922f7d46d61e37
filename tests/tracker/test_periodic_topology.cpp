/// Periodic meshes (issue 39), measures and topology changes: volume, area, edge and angle
/// statistics, normals, curvature and validation read by the minimum image, exact on the
/// closed-form test meshes whichever image (translation) they sit at; merging across the seam and
/// separation on a periodic mesh.

#include "periodic_meshes.h"
#include "remesh_test_meshes.h"

#include "tracker/flows/mean_curvature.h"
#include "tracker/mesh_distance.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

namespace meniscus::tracker {
namespace {

/// The periodic tube's exact volume: each band between two rings is an antiprism band (rings
/// turned by half a step), a prismatoid of height h = length / along whose mid-section is the
/// regular 2n-gon through the lateral edges' midpoints (circumradius r cos(π/2n)); Simpson's
/// rule, exact for it, gives h n r² sin(π/n) (1 + 2 cos(π/n)) / 3 per band.
double tube_volume(double r, double length, int around) {
    const double n = around, c = std::cos(M_PI / n);
    return length * n * r * r * std::sin(M_PI / n) * (1.0 + 2.0 * c) / 3.0;
}

/// The periodic tube's exact area: 2 · around · along congruent triangles, each with a ring
/// chord 2r sin(π/n) as base and height √(h² + r²(1 − cos(π/n))²) to the other ring's vertex.
double tube_area(double r, double length, int around, int along) {
    const double n = around, c = std::cos(M_PI / n), h = length / along;
    return 2.0 * n * along * r * std::sin(M_PI / n) *
           std::sqrt(h * h + r * r * (1.0 - c) * (1.0 - c));
}

/// Moves every live vertex by `shift` and wraps it back into the box.
void translate(SurfaceMesh& mesh, const Vec3& shift) {
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            mesh.set_position(vi, mesh.position(vi) + shift);
    mesh.wrap_positions();
}

double relative(double value, double reference) {
    return std::abs(value - reference) / std::abs(reference);
}

// ---- measures --------------------------------------------------------------------------------

TEST(PeriodicMeasures, TubeVolumeAndAreaAreExactOnEveryAxisAndEveryTranslation) {
    const double r = 0.2, length = 1.0;
    const int around = 16, along = 20;
    const double volume = tube_volume(r, length, around);
    const double area = tube_area(r, length, around, along);
    for (int axis = 0; axis < 3; ++axis) {
        SurfaceMesh mesh =
            testing::periodic_tube(r, Vec3(0.5, 0.5, 0.5), axis, length, around, along);
        EXPECT_LT(relative(enclosed_volume(mesh), volume), 1e-12) << "axis " << axis;
        EXPECT_LT(relative(surface_area(mesh), area), 1e-12) << "axis " << axis;
        // The seam rings' triangles read with raw positions would span the box: the same sum
        // without periods is far off (this is what the test would catch).
        SurfaceMesh raw = mesh;
        raw.set_periods(MeshPeriods{});
        EXPECT_GT(relative(surface_area(raw), area), 0.5);
        // Translated along the axis by non-lattice amounts (across the seam) and across it.
        for (const double s : {0.013, 0.37, 0.5, 0.9871}) {
            SurfaceMesh moved = mesh;
            Vec3 shift = Vec3::Constant(0.3 * s);
            shift[axis] = s * length;
            translate(moved, shift);
            EXPECT_LT(relative(enclosed_volume(moved), volume), 1e-12)
                << "axis " << axis << " shift " << s;
            EXPECT_LT(relative(surface_area(moved), area), 1e-12);
            const Components components = triangle_components(moved);
            ASSERT_EQ(components.count, 1);
            EXPECT_LT(relative(component_volumes(moved, components)[0], volume), 1e-12);
            EXPECT_EQ(euler_characteristic(moved), 0);  // a torus in the periodic box
        }
    }
}

TEST(PeriodicMeasures, VolumeOfUnwrappedPositionsIsTheSame) {
    // enclosed_volume(mesh, positions) with each vertex at an arbitrary image (a motion's x_t1
    // is not wrapped) reads each triangle at its first corner's images.
    SurfaceMesh mesh = testing::periodic_sheet(1.0, 0.8, 12, 10, [](double x, double y) {
        return 0.3 + 0.05 * std::sin(2.0 * M_PI * x) * std::cos(2.0 * M_PI * y / 0.8);
    });
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> image(-2, 2);
    std::vector<Vec3> x = mesh.positions();
    for (Vec3& p : x)
        p += Vec3(image(rng) * 1.0, image(rng) * 0.8, 0.0);
    EXPECT_NEAR(enclosed_volume(mesh, x), enclosed_volume(mesh), 1e-14);
    // A displacement changes it as it would the wrapped mesh.
    for (Vec3& p : x)
        p.z() += 0.01;
    EXPECT_NEAR(enclosed_volume(mesh, x), enclosed_volume(mesh) + 0.01 * 0.8, 1e-14);
}

TEST(PeriodicMeasures, SheetVolumeIsTheIntegralOfItsHeight) {
    // The flux of z e_z through the sheet: the integral of its piecewise linear height over the
    // box, which on this grid (each vertex in six triangles) is dx·dy·Σ h at the vertices, and
    // lx·ly·mean height for a trigonometric height sampled over whole periods.
    const double lx = 1.2, ly = 0.9, z0 = 0.35;
    const int nx = 15, ny = 12;
    const auto height = [&](double x, double y) {
        return z0 + 0.04 * std::sin(2.0 * M_PI * x / lx) + 0.03 * std::cos(4.0 * M_PI * y / ly) +
               0.02 * x * (lx - x);
    };
    SurfaceMesh mesh = testing::periodic_sheet(lx, ly, nx, ny, height);
    double sum = 0.0;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i)
            sum += height(lx * i / nx, ly * j / ny);
    const double expected = sum * (lx / nx) * (ly / ny);
    EXPECT_LT(relative(enclosed_volume(mesh), expected), 1e-13);
    SurfaceMesh flat = testing::periodic_sheet(lx, ly, nx, ny, [&](double, double) { return z0; });
    EXPECT_LT(relative(enclosed_volume(flat), lx * ly * z0), 1e-14);
    EXPECT_LT(relative(surface_area(flat), lx * ly), 1e-14);
    EXPECT_EQ(euler_characteristic(flat), 0);
    // Shifted in x and y across the seam: the same volume.
    translate(mesh, Vec3(0.77, 0.41, 0.0));
    EXPECT_LT(relative(enclosed_volume(mesh), expected), 1e-13);
    // The flat sheet's normals all point up, the seam's vertices included.
    for (const Vec3& n : area_weighted_vertex_normals(flat))
        EXPECT_LT((n - Vec3::UnitZ()).norm(), 1e-14);
}

TEST(PeriodicMeasures, DropAcrossTheSeamHasItsNonPeriodicVolumeAndArea) {
    // A closed sphere straddling the seam (x ∈ [−0.25, 0.25], box [0, 1) along x and z).
    const SurfaceMesh sphere = testing::make_test_sphere();
    SurfaceMesh periodic = sphere;
    MeshPeriods periods;
    periods.length = Vec3(1.0, 0.0, 1.0);
    periodic.set_periods(periods);
    int wrapped = 0;
    for (int vi = 0; vi < sphere.num_vertices(); ++vi)
        wrapped += periodic.position(vi) != sphere.position(vi) ? 1 : 0;
    EXPECT_GT(wrapped, sphere.num_vertices() / 2);  // most vertices moved by a period
    EXPECT_LT(relative(enclosed_volume(periodic), enclosed_volume(sphere)), 1e-12);
    EXPECT_LT(relative(surface_area(periodic), surface_area(sphere)), 1e-12);
    const EdgeLengthStats a = edge_length_stats(periodic), b = edge_length_stats(sphere);
    EXPECT_EQ(a.count, b.count);
    EXPECT_NEAR(a.max, b.max, 1e-12);
    EXPECT_NEAR(a.min, b.min, 1e-12);
    EXPECT_NEAR(a.mean, b.mean, 1e-12);
    const AngleStats p = angle_stats(periodic), q = angle_stats(sphere);
    EXPECT_NEAR(p.min_degrees, q.min_degrees, 1e-9);
    EXPECT_NEAR(p.max_degrees, q.max_degrees, 1e-9);
    const std::vector<Vec3> n = area_weighted_vertex_normals(periodic);
    const std::vector<Vec3> m = area_weighted_vertex_normals(sphere);
    for (size_t i = 0; i < n.size(); ++i)
        EXPECT_LT((n[i] - m[i]).norm(), 1e-12) << "vertex " << i;
    EXPECT_EQ(euler_characteristic(periodic), 2);
}

TEST(PeriodicMeasures, VolumeRefusesAMeshWrappingAroundEveryAxis) {
    SurfaceMesh mesh = testing::make_test_sphere();
    MeshPeriods periods;
    periods.length = Vec3(1.0, 1.0, 1.0);
    mesh.set_periods(periods);
    EXPECT_THROW(enclosed_volume(mesh), std::invalid_argument);
    EXPECT_THROW(component_volumes(mesh, triangle_components(mesh)), std::invalid_argument);
    EXPECT_GT(surface_area(mesh), 0.0);  // the other measures still work
}

TEST(PeriodicMeasures, EdgeAndAngleStatisticsReadTheSeamByMinimumImage) {
    const double r = 0.2, length = 1.0;
    const int around = 16, along = 20;
    SurfaceMesh mesh = testing::periodic_tube(r, Vec3(0.5, 0.5, 0.0), 2, length, around, along);
    translate(mesh, Vec3(0.0, 0.0, 0.021));  // no ring on the seam
    // Two kinds of edge: ring chords 2r sin(π/n) and lateral edges √(h² + (2r sin(π/4n))²).
    const double chord = 2.0 * r * std::sin(M_PI / around), h = length / along;
    const double lateral = std::hypot(h, 2.0 * r * std::sin(M_PI / (2.0 * around)));
    const EdgeLengthStats s = edge_length_stats(mesh);
    EXPECT_EQ(s.count, 3 * around * along);
    EXPECT_NEAR(s.min, std::min(chord, lateral), 1e-12);
    EXPECT_NEAR(s.max, std::max(chord, lateral), 1e-12);
    EXPECT_NEAR(s.mean, (chord + 2.0 * lateral) / 3.0, 1e-12);
    // Every triangle is congruent: isosceles with base `chord` and legs `lateral`.
    const double apex = 2.0 * std::asin(0.5 * chord / lateral) * 180.0 / M_PI;
    const AngleStats a = angle_stats(mesh);
    EXPECT_NEAR(a.min_degrees, std::min(apex, 90.0 - 0.5 * apex), 1e-9);
    EXPECT_NEAR(a.max_degrees, std::max(apex, 90.0 - 0.5 * apex), 1e-9);
}

TEST(PeriodicMeasures, TubeNormalsPointRadiallyOutAtTheSeamRings) {
    SurfaceMesh mesh = testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 2, 1.0, 16, 20);
    const std::vector<Vec3> normals = area_weighted_vertex_normals(mesh);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        Vec3 radial = mesh.position(vi) - Vec3(0.5, 0.5, mesh.position(vi).z());
        EXPECT_LT((normals[static_cast<size_t>(vi)] - radial.normalized()).norm(), 1e-12)
            << "vertex " << vi;
    }
}

// ---- validation ------------------------------------------------------------------------------

TEST(PeriodicValidation, DegenerateAreaIsJudgedByMinimumImage) {
    // Three corners on a line that crosses the seam at x = 0 ≡ 1: collinear by the minimum
    // image, a fat triangle in raw coordinates.
    const std::vector<Vec3> x = {Vec3(0.99, 0.5, 0.0), Vec3(0.01, 0.52, 0.0), Vec3(0.0, 0.51, 0.0)};
    ValidationOptions options;
    options.allow_boundary = true;
    SurfaceMesh raw(x, {Triangle{0, 1, 2}});
    const auto degenerate = [&](const SurfaceMesh& m) {
        for (const MeshViolation& v : validate_mesh(m, options))
            if (v.kind == ViolationKind::DegenerateTriangle)
                return true;
        return false;
    };
    EXPECT_FALSE(degenerate(raw));
    SurfaceMesh periodic = raw;
    MeshPeriods periods;
    periods.length.x() = 1.0;
    periodic.set_periods(periods);
    EXPECT_TRUE(degenerate(periodic));
    // And a healthy seam triangle of the tube is not flagged.
    SurfaceMesh tube = testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 2, 1.0, 16, 20);
    EXPECT_TRUE(validate_mesh(tube).empty());
}

// ---- curvature -------------------------------------------------------------------------------

TEST(PeriodicCurvature, TubeCurvatureIsTheSameAtEveryVertexSeamRingsIncluded) {
    // Every vertex of the tube is equivalent (a screw motion maps any to any), so the discrete
    // curvature normal is the same radial vector everywhere; near 1/r for this fine a ring.
    const double r = 0.2;
    SurfaceMesh mesh = testing::periodic_tube(r, Vec3(0.5, 0.5, 0.0), 2, 1.0, 32, 40);
    translate(mesh, Vec3(0.0, 0.0, 0.6));
    const std::vector<Vec3> k = mean_curvature_normals(mesh);
    const std::vector<double> kappa = mean_curvatures(mesh);
    const std::vector<double> areas = mixed_voronoi_areas(mesh);
    double area_sum = 0.0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        const size_t i = static_cast<size_t>(vi);
        const Vec3 radial =
            (mesh.position(vi) - Vec3(0.5, 0.5, mesh.position(vi).z())).normalized();
        EXPECT_LT((k[i] - kappa[0] * radial).norm(), 1e-9 * kappa[0]) << "vertex " << vi;
        EXPECT_NEAR(kappa[i], kappa[0], 1e-9 * kappa[0]);
        EXPECT_NEAR(areas[i], areas[0], 1e-12);
        area_sum += areas[i];
    }
    EXPECT_LT(relative(kappa[0], 1.0 / r), 0.005) << "kappa " << kappa[0];
    EXPECT_LT(relative(area_sum, surface_area(mesh)), 1e-12);
    // The flow step moves every vertex inwards by the same amount.
    const std::vector<Vec3> d = mean_curvature_displacements(mesh, 1e-4);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        EXPECT_NEAR(d[static_cast<size_t>(vi)].norm(), 1e-4 * kappa[0], 1e-12);
    // Heun's predictor x − dt K is not wrapped: read by minimum image too.
    const std::vector<Vec3> heun =
        mean_curvature_displacements(mesh, 1e-4, MeanCurvatureIntegrator::heun);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        EXPECT_NEAR(heun[static_cast<size_t>(vi)].norm(), heun[0].norm(), 1e-12);
}

TEST(PeriodicCurvature, FlatSheetHasNoCurvature) {
    SurfaceMesh mesh =
        testing::periodic_sheet(1.0, 1.0, 10, 10, [](double, double) { return 0.4; });
    for (const Vec3& k : mean_curvature_normals(mesh))
        EXPECT_LT(k.norm(), 1e-10);
}

// ---- distance --------------------------------------------------------------------------------

TEST(PeriodicDistance, DistanceToATubeIsTakenToItsNearestImage) {
    const double r = 0.2;
    SurfaceMesh mesh = testing::periodic_tube(r, Vec3(0.5, 0.5, 0.5), 0, 1.0, 32, 40);
    const MeshDistance distance(mesh);
    // On the axis, from inside the box and from images of it: r·cos(π/n) to the facets at most.
    const double inscribed = r * std::cos(M_PI / 32);
    for (const double x : {0.0, 0.013, 0.5, 0.999, 1.7, -3.2}) {
        const double d = distance.distance(Vec3(x, 0.5, 0.5));
        EXPECT_GE(d, inscribed - 1e-12) << x;
        EXPECT_LE(d, r + 1e-12) << x;
    }
    // Outside, beside the seam.
    EXPECT_NEAR(distance.distance(Vec3(0.9999, 0.5, 0.5 + r + 0.1)), 0.1, 0.002);
}

}  // namespace
}  // namespace meniscus::tracker
