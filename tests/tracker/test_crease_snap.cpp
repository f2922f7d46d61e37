// Putting meshes of implicit shapes onto their creases (tracker/crease_snap.h) through the
// mesher's /surface/crease/snap option.
#include "tracker/crease_snap.h"
#include "tracker/flows/flow_errors.h"
#include "tracker/implicit_mesher.h"
#include "tracker/mesh_intersections.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

namespace meniscus::tracker {
namespace {

/// Zalesak's notched sphere (app/validate_zalesak.h): a ball of radius 0.15 minus a slot 0.05
/// wide and 0.125 deep, whose sharp edges meet in four corners.
ShapePtr notched_ball() {
    return make_difference(make_sphere({0.5, 0.75, 0.5}, 0.15),
                           make_box({0.475, 0.45, 0.2}, {0.525, 0.725, 0.8}));
}

/// Largest distance of the mesh (vertices and 2² samples per triangle) from the exact surface.
double largest_distance(const SurfaceMesh& mesh, const ImplicitShape& shape) {
    SurfaceErrorOptions o;
    o.triangle_subdivisions = 2;
    return surface_error(
               mesh, [&shape](const Vec3& x) { return projected_signed_distance(shape, x, 1e-10); },
               o)
        .linf;
}

void expect_valid(const SurfaceMesh& mesh) {
    const auto violations = validate_mesh(mesh);
    EXPECT_TRUE(violations.empty()) << violations.front().message;
    EXPECT_TRUE(find_self_intersections(mesh).triangle_pairs.empty());
}

TEST(CreaseSnap, NotchedBallGetsItsSharpEdgesInsteadOfChamfers) {
    const double xi = 0.02;
    const ShapePtr shape = notched_ball();
    ImplicitMeshOptions options;
    options.edge_length = xi;
    const SurfaceMesh plain = mesh_implicit_shape(*shape, options);
    options.crease.snap = true;
    ImplicitMeshReport report;
    const SurfaceMesh snapped = mesh_implicit_shape(*shape, options, &report);
    const double plain_distance = largest_distance(plain, *shape);
    const double snapped_distance = largest_distance(snapped, *shape);
    std::cout << "[ measured ] notched ball ξ = 0.02: largest distance from the exact surface "
              << plain_distance / xi << " ξ meshed plainly, " << snapped_distance / xi
              << " ξ snapped (" << report.crease_snaps << " snaps, " << report.crease_flips
              << " flips, " << report.snapped_vertices << " vertices on creases, angles "
              << report.min_angle_degrees << "°–" << report.max_angle_degrees << "°)\n";
    // Measured: 0.39 ξ plainly (triangles cut across the slot's edges), 0.040 ξ snapped.
    EXPECT_GT(plain_distance, 0.3 * xi);
    EXPECT_LT(snapped_distance, 0.06 * xi);
    EXPECT_GT(report.snapped_vertices, 0);
    EXPECT_GE(report.min_angle_degrees, 10.0);
    EXPECT_LT(report.max_abs_phi, 1e-3 * xi);
    expect_valid(snapped);
    EXPECT_NEAR(enclosed_volume(snapped), enclosed_volume(plain), 0.01 * enclosed_volume(plain));
}

TEST(CreaseSnap, BoxGetsItsEdgesAndMostCorners) {
    const Vec3 lo(-0.2, -0.15, -0.1), hi(0.2, 0.15, 0.1);
    const double volume = 0.4 * 0.3 * 0.2;
    const ShapePtr box = make_box(lo, hi);
    ImplicitMeshOptions options;
    options.edge_length = 0.04;
    const SurfaceMesh plain = mesh_implicit_shape(*box, options);
    options.crease.snap = true;
    const SurfaceMesh mesh = mesh_implicit_shape(*box, options);
    expect_valid(mesh);
    int corners = 0;
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3 c((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                     (corner & 4) ? hi.z() : lo.z());
        double nearest = 1.0;
        for (int vi = 0; vi < mesh.num_vertices(); ++vi)
            if (mesh.vertex_alive(vi))
                nearest = std::min(nearest, (mesh.position(vi) - c).norm());
        corners += nearest < 1e-9 ? 1 : 0;
    }
    const double plain_distance = largest_distance(plain, *box);
    const double snapped_distance = largest_distance(mesh, *box);
    const double volume_error = std::abs(enclosed_volume(mesh) - volume) / volume;
    std::cout << "[ measured ] box, ξ = 0.04: largest distance " << plain_distance << " plainly, "
              << snapped_distance << " snapped; " << corners << " of 8 corners are vertices; "
              << "volume error " << std::abs(enclosed_volume(plain) - volume) / volume
              << " plainly, " << volume_error << " snapped\n";
    // Measured: 7 of 8 corners (the eighth's vertex would turn a triangle too far), largest
    // distance 0.0099 (there) against 0.0146 plainly, volume error 3.2e-4 against 3.2e-2.
    EXPECT_GE(corners, 6);
    EXPECT_LT(snapped_distance, 0.75 * plain_distance);
    EXPECT_LT(volume_error, 1e-3);
}

TEST(CreaseSnap, SmoothShapeIsLeftAlone) {
    ImplicitMeshOptions options;
    options.edge_length = 0.04;
    const ShapePtr sphere = make_sphere({0, 0, 0}, 0.15);  // edges turn by about 0.27 rad
    const SurfaceMesh plain = mesh_implicit_shape(*sphere, options);
    options.crease.snap = true;
    ImplicitMeshReport report;
    const SurfaceMesh snapped = mesh_implicit_shape(*sphere, options, &report);
    EXPECT_EQ(report.crease_snaps, 0);
    EXPECT_EQ(report.crease_flips, 0);
    EXPECT_EQ(snapped.positions(), plain.positions());
}

TEST(CreaseSnap, OptionsAreValidatedByName) {
    const auto message = [](const CreaseSnapOptions& o) -> std::string {
        try {
            o.validate();
        } catch (const std::invalid_argument& e) {
            return e.what();
        }
        return "";
    };
    CreaseSnapOptions o;
    EXPECT_EQ(message(o), "");
    o.angle = 2.0;
    EXPECT_EQ(message(o).rfind("angle:", 0), 0u);
    o = {};
    o.passes = 0;
    EXPECT_EQ(message(o).rfind("passes:", 0), 0u);
    o = {};
    o.max_edge_fraction = 1.0;
    EXPECT_EQ(message(o).rfind("max_edge_fraction:", 0), 0u);
    ImplicitMeshOptions mesher;
    mesher.edge_length = 0.04;
    mesher.crease.snap = true;
    mesher.crease.angle = 2.0;  // fine for refinement alone, not for snapping
    EXPECT_THROW(mesher.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace meniscus::tracker
