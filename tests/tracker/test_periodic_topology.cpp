/// Periodic meshes (issue 39), measures and topology changes: volume, area, edge and angle
/// statistics, normals, curvature and validation read by the minimum image, exact on the
/// closed-form test meshes whichever image (translation) they sit at; merging across the seam and
/// separation on a periodic mesh.

#include "periodic_meshes.h"
#include "remesh_test_meshes.h"

#include "tracker/flows/mean_curvature.h"
#include "tracker/intersection.h"
#include "tracker/mesh_distance.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"
#include "tracker/remesh/improve.h"
#include "tracker/topology/change_topology.h"

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

std::string violations_text(const std::vector<MeshViolation>& v) {
    std::string s;
    for (const MeshViolation& m : v)
        s += m.message + "; ";
    return s;
}

/// Triangle tj's corners at the image nearest triangle ti's first corner (the first corner's
/// nearest image, the others nearest it: a coherent triangle even for a far pair).
std::array<Vec3, 3> corners_near(const SurfaceMesh& mesh, int tj, const Vec3& reference) {
    const Triangle& t = mesh.triangle(tj);
    const Vec3 q0 = mesh.position_near(t[0], reference);
    return {q0, mesh.position_near(t[1], q0), mesh.position_near(t[2], q0)};
}

/// Brute-force periodic intersection test (independent of the broad phase): every pair of live
/// triangles, the second at its image nearest the first, by the exact shared-vertex-aware test.
/// Returns the number of intersecting pairs.
int periodic_intersections(const SurfaceMesh& mesh) {
    int count = 0;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const std::array<Vec3, 3> p = mesh.triangle_positions(ti);
        Eigen::AlignedBox3d box(p[0]);
        box.extend(p[1]);
        box.extend(p[2]);
        for (int tj = ti + 1; tj < mesh.num_triangles(); ++tj) {
            if (!mesh.triangle_alive(tj))
                continue;
            const std::array<Vec3, 3> q = corners_near(mesh, tj, p[0]);
            Eigen::AlignedBox3d other(q[0]);
            other.extend(q[1]);
            other.extend(q[2]);
            if (box.intersects(other) &&
                triangles_intersect(p, mesh.triangle(ti), q, mesh.triangle(tj)))
                ++count;
        }
    }
    return count;
}

void expect_valid(const SurfaceMesh& mesh, const char* after) {
    const auto violations = validate_mesh(mesh);
    EXPECT_TRUE(violations.empty()) << after << ": " << violations_text(violations);
    EXPECT_EQ(periodic_intersections(mesh), 0) << "intersects after " << after;
}

/// One mesh holding both meshes' vertices and triangles, with `periods`.
SurfaceMesh combine(const SurfaceMesh& a, const SurfaceMesh& b, const MeshPeriods& periods) {
    std::vector<Vec3> x = a.positions();
    x.insert(x.end(), b.positions().begin(), b.positions().end());
    std::vector<Triangle> t;
    for (int ti = 0; ti < a.num_triangles(); ++ti)
        t.push_back(a.triangle(ti));
    for (int ti = 0; ti < b.num_triangles(); ++ti) {
        Triangle tri = b.triangle(ti);
        for (int& v : tri)
            v += a.num_vertices();
        t.push_back(tri);
    }
    SurfaceMesh mesh(std::move(x), t);
    mesh.set_periods(periods);
    return mesh;
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
    // The quartic fit over two-rings (surface_fit, by minimum image): the same at the seam rings
    // and closer to 1/r than the cotangent formula.
    int fallbacks = -1;
    const std::vector<Vec3> fitted = fitted_mean_curvature_normals(mesh, 1.0, nullptr, &fallbacks);
    EXPECT_EQ(fallbacks, 0);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        const size_t i = static_cast<size_t>(vi);
        const Vec3 radial =
            (mesh.position(vi) - Vec3(0.5, 0.5, mesh.position(vi).z())).normalized();
        EXPECT_LT((fitted[i] - fitted[i].norm() * radial).norm(), 1e-6) << "vertex " << vi;
        EXPECT_LT(relative(fitted[i].norm(), 1.0 / r), 1.5e-3) << "vertex " << vi;
    }
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

// ---- merging ---------------------------------------------------------------------------------

