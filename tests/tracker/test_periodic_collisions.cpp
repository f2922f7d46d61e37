// Periodic meshes (issue 39): the collision pipeline sees the images across the box's faces —
// broad phase, CCD and repulsion, impact zones, the static intersection test, volumes, and the
// SurfaceTracker's wrapping and period check.
#include "periodic_meshes.h"

#include "tracker/broadphase.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
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

}  // namespace
}  // namespace meniscus::tracker
