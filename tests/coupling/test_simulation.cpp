#include "coupling/simulation.h"
#include "tracker/implicit_mesher.h"
#include "tracker/mesh_intersections.h"
#include "tracker/mesh_measures.h"

#include <gtest/gtest.h>

namespace meniscus::coupling {
namespace {

using tracker::Vec3;

tracker::SurfaceMesh drops(const std::vector<std::pair<Vec3, double>>& spheres, double h) {
    std::vector<Vec3> x;
    std::vector<tracker::Triangle> t;
    for (const auto& [c, r] : spheres) {
        tracker::ImplicitMeshOptions o;
        o.edge_length = h;
        const tracker::SurfaceMesh m = tracker::mesh_implicit_shape(*tracker::make_sphere(c, r), o);
        const int offset = static_cast<int>(x.size());
        x.insert(x.end(), m.positions().begin(), m.positions().end());
        for (int ti = 0; ti < m.num_triangles(); ++ti) {
            tracker::Triangle tri = m.triangle(ti);
            for (int& v : tri)
                v += offset;
            t.push_back(tri);
        }
    }
    return tracker::SurfaceMesh(x, t);
}

fluid::FluidOptions weightless() {
    fluid::FluidOptions o;
    o.gravity = Eigen::Vector3d::Zero();
    return o;
}

TEST(Simulation, StaticDropKeepsVolumeAndStaysStill) {
    // 1 cm box, 20 cells, a 3 mm radius water drop in air: 12 cells per diameter.
    const double L = 0.01, R = 0.003;
    const int n = 20;
    tracker::TrackerOptions to;
    to.verify_intersection_free = true;
    Simulation sim(tracker::SurfaceTracker(drops({{Vec3::Constant(L / 2), R}}, L / n), to),
                   fluid::FluidSolver(n, n, n, L / n, Vec3::Zero(), weightless()),
                   SimulationOptions{});
    const double v0 = tracker::enclosed_volume(sim.tracker().mesh());
    double max_speed = 0.0;
    for (int step = 0; step < 5; ++step) {
        const SimulationStepReport r = sim.step(1.0);
        ASSERT_TRUE(r.fluid.pressure.converged) << "step " << step;
        ASSERT_EQ(r.integrate.intersecting_pairs, 0) << "step " << step;
        EXPECT_EQ(r.limit, StepLimit::capillary);  // nothing moves: surface tension sets Δt
        max_speed = std::max(max_speed, r.max_vertex_speed);
    }
    EXPECT_NEAR(tracker::enclosed_volume(sim.tracker().mesh()), v0, 0.005 * v0);
    // Spurious currents stay far below the capillary velocity σ/μ (≈ 73 m/s) and the
    // Laplace-pressure velocity sqrt(2σ/(ρR)) (≈ 0.22 m/s).
    EXPECT_LT(max_speed, 0.01);
    EXPECT_GT(sim.time(), 0.0);
}

TEST(Simulation, TouchingDropsMergeAndKeepTheirVolume) {
    const double L = 0.01, R = 0.0022, h = L / 20;
    // A gap of 5 % of an edge: below the merge distance (10 %), so they zip on the first step.
    const double gap = 0.05 * h;
    tracker::TrackerOptions to;
    to.verify_intersection_free = true;
    Simulation sim(tracker::SurfaceTracker(drops({{Vec3(L / 2 - R - gap / 2, L / 2, L / 2), R},
                                                  {Vec3(L / 2 + R + gap / 2, L / 2, L / 2), R}},
                                                 h),
                                           to),
                   fluid::FluidSolver(20, 20, 20, h, Vec3::Zero(), weightless()),
                   SimulationOptions{});
    const double v0 = tracker::enclosed_volume(sim.tracker().mesh());
    ASSERT_EQ(tracker::triangle_components(sim.tracker().mesh()).count, 2);
    int merges = 0;
    for (int step = 0; step < 4; ++step) {
        const SimulationStepReport r = sim.step(1.0);
        ASSERT_EQ(r.integrate.intersecting_pairs, 0) << "step " << step;
        merges += r.volume.merges;
    }
    EXPECT_EQ(tracker::triangle_components(sim.tracker().mesh()).count, 1);
    EXPECT_GE(merges, 1);
    EXPECT_NEAR(tracker::enclosed_volume(sim.tracker().mesh()), v0, 0.005 * v0);
    EXPECT_GT(sim.kinetic_energy(), 0.0);  // the merged neck pulls: the fluid moves
}

}  // namespace
}  // namespace meniscus::coupling