/// Two columns along z (period 1) side by side along x, in a box also periodic in x (period 1):
/// radius 0.15, 16 × 20 vertices, placed on either side of x = `contact` (mod 1) with `gap`
/// between them there and 0.4 − gap on the other side.
SurfaceMesh two_columns(double gap, double contact) {
    constexpr double R = 0.15;
    MeshPeriods periods;
    periods.length = Vec3(1.0, 0.0, 1.0);
    const SurfaceMesh a =
        testing::periodic_tube(R, Vec3(contact + R + 0.5 * gap, 0.5, 0.0), 2, 1.0, 16, 20);
    const SurfaceMesh b =
        testing::periodic_tube(R, Vec3(contact - R - 0.5 * gap, 0.5, 0.0), 2, 1.0, 16, 20);
    return combine(a, b, periods);
}

TEST(PeriodicMerge, ColumnsTouchingAcrossTheSeamMergeIntoOneComponent) {
    constexpr double GAP = 0.004;
    // Contact across the seam x = 0 ≡ 1, and (the control) in the middle of the box.
    for (const double contact : {0.0, 0.5}) {
        SurfaceMesh mesh = two_columns(GAP, contact);
        expect_valid(mesh, "generation");
        ASSERT_EQ(triangle_components(mesh).count, 2);
        ASSERT_EQ(euler_characteristic(mesh), 0);
        const double volume = enclosed_volume(mesh);

        TopologyOptions options;
        TopologyContext context;
        context.xi = testing::mean_edge_length(mesh);
        ASSERT_LT(GAP, options.merge_distance_fraction * context.xi);
        const TopologyReport report = change_topology(mesh, options, context);
        EXPECT_GT(report.merge.candidates, 0) << "contact " << contact;
        EXPECT_GE(report.merge.merges, 1) << "contact " << contact;
        expect_valid(mesh, "merging");
        // Across the seam, the band's triangles join vertices a period apart in raw coordinates
        // (before the merge no triangle did: each column lies inside the box).
        int across = 0;
        for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
            if (!mesh.triangle_alive(ti))
                continue;
            const Triangle& t = mesh.triangle(ti);
            const double x0 = mesh.position(t[0]).x();
            across += std::abs(mesh.position(t[1]).x() - x0) > 0.5 ||
                              std::abs(mesh.position(t[2]).x() - x0) > 0.5
                          ? 1
                          : 0;
        }
        EXPECT_EQ(across > 0, contact == 0.0) << across << " triangles across the x seam";
        EXPECT_EQ(triangle_components(mesh).count, 1) << "contact " << contact;
        // Each merge opens one handle between the columns: χ drops by 2 per merge.
        EXPECT_EQ(euler_characteristic(mesh), -2 * report.merge.merges);
        // The band bridges a gap of 0.004 over a few edges: a tiny volume change.
        EXPECT_LT(relative(enclosed_volume(mesh), volume), 1e-3)
            << enclosed_volume(mesh) << " vs " << volume;
        // The merged neck is where the columns met: within a few edges of x = contact.
        for (int ti = 0; ti < mesh.num_triangles(); ++ti)
            if (mesh.triangle_alive(ti) && mesh.triangle_marked(ti)) {
                const Vec3 c = mesh.triangle_positions(ti)[0];
                const double dx = mesh.periods().difference(c, Vec3(contact, 0.0, 0.0)).x();
                EXPECT_LT(std::abs(dx), 0.1) << "a new triangle at x = " << c.x();
            }

        // Remeshing afterwards keeps one valid component.
        RemeshOptions remesh;
        ImproveContext improve;
        improve.xi = context.xi;
        improve_mesh(mesh, remesh, improve);
        expect_valid(mesh, "improvement after merging");
        EXPECT_EQ(triangle_components(mesh).count, 1);
    }
}

TEST(PeriodicMerge, FarColumnsDoNotMerge) {
    SurfaceMesh mesh = two_columns(0.05, 0.0);  // 0.05 apart across the seam: beyond 0.1 ξ
    TopologyContext context;
    context.xi = testing::mean_edge_length(mesh);
    const TopologyReport report = change_topology(mesh, TopologyOptions{}, context);
    EXPECT_EQ(report.merge.candidates, 0);
    EXPECT_EQ(triangle_components(mesh).count, 2);
}

// ---- separation --------------------------------------------------------------------------------

