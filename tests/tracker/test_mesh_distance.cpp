// Distance from points to a mesh (tracker/mesh_distance.h) and the sampled Hausdorff distance
// between two meshes (tracker/flows/flow_errors.h).
#include "tracker/distance.h"
#include "tracker/flows/flow_errors.h"
#include "tracker/implicit_mesher.h"
#include "tracker/mesh_distance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace meniscus::tracker {
namespace {

SurfaceMesh sphere_mesh(const Vec3& center, double radius, double edge_length) {
    ImplicitMeshOptions o;
    o.edge_length = edge_length;
    return mesh_implicit_shape(*make_sphere(center, radius), o);
}

double brute_force_distance(const SurfaceMesh& mesh, const Vec3& p) {
    double best = std::numeric_limits<double>::infinity();
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        best = std::min(best, point_triangle_proximity(p, mesh.position(t[0]), mesh.position(t[1]),
                                                       mesh.position(t[2]))
                                  .distance);
    }
    return best;
}

TEST(MeshDistance, MatchesBruteForceNearAndFar) {
    const SurfaceMesh mesh = sphere_mesh(Vec3(0.1, 0.2, -0.1), 0.3, 0.05);
    const MeshDistance d(mesh);
    EXPECT_EQ(d.triangles(), mesh.count_live_triangles());
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (double scale : {0.35, 1.0, 20.0}) {  // near the surface, around it, far away
        for (int i = 0; i < 300; ++i) {
            const Vec3 p = Vec3(0.1, 0.2, -0.1) + scale * Vec3(u(rng), u(rng), u(rng));
            EXPECT_EQ(d.distance(p), brute_force_distance(mesh, p)) << p.transpose();
        }
    }
    // On a vertex: zero.
    EXPECT_EQ(d.distance(mesh.position(0)), 0.0);
}

TEST(MeshDistance, NeedsALiveTriangle) {
    const SurfaceMesh empty;
    EXPECT_THROW(MeshDistance{empty}, std::invalid_argument);
}

TEST(HausdorffDistance, OfAMeshAndItselfIsZeroAndOfATranslateIsTheShift) {
    const SurfaceMesh a = sphere_mesh(Vec3::Zero(), 0.25, 0.04);
    const HausdorffDistance self = hausdorff_distance(a, a);
    EXPECT_LT(self.symmetric, 1e-15);  // samples on a triangle: zero up to round-off
    EXPECT_LT(self.a_to_b.l1, 1e-15);
    // Shifted along x by s: samples move at most s away (the far pole exactly s, where the
    // tangent plane is perpendicular to the shift) and at least 0 (the sides slide along).
    const double shift = 0.01;
    SurfaceMesh b = a;
    for (int vi = 0; vi < b.num_vertices(); ++vi)
        b.set_position(vi, b.position(vi) + Vec3(shift, 0.0, 0.0));
    const HausdorffDistance h = hausdorff_distance(a, b);
    EXPECT_LE(h.symmetric, shift * (1 + 1e-12));
    EXPECT_GT(h.symmetric, 0.9 * shift);  // the poles on ±x (a mesh vertex may sit off them)
    EXPECT_NEAR(h.a_to_b.linf, h.b_to_a.linf, 0.05 * shift);  // symmetric by construction
    // The mean of |shift·n_x| over a sphere is shift/2.
    EXPECT_NEAR(h.a_to_b.l1, 0.5 * shift, 0.05 * shift);
}

TEST(HausdorffDistance, SeesANotchTheOtherMeshLacks) {
    // A ball with a slot cut into it against the whole ball: from the ball's side the distance
    // is as deep as the slot reaches into it; from the notched side zero only up to the samples
    // on the slot's walls, which lie inside the ball (their distance to its surface).
    const Vec3 c = Vec3::Zero();
    const double r = 0.3, depth = 0.1;
    const SurfaceMesh ball = sphere_mesh(c, r, 0.03);
    ImplicitMeshOptions o;
    o.edge_length = 0.03;
    const SurfaceMesh notched = mesh_implicit_shape(
        *make_difference(make_sphere(c, r),
                         make_box(Vec3(-0.05, -1.0, -1.0), Vec3(0.05, -r + depth, 1.0))),
        o);
    const HausdorffDistance h = hausdorff_distance(ball, notched);
    // The ball's surface where the slot opens lies about `depth` above the slot's floor and
    // half a slot width (0.05) from its walls: distance ≈ 0.05.
    EXPECT_GT(h.a_to_b.linf, 0.04);
    EXPECT_LT(h.a_to_b.linf, 0.06);
    // The slot's floor, at y = −r + depth, is 0.1 inside the ball's bottom.
    EXPECT_GT(h.b_to_a.linf, 0.09);
    EXPECT_LT(h.b_to_a.linf, 0.11);
    EXPECT_EQ(h.symmetric, std::max(h.a_to_b.linf, h.b_to_a.linf));
}

}  // namespace
}  // namespace meniscus::tracker
