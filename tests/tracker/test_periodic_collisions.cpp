// Periodic meshes (issue 39): the collision pipeline sees the images across the box's faces —
// broad phase, CCD and repulsion, impact zones, the static intersection test, volumes, and the
// SurfaceTracker's wrapping and period check.
#include "periodic_meshes.h"

#include "tracker/broadphase.h"
#include "tracker/ccd.h"
#include "tracker/collision_resolution.h"
#include "tracker/mesh_intersections.h"
#include "tracker/surface_tracker.h"
#include "tracker/volume_constraint.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

namespace meniscus::tracker {
namespace {

std::vector<Vec3> randomly_moved(const std::vector<Vec3>& x, double amplitude, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, amplitude);
    std::vector<Vec3> moved = x;
    for (Vec3& p : moved)
        p += Vec3(n(rng), n(rng), n(rng));
    return moved;
}

/// True when the two positions are more than half a period apart along a wrapping axis: a
/// pair of elements there meets only across the box's faces.
bool across_seam(const MeshPeriods& periods, const Vec3& a, const Vec3& b) {
    for (int axis = 0; axis < 3; ++axis)
        if (periods.wraps(axis) && std::abs(a[axis] - b[axis]) > 0.5 * periods.length[axis])
            return true;
    return false;
}

/// The broad phase's pairs equal the periodic brute force's (each pair against the 3^k images
/// of its second element) for a random motion; returns how many vertex–triangle and edge–edge
/// pairs meet only across the seam.
std::pair<int, int> expect_broad_phase_equals_brute_force(const SurfaceMesh& mesh, double amplitude,
                                                          double padding, unsigned seed) {
    const std::vector<Vec3>& x0 = mesh.positions();
    const std::vector<Vec3> x1 = randomly_moved(x0, amplitude, seed);
    const BroadPhase broad(mesh, x0, x1, padding);
    const auto vt = broad.vertex_triangle_pairs();
    const auto ee = broad.edge_edge_pairs();
    const auto vt_ref = brute_force_vertex_triangle_pairs(mesh, x0, x1, padding);
    const auto ee_ref = brute_force_edge_edge_pairs(mesh, x0, x1, padding);
    EXPECT_EQ(vt, vt_ref) << "seed " << seed;
    EXPECT_EQ(ee, ee_ref) << "seed " << seed;
    int vt_seam = 0, ee_seam = 0;
    for (const VertexTrianglePair& p : vt_ref)
        vt_seam += across_seam(mesh.periods(), x0[static_cast<size_t>(p.vi)],
                               x0[static_cast<size_t>(mesh.triangle(p.ti)[0])]);
    for (const EdgeEdgePair& p : ee_ref)
        ee_seam += across_seam(mesh.periods(), x0[static_cast<size_t>(mesh.edge(p.ei)[0])],
                               x0[static_cast<size_t>(mesh.edge(p.ej)[0])]);

    const BroadPhase still(mesh, padding);
    const auto tt = still.triangle_pairs();
    EXPECT_EQ(tt, brute_force_triangle_pairs(mesh, padding));
    for (const TrianglePair& p : tt)
        EXPECT_LT(p.ti, p.tj);  // never a triangle with its own image
    EXPECT_EQ(static_edge_edge_pairs(mesh, padding, [](int, int) { return true; }),
              brute_force_edge_edge_pairs(mesh, x0, x0, padding));
    return {vt_seam, ee_seam};
}

TEST(PeriodicBroadPhase, EqualsPeriodicBruteForceOnATube) {
    const SurfaceMesh tube = testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 2, 1.0, 12, 16);
    for (unsigned seed = 0; seed < 4; ++seed) {
        const auto [vt_seam, ee_seam] =
            expect_broad_phase_equals_brute_force(tube, 0.01, 0.02 * seed, seed);
        if (seed > 0) {  // padded: elements a ring apart across the seam are paired
            EXPECT_GT(vt_seam, 0) << "seed " << seed;
            EXPECT_GT(ee_seam, 0) << "seed " << seed;
        }
    }
}