TEST(PeriodicSeparation, SingularVertexOnTheSeamIsSplitTowardsItsFansNearestImages) {
    // Two tetrahedra sharing vertex 0 at x = 0 ≡ 1: one on each side of the seam, so that one
    // fan's other vertices lie a period away in raw coordinates.
    const double s = 0.1;
    std::vector<Vec3> p = {{0, 0.5, 0.5},     {s, 0.5, 0.5},       {0, 0.5 + s, 0.5},
                           {0, 0.5, 0.5 + s}, {1.0 - s, 0.5, 0.5}, {0, 0.5 - s, 0.5},
                           {0, 0.5, 0.5 - s}};
    std::vector<Triangle> t = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3},
                               {0, 4, 5}, {0, 6, 4}, {0, 5, 6}, {4, 6, 5}};
    SurfaceMesh mesh(p, t);
    MeshPeriods periods;
    periods.length = Vec3(1.0, 0.0, 0.0);
    mesh.set_periods(periods);
    expect_valid(mesh, "generation");
    const Vec3 x0 = mesh.position(0);
    const SeparationOptions options;
    const SeparationReport r = separate(mesh, options, true, 0.5);
    EXPECT_EQ(r.singular_vertices_split, 1);
    EXPECT_EQ(r.copies_created, 1);
    EXPECT_EQ(vertex_fans(mesh, 0).size(), 1u);
    expect_valid(mesh, "separation");
    EXPECT_EQ(triangle_components(mesh).count, 2);
    // Each copy moved by nudge_fraction × the distance to its fan's centroid (about s / 2), in
    // the box; read by raw coordinates the seam-side fan's centroid would be half a box away.
    for (const int v : {0, mesh.num_vertices() - 1}) {
        const Vec3 x = mesh.position(v);
        EXPECT_GE(x.x(), 0.0);
        EXPECT_LT(x.x(), 1.0);
        const double moved = mesh.periods().difference(x, x0).norm();
        EXPECT_GT(moved, 0.0);
        EXPECT_LT(moved, options.nudge_fraction * s) << "vertex " << v;
    }
    // Both pieces keep their volume (the nudge moves a vertex inside its own tetrahedron's
    // fan: a change of order nudge_fraction).
    const std::vector<double> v = component_volumes(mesh, triangle_components(mesh));
    for (double vol : v)
        EXPECT_NEAR(vol, s * s * s / 6.0, 0.05 * s * s * s / 6.0);
}

TEST(PeriodicSeparation, ColumnPinchedAtTheSeamBecomesOneClosedDrop) {
    // A column whose radius narrows towards z = 0 ≡ 1; squeezing the waist further (about the
    // seam) while remeshing and changing topology pinches it: the periodic column (a torus in
    // the box, χ = 0) becomes one closed drop (χ = 2).
    constexpr double R = 0.15;
    const auto waist = [](double z) {
        const double d = std::min(z, 1.0 - z);  // distance to the seam
        return 1.0 - 0.5 * std::exp(-(d / 0.12) * (d / 0.12));
    };
    SurfaceMesh mesh = testing::periodic_tube(R, Vec3(0.5, 0.5, 0.0), 2, 1.0, 24, 40, waist);
    expect_valid(mesh, "generation");
    RemeshOptions remesh;
    ImproveContext improve;
    improve.xi = testing::mean_edge_length(mesh);
    TopologyOptions topology;
    TopologyContext topo_context;
    topo_context.xi = improve.xi;
    constexpr int MAX_STEPS = 60;
    int steps = 0;
    while ((triangle_components(mesh).count != 1 || euler_characteristic(mesh) != 2) &&
           steps < MAX_STEPS) {
        for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
            if (!mesh.vertex_alive(vi))
                continue;
            Vec3 x = mesh.position(vi);
            const double d = std::min(x.z(), 1.0 - x.z());
            const double f = 1.0 - 0.15 * std::exp(-(d / 0.1) * (d / 0.1));
            x.x() = 0.5 + f * (x.x() - 0.5);
            x.y() = 0.5 + f * (x.y() - 0.5);
            mesh.set_position(vi, x);
        }
        ASSERT_EQ(periodic_intersections(mesh), 0) << "the squeeze itself intersected";
        improve_mesh(mesh, remesh, improve);
        expect_valid(mesh, "improvement");
        change_topology(mesh, topology, topo_context);
        expect_valid(mesh, "topology change");
        ++steps;
    }
    mesh.compact();
    EXPECT_EQ(triangle_components(mesh).count, 1) << "after " << steps << " steps";
    EXPECT_EQ(euler_characteristic(mesh), 2) << "after " << steps << " steps";
    EXPECT_GT(enclosed_volume(mesh), 0.0);
    // The drop no longer wraps: every vertex's z is away from the seam it pinched at.
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        EXPECT_GT(std::min(mesh.position(vi).z(), 1.0 - mesh.position(vi).z()), 0.0);
}

}  // namespace
}  // namespace meniscus::tracker
