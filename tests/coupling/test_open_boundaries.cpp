// The interface mesh at open faces of the box (coupling/open_boundaries.h): a drop carried out
// through an outflow face is clipped off cleanly with its volume accounted; a jet fed through an
// inflow disc grows from the nozzle's rim by the volume that flows in.
#include "coupling/open_boundaries.h"
#include "coupling/simulation.h"
#include "tracker/implicit_mesher.h"
#include "tracker/implicit_shape.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace meniscus::coupling {
namespace {

using tracker::Vec3;

constexpr double DX = 2.5e-4;  ///< m: 0.25 mm cells

tracker::SurfaceMesh meshed(const tracker::ShapePtr& shape, double edge) {
    tracker::ImplicitMeshOptions o;
    o.edge_length = edge;
    return tracker::mesh_implicit_shape(*shape, o);
}

/// Water and air, no gravity, free-slip walls but for the faces the test opens.
fluid::FluidOptions water_in_air() {
    fluid::FluidOptions o;
    o.gravity = Eigen::Vector3d::Zero();
    return o;
}

TEST(OpenBoundaries, DropCarriedOutThroughAnOutflowFaceIsRemovedCleanly) {
    // A 1.25 mm water drop in an air stream of 0.5 m/s along x (gas inflow over the whole x_min
    // face, outflow at x_max) in a box of 32 × 16 × 16 cells: it drifts out through x_max.
    const double speed = 0.5, radius = 1.25e-3;
    fluid::FluidOptions options = water_in_air();
    options.boundaries.x_min.type = fluid::BoundaryType::inflow;
    options.boundaries.x_min.inflow.speed = speed;
    options.boundaries.x_min.inflow.phase = fluid::InflowPhase::gas;
    options.boundaries.x_max.type = fluid::BoundaryType::outflow;
    fluid::FluidSolver solver(32, 16, 16, DX, Vec3::Zero(), options);
    solver.grid().u().fill(speed);  // the stream is already running
    tracker::TrackerOptions to;
    to.verify_intersection_free = true;
    Simulation sim(tracker::SurfaceTracker(
                       meshed(tracker::make_sphere(Vec3(5.5e-3, 2e-3, 2e-3), radius), DX), to),
                   std::move(solver), SimulationOptions{});
    const double v0 = tracker::enclosed_volume(sim.tracker().mesh());
    int removed = 0, clips = 0, steps = 0;
    double worst_balance = 0.0;
    while (sim.tracker().mesh().count_live_triangles() > 0 && steps < 400) {
        const SimulationStepReport r = sim.step(1.0);
        ++steps;
        ASSERT_EQ(r.integrate.intersecting_pairs, 0) << "step " << steps;
        ASSERT_TRUE(r.open_boundaries.deferred.empty()) << r.open_boundaries.deferred;
        ASSERT_TRUE(tracker::validate_mesh(sim.tracker().mesh()).empty()) << "step " << steps;
        removed += r.open_boundaries.components_removed;
        clips += r.open_boundaries.clips;
        // What is left plus what left is what there was.
        const double balance =
            tracker::enclosed_volume(sim.tracker().mesh()) + sim.boundary_volumes().liquid_out;
        worst_balance = std::max(worst_balance, std::abs(balance - v0) / v0);
        for (int vi = 0; vi < sim.tracker().mesh().num_vertices(); ++vi) {
            if (sim.tracker().mesh().vertex_alive(vi)) {
                ASSERT_LT(sim.tracker().mesh().position(vi).x(), 32 * DX + 4.0 * DX);  // + a step
            }
        }
    }
    std::printf(
        "[ measured ] drop through an outflow face: %d steps, %d clips, liquid out %.4e "
        "of %.4e m^3, worst |left + out - start| / start %.2e\n",
        steps, clips, sim.boundary_volumes().liquid_out, v0, worst_balance);
    EXPECT_EQ(sim.tracker().mesh().count_live_triangles(), 0);  // gone, in a finite time
    EXPECT_EQ(removed, 1);
    EXPECT_GT(clips, 3);  // cut slice by slice, not dropped whole
    EXPECT_NEAR(sim.boundary_volumes().liquid_out, v0, 5e-3 * v0);
    EXPECT_LT(worst_balance, 5e-3);
    EXPECT_EQ(sim.boundary_volumes().liquid_in, 0.0);
    EXPECT_GT(sim.boundary_volumes().gas_in, 0.0);
    // The empty box keeps stepping (everything gas).
    EXPECT_NO_THROW(sim.step(1.0));
}

TEST(OpenBoundaries, JetGrowsFromTheNozzleRimByTheVolumeThatFlowsIn) {
    // Water through a disc of radius 0.75 mm (3 cells) in the x_min face at 1 m/s into air (Weber
    // number ρU²R/σ = 10: a jet, not a drop growing at the nozzle); the jet starts as a short
    // rounded column reaching 3 cells behind the face (the nozzle's part).
    const double speed = 1.0, radius = 7.5e-4, duration = 3e-3;
    const Vec3 centre(0.0, 2e-3, 2e-3);
    fluid::FluidOptions options = water_in_air();
    options.boundaries.x_min.type = fluid::BoundaryType::inflow;
    options.boundaries.x_min.inflow.speed = speed;
    options.boundaries.x_min.inflow.region = fluid::InflowRegion::disc;
    options.boundaries.x_min.inflow.centre = centre;
    options.boundaries.x_min.inflow.radius = radius;
    options.boundaries.x_max.type = fluid::BoundaryType::outflow;
    fluid::FluidSolver solver(32, 16, 16, DX, Vec3::Zero(), options);
    const tracker::ShapePtr jet = tracker::make_union(
        {tracker::make_cylinder(Vec3(0.0, centre.y(), centre.z()), Vec3::UnitX(), radius, 6 * DX),
         tracker::make_sphere(Vec3(3 * DX, centre.y(), centre.z()), radius)});
    // The liquid already moves with the nozzle's speed (an impulsive start instead spreads it
    // radially: the impulse pressure vanishes on the surface, so the flow leaves the blob where
    // its surface is nearest the disc, at the rim).
    for (int k = 0; k < solver.grid().u().nk(); ++k)
        for (int j = 0; j < solver.grid().u().nj(); ++j)
            for (int i = 0; i < solver.grid().u().ni(); ++i)
                if (jet->value(solver.grid().face_centre(0, i, j, k)) < 0.0)
                    solver.grid().u()(i, j, k) = speed;
    tracker::TrackerOptions to;
    to.verify_intersection_free = true;
    Simulation sim(tracker::SurfaceTracker(meshed(jet, DX), to), std::move(solver),
                   SimulationOptions{});
    const tracker::SurfaceMesh& mesh = sim.tracker().mesh();
    const double v0 = tracker::enclosed_volume(mesh);
    const auto tip = [&]() {
        double x = -1.0;
        for (int vi = 0; vi < mesh.num_vertices(); ++vi)
            if (mesh.vertex_alive(vi))
                x = std::max(x, mesh.position(vi).x());
        return x;
    };
    const double tip0 = tip();
    double back = 0.0;  // the pipe's end, behind the face
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        if (mesh.vertex_alive(vi))
            back = std::min(back, mesh.position(vi).x());
    int unfed = 0;
    while (sim.time() < duration) {
        const SimulationStepReport r = sim.step(duration - sim.time());
        ASSERT_EQ(r.integrate.intersecting_pairs, 0) << "t = " << sim.time();
        unfed += r.open_boundaries.unfed_inflows;
    }
    const double grown = tracker::enclosed_volume(mesh) - v0;
    const double entered = sim.boundary_volumes().liquid_in;
    const double expected = speed * M_PI * radius * radius * duration;
    std::printf(
        "[ measured ] jet from a nozzle after %.0f ms: volume grew %.4e m^3, %.4e flowed "
        "in (%.4e = speed x area x time); tip %.3f -> %.3f mm\n",
        duration * 1e3, grown, entered, expected, tip0 * 1e3, tip() * 1e3);
    EXPECT_EQ(unfed, 0);
    EXPECT_NEAR(entered, expected, 5e-3 * expected);  // the rim faces carry their share
    EXPECT_NEAR(grown, entered, 0.01 * entered);
    EXPECT_GT(tip() - tip0, 0.5 * speed * duration);  // the jet advances
    // The nozzle's part keeps its place and shape: behind the face, the mesh is the pipe's
    // cylinder of the disc's radius, back to where it started.
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi) || mesh.position(vi).x() >= 0.0)
            continue;
        const Vec3& p = mesh.position(vi);
        EXPECT_GE(p.x(), back - 1e-12);
        if (p.x() > -2.5 * DX) {  // the side of the pipe, not its end cap
            EXPECT_NEAR(std::hypot(p.y() - centre.y(), p.z() - centre.z()), radius, 0.05 * radius);
        }
    }
    EXPECT_TRUE(tracker::validate_mesh(mesh).empty());
    EXPECT_EQ(tracker::triangle_components(mesh).count, 1);
}

TEST(OpenBoundaries, HeldVerticesAreThoseBeyondAnInflowFace) {
    const fluid::MacGrid grid(4, 4, 4, 1.0);
    fluid::BoundaryOptions b;
    b.z_min.type = fluid::BoundaryType::inflow;
    b.z_max.type = fluid::BoundaryType::outflow;
    const tracker::SurfaceMesh mesh({Vec3(1, 1, -0.5), Vec3(2, 1, 0.5), Vec3(1, 2, 4.5)},
                                    {{0, 1, 2}});
    const std::vector<std::uint8_t> held = held_vertices(mesh, grid, b);
    EXPECT_EQ(held, (std::vector<std::uint8_t>{1, 0, 0}));  // beyond the outflow: not held
}

}  // namespace
}  // namespace meniscus::coupling