TEST(PeriodicBroadPhase, EqualsPeriodicBruteForceOnADoublyPeriodicSheet) {
    const SurfaceMesh sheet = testing::periodic_sheet(1.0, 0.8, 10, 8, [](double x, double y) {
        return 0.5 + 0.05 * std::sin(2.0 * M_PI * x) * std::cos(2.0 * M_PI * y / 0.8);
    });
    for (unsigned seed = 0; seed < 4; ++seed) {
        const auto [vt_seam, ee_seam] =
            expect_broad_phase_equals_brute_force(sheet, 0.01, 0.02 * seed, 10 + seed);
        EXPECT_GT(vt_seam, 0) << "seed " << seed;
        EXPECT_GT(ee_seam, 0) << "seed " << seed;
    }
}

/// Positions handed to the broad phase need not be wrapped: moving some vertices by whole
/// periods changes no pair; and the pairs across the seam are those of the same mesh shifted
/// so that no element straddles a face.
TEST(PeriodicBroadPhase, PairsDoNotDependOnWhichImageHoldsAVertex) {
    SurfaceMesh tube = testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 2, 1.0, 12, 16);
    const std::vector<Vec3> x0 = tube.positions();
    const std::vector<Vec3> x1 = randomly_moved(x0, 0.01, 3);
    std::vector<Vec3> y0 = x0, y1 = x1;
    for (size_t i = 0; i < y0.size(); i += 3) {
        const double k = i % 2 == 0 ? 1.0 : -2.0;
        y0[i].z() += k;
        y1[i].z() += k;
    }
    const BroadPhase a(tube, x0, x1, 0.01), b(tube, y0, y1, 0.01);
    EXPECT_EQ(a.vertex_triangle_pairs(), b.vertex_triangle_pairs());
    EXPECT_EQ(a.edge_edge_pairs(), b.edge_edge_pairs());
    EXPECT_EQ(a.triangle_pairs(), b.triangle_pairs());
}

// ---- helpers for the motions below --------------------------------------------------------

/// The meshes' vertices and triangles in one mesh, with `periods` (positions wrapped).
SurfaceMesh joined(const std::vector<const SurfaceMesh*>& parts, const MeshPeriods& periods) {
    std::vector<Vec3> x;
    std::vector<Triangle> t;
    for (const SurfaceMesh* m : parts) {
        const int offset = static_cast<int>(x.size());
        x.insert(x.end(), m->positions().begin(), m->positions().end());
        for (int ti = 0; ti < m->num_triangles(); ++ti) {
            Triangle tri = m->triangle(ti);
            for (int& v : tri)
                v += offset;
            t.push_back(tri);
        }
    }
    SurfaceMesh mesh(std::move(x), t);
    mesh.set_periods(periods);
    return mesh;
}

/// An octahedron of `radius` about `centre`, normals outwards.
SurfaceMesh octahedron(const Vec3& centre, double radius) {
    std::vector<Vec3> x = {centre + radius * Vec3::UnitX(), centre - radius * Vec3::UnitX(),
                           centre + radius * Vec3::UnitY(), centre - radius * Vec3::UnitY(),
                           centre + radius * Vec3::UnitZ(), centre - radius * Vec3::UnitZ()};
    return SurfaceMesh(
        std::move(x),
        {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
}

MeshPeriods periods_of(double lx, double ly, double lz) {
    MeshPeriods p;
    p.length = Vec3(lx, ly, lz);
    return p;
}

/// The volume enclosed by the mesh at `x` from the divergence theorem along `axis` (which must
/// not wrap): Σ_t (centroid_axis) (area vector)_axis, every triangle by the minimum image. The
/// test's own sum, independent of the library's volumes.
double divergence_volume(const SurfaceMesh& mesh, const std::vector<Vec3>& x, int axis) {
    double v = 0.0;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        const Vec3& a = x[static_cast<size_t>(t[0])];
        const Vec3 b = mesh.periods().nearest_image(x[static_cast<size_t>(t[1])], a);
        const Vec3 c = mesh.periods().nearest_image(x[static_cast<size_t>(t[2])], a);
        v += (a[axis] + b[axis] + c[axis]) / 3.0 * 0.5 * (b - a).cross(c - a)[axis];
    }
    return v;
}

/// Smallest distance between a vertex of [0, split) and one of [split, n), by the minimum image.
double closest_vertices(const SurfaceMesh& mesh, int split) {
    double best = INFINITY;
    for (int i = 0; i < split; ++i)
        for (int j = split; j < mesh.num_vertices(); ++j)
            best = std::min(best,
                            mesh.periods().difference(mesh.position(i), mesh.position(j)).norm());
    return best;
}

// ---- CCD and repulsion across the seam --------------------------------------------------

/// A small octahedron above a flat doubly periodic sheet (pinned) dives through it while moving
/// across the box's face x = 1: every vertex crosses z = 0.5 at x ∈ [1.01, 1.05], i.e. over the
/// sheet's triangles near x = 0, which lie more than half a period from the octahedron's path
/// in the box and meet it only through their images. CCD finds those collisions and the
/// response keeps the octahedron above the sheet.
TEST(PeriodicCollisions, ADiveAcrossTheSeamIsCaughtThroughTheImages) {
    const SurfaceMesh sheet =
        testing::periodic_sheet(1.0, 1.0, 8, 8, [](double, double) { return 0.5; });
    const SurfaceMesh octa = octahedron(Vec3(0.93, 0.5, 0.6), 0.02);
    const SurfaceMesh mesh = joined({&sheet, &octa}, periods_of(1.0, 1.0, 0.0));
    const int first_octa = sheet.num_vertices();
    const std::vector<Vec3> x0 = mesh.positions();
    std::vector<Vec3> x1 = x0;
    for (int v = first_octa; v < mesh.num_vertices(); ++v)
        x1[static_cast<size_t>(v)] += Vec3(0.2, 0.0, -0.2);
    ASSERT_TRUE(is_intersection_free(mesh));

    // The vertex–triangle collisions of the requested motion (periodic brute force, each pair
    // by the minimum image about the vertex): all with sheet triangles whose corners lie at
    // x < 0.5 in the box, far from the path x ∈ [0.91, 1.15].
    int hits = 0, only_through_images = 0;
    for (const VertexTrianglePair& p : brute_force_vertex_triangle_pairs(mesh, x0, x1, 0.0)) {
        const Triangle& t = mesh.triangle(p.ti);
        if (p.vi < first_octa || t[0] >= first_octa)
            continue;
        const Vec3& ref = x0[static_cast<size_t>(p.vi)];
        std::array<Vec3, 3> c0, c1;
        bool far = true;
        for (int k = 0; k < 3; ++k) {
            const auto i = static_cast<size_t>(t[k]);
            const Vec3 s = mesh.periods().shift_towards(x0[i], ref);
            c0[k] = x0[i] + s;
            c1[k] = x1[i] + s;
            far = far && x0[i].x() < 0.5;
        }
        if (point_triangle_ccd(ref, c0[0], c0[1], c0[2], x1[static_cast<size_t>(p.vi)], c1[0],
                               c1[1], c1[2])) {
            ++hits;
            only_through_images += far;
        }
    }
    EXPECT_GT(hits, 0);
    EXPECT_EQ(only_through_images, hits);
    EXPECT_FALSE(motion_is_collision_free(mesh, x0, x1)) << "the dive across the seam was missed";

    CollisionOptions o;
    o.proximity_epsilon = 1e-4;
    std::vector<std::uint8_t> pinned(static_cast<size_t>(mesh.num_vertices()), 0);
    std::fill(pinned.begin(), pinned.begin() + first_octa, 1);
    std::vector<Vec3> resolved = x1;
    const CollisionReport report = resolve_collisions(mesh, x0, resolved, 1.0, o, nullptr, &pinned);
    EXPECT_GT(report.collisions_first_sweep, 0);
    EXPECT_TRUE(report.collision_free);
    EXPECT_TRUE(motion_is_collision_free(mesh, x0, resolved));
    EXPECT_TRUE(find_self_intersections(mesh, &resolved).intersection_free());
    double lowest = INFINITY;
    for (int v = first_octa; v < mesh.num_vertices(); ++v)
        lowest = std::min(lowest, resolved[static_cast<size_t>(v)].z());
    EXPECT_GT(lowest, 0.5) << "the octahedron went through the sheet";
    std::cout << "[ info ] " << hits << " vertex-triangle hits, " << report.collisions_first_sweep
              << " first-sweep collisions, lowest vertex " << lowest - 0.5
              << " above the sheet, motion fraction " << report.motion_fraction << "\n";
}

/// Two columns along z, periodic in x and z, 0.1 apart across the face x = 0 (0.3 apart inside
/// the box), driven into each other across that face for 20 steps of 0.01 each. The tracker
/// (repulsion, CCD, impact zones, all through the images) keeps them intersection-free after
/// every step and lets them touch; without collision handling the same motion intersects
/// across the seam, and the static test sees that.
TEST(PeriodicCollisions, ColumnsDrivenIntoEachOtherAcrossTheSeamStayApart) {
    const SurfaceMesh a = testing::periodic_tube(0.15, Vec3(0.2, 0.5, 0.0), 2, 1.0, 16, 16);
    const SurfaceMesh b = testing::periodic_tube(0.15, Vec3(0.8, 0.5, 0.0), 2, 1.0, 16, 16);
    const SurfaceMesh start = joined({&a, &b}, periods_of(1.0, 0.0, 1.0));
    const int split = a.num_vertices();
    ASSERT_TRUE(find_self_intersections(start).intersection_free());
    const double gap = closest_vertices(start, split);
    EXPECT_NEAR(gap, 0.1, 1e-9);
    std::vector<Vec3> velocity(static_cast<size_t>(start.num_vertices()), Vec3(-1.0, 0.0, 0.0));
    for (int v = split; v < start.num_vertices(); ++v)
        velocity[static_cast<size_t>(v)] = Vec3(1.0, 0.0, 0.0);

    for (const bool safe : {true, false}) {
        TrackerOptions o;
        o.improve_mesh = false;
        o.allow_topology_changes = false;
        o.collision_safety = safe;
        o.verify_intersection_free = true;
        SurfaceTracker tracker(start, o);
        int proximities = 0, collisions = 0, intersecting = 0;
        for (int step = 0; step < 20; ++step) {
            const IntegrateResult r = tracker.integrate(velocity, 0.01);
            proximities += r.collisions.proximities;
            collisions += r.collisions.collisions_first_sweep;
            intersecting = std::max(intersecting, r.intersecting_pairs);
            if (safe) {
                ASSERT_EQ(r.intersecting_pairs, 0) << "step " << step;
            }
        }
        const SurfaceMesh& m = tracker.mesh();
        for (int v = 0; v < m.num_vertices(); ++v) {
            EXPECT_GE(m.position(v).x(), 0.0);
            EXPECT_LT(m.position(v).x(), 1.0);
            EXPECT_GE(m.position(v).z(), 0.0);
            EXPECT_LT(m.position(v).z(), 1.0);
        }
        if (safe) {
            EXPECT_GT(proximities, 0);
            EXPECT_GT(collisions, 0);
            EXPECT_LT(closest_vertices(m, split), 0.01) << "the columns did not come together";
            std::cout << "[ info ] safe: " << proximities << " proximities, " << collisions
                      << " first-sweep collisions, closest vertices " << closest_vertices(m, split)
                      << "\n";
        } else {
            EXPECT_GT(intersecting, 0) << "unsafe motion should intersect across the seam";
            std::cout << "[ info ] unsafe: " << intersecting << " intersecting pairs\n";
        }
    }
}

// ---- static intersections -----------------------------------------------------------------

/// Two columns whose surfaces overlap only across the face x = 1 (centres 0.15 and 0.9, radii
/// 0.15: 0.25 apart across it): the static test finds the intersections, all between the two
/// columns; the same positions read without the period along x (the second column unwrapped
/// past x = 1) are 0.45 apart and free, and columns 0.05 apart across the face are free.
TEST(PeriodicIntersections, FoundAcrossTheSeam) {
    const SurfaceMesh a = testing::periodic_tube(0.15, Vec3(0.15, 0.5, 0.0), 2, 1.0, 16, 16);
    const SurfaceMesh b = testing::periodic_tube(0.15, Vec3(0.9, 0.5, 0.0), 2, 1.0, 16, 16);
    const SurfaceMesh mesh = joined({&a, &b}, periods_of(1.0, 0.0, 1.0));
    const IntersectionReport report = find_self_intersections(mesh);
    EXPECT_GT(report.triangle_pairs.size(), 0u);
    EXPECT_FALSE(is_intersection_free(mesh));
    EXPECT_GT(report.edge_triangle_pairs.size(), 0u);
    for (const TrianglePair& p : report.triangle_pairs) {
        const bool a_first = mesh.triangle(p.ti)[0] < a.num_vertices();
        const bool a_second = mesh.triangle(p.tj)[0] < a.num_vertices();
        EXPECT_NE(a_first, a_second) << "a column intersects itself";
    }
    std::cout << "[ info ] " << report.triangle_pairs.size() << " intersecting pairs\n";
    const SurfaceMesh unwrapped = joined({&a, &b}, periods_of(0.0, 0.0, 1.0));
    EXPECT_TRUE(is_intersection_free(unwrapped));

    const SurfaceMesh c = testing::periodic_tube(0.15, Vec3(0.8, 0.5, 0.0), 2, 1.0, 16, 16);
    const SurfaceMesh apart = joined({&a, &c}, periods_of(1.0, 0.0, 1.0));  // 0.05 across
    EXPECT_TRUE(find_self_intersections(apart).intersection_free());
    EXPECT_TRUE(is_intersection_free(apart));
}

// ---- volumes ------------------------------------------------------------------------------

/// The volume of a column closed through the box's faces: from the divergence theorem along a
/// non-wrapping axis, the same along x and y, near π r² L, unchanged by a shift across the seam;
/// the volume-restoring displacements change it by the requested amount to first order.
TEST(PeriodicVolumes, ColumnVolumeAndItsGradient) {
    const double r = 0.2;
    SurfaceMesh tube = testing::periodic_tube(r, Vec3(0.5, 0.5, 0.0), 2, 1.0, 24, 24);
    const VolumeComponents components = volume_components(tube);
    ASSERT_EQ(components.count, 1);
    ASSERT_TRUE(components.closed[0]);
    const double v = component_volumes_at(tube, components, tube.positions())[0];
    const double vx = divergence_volume(tube, tube.positions(), 0);
    const double vy = divergence_volume(tube, tube.positions(), 1);
    EXPECT_NEAR(v, vx, 1e-14);
    EXPECT_NEAR(vx, vy, 1e-14);
    EXPECT_GT(v, 0.97 * M_PI * r * r);
    EXPECT_LT(v, M_PI * r * r);

    std::vector<Vec3> shifted = tube.positions();
    for (Vec3& p : shifted)
        p = tube.periods().wrap(Vec3(p + Vec3(0.0, 0.0, 0.37)));
    EXPECT_NEAR(component_volumes_at(tube, components, shifted)[0], v, 1e-14);

    const double error = 1e-4;
    const std::vector<std::uint8_t> movable(static_cast<size_t>(tube.num_vertices()), 1);
    const std::vector<double> inv_mass(static_cast<size_t>(tube.num_vertices()), 1.0);
    const std::vector<Vec3> delta =
        volume_restoring_displacements(tube, components, shifted, {error}, movable, inv_mass);
    std::vector<Vec3> corrected = shifted;
    for (size_t i = 0; i < corrected.size(); ++i)
        corrected[i] += delta[i];
    EXPECT_NEAR(component_volumes_at(tube, components, corrected)[0] - v, error, 1e-3 * error);
    // Every vertex moves outwards (the seam's rings too).
    for (size_t i = 0; i < corrected.size(); ++i) {
        const Vec3 radial(shifted[i].x() - 0.5, shifted[i].y() - 0.5, 0.0);
        EXPECT_GT(delta[i].dot(radial), 0.0) << "vertex " << i;
    }
}

// ---- the tracker --------------------------------------------------------------------------

/// A column carried along its axis by 1.75 periods in 25 steps: no contact is reported (no
/// false pair across the seam), it stays intersection-free and in the box, its volume does not
/// change, and it ends at its start translated by 0.75 (mod 1).
TEST(PeriodicTracker, ColumnCarriedAlongItsAxisBeyondAPeriod) {
    const SurfaceMesh tube =
        testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 2, 1.0, 16, 16,
                               [](double s) { return 1.0 + 0.2 * std::sin(2.0 * M_PI * s); });
    TrackerOptions o;
    o.improve_mesh = false;
    o.allow_topology_changes = false;
    o.verify_intersection_free = true;
    SurfaceTracker tracker(tube, o);
    const double v0 = divergence_volume(tube, tube.positions(), 0);
    const std::vector<Vec3> velocity(static_cast<size_t>(tube.num_vertices()), Vec3(0, 0, 1.0));
    for (int step = 0; step < 25; ++step) {
        const IntegrateResult r = tracker.integrate(velocity, 0.07);
        EXPECT_EQ(r.intersecting_pairs, 0) << "step " << step;
        EXPECT_EQ(r.collisions.proximities, 0) << "step " << step;
        EXPECT_EQ(r.collisions.collisions_first_sweep, 0) << "step " << step;
        EXPECT_EQ(r.collisions.motion_fraction, 1.0) << "step " << step;
        const SurfaceMesh& m = tracker.mesh();
        for (int v = 0; v < m.num_vertices(); ++v) {
            ASSERT_GE(m.position(v).z(), 0.0);
            ASSERT_LT(m.position(v).z(), 1.0);
        }
        EXPECT_NEAR(divergence_volume(m, m.positions(), 0), v0, 1e-12 * v0) << "step " << step;
    }
    for (int v = 0; v < tube.num_vertices(); ++v) {
        const Vec3 expected = tube.periods().wrap(Vec3(tube.position(v) + Vec3(0, 0, 1.75)));
        EXPECT_LT(tube.periods().difference(tracker.mesh().position(v), expected).norm(), 1e-12);
    }
}

/// The tracker refuses a period shorter than PERIOD_TO_EDGE_RATIO times the longest edge and
/// names the axis; a fine enough mesh is accepted.
TEST(PeriodicTracker, RefusesAPeriodTooShortForTheEdgesAndNamesTheAxis) {
    TrackerOptions o;
    const SurfaceMesh coarse = testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 1, 1.0, 16, 4);
    try {
        SurfaceTracker tracker(coarse, o);
        FAIL() << "a period of 4 rings was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("period along y"), std::string::npos) << e.what();
    }
    const SurfaceMesh fine = testing::periodic_tube(0.2, Vec3(0.5, 0.5, 0.0), 1, 1.0, 16, 16);
    EXPECT_NO_THROW(SurfaceTracker(fine, o));
}

}  // namespace
}  // namespace meniscus::tracker
