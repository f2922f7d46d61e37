/// Topology changes (paper §3.6, §3.7): touching spheres merge into one sphere-like component,
/// a thinning dumbbell pinches into two closed components, and with topology changes off
/// neither genus nor component count ever changes.

#include "remesh_test_meshes.h"

#include "tracker/collision_resolution.h"
#include "tracker/mesh_intersections.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"
#include "tracker/remesh/improve.h"
#include "tracker/topology/change_topology.h"

#include <gtest/gtest.h>

#include <cmath>

namespace meniscus::tracker {
namespace {

std::string violations_text(const std::vector<MeshViolation>& v) {
    std::string s;
    for (const MeshViolation& m : v)
        s += m.message + "; ";
    return s;
}

void expect_valid(const SurfaceMesh& mesh, const char* after) {
    const auto violations = validate_mesh(mesh);
    EXPECT_TRUE(violations.empty()) << after << ": " << violations_text(violations);
    EXPECT_TRUE(is_intersection_free(mesh)) << "intersects after " << after;
}

/// Squeezes the handle of an x-aligned dumbbell towards the x axis: (y, z) scaled by
/// 1 − strength · exp(−(x/width)²). The map is injective for strength < 1, so a surface of
/// revolution stays intersection-free.
void squeeze_handle(SurfaceMesh& mesh, double strength, double width) {
    for (int vi = 0; vi < mesh.num_vertices(); ++vi) {
        if (!mesh.vertex_alive(vi))
            continue;
        Vec3 p = mesh.position(vi);
        const double f = 1.0 - strength * std::exp(-(p.x() / width) * (p.x() / width));
        p.y() *= f;
        p.z() *= f;
        mesh.set_position(vi, p);
    }
}

TEST(Merge, TwoTouchingSpheresBecomeOneSphere) {
    constexpr double RADIUS = 0.2, GAP = 0.002, EDGE = 0.05;
    SurfaceMesh mesh = testing::make_two_spheres(RADIUS, GAP, EDGE);
    expect_valid(mesh, "generation");
    ASSERT_EQ(triangle_components(mesh).count, 2);
    ASSERT_EQ(euler_characteristic(mesh), 4);

    TopologyOptions options;
    TopologyContext context;
    context.xi = testing::mean_edge_length(mesh);
    ASSERT_LT(GAP, options.merge_distance_fraction * context.xi);
    const TopologyReport report = change_topology(mesh, options, context);
    EXPECT_GE(report.merge.merges, 1);
    expect_valid(mesh, "merging");
    EXPECT_EQ(triangle_components(mesh).count, 1);
    EXPECT_EQ(euler_characteristic(mesh), 2);

    // Improvement afterwards keeps it one sphere-like, valid component.
    RemeshOptions remesh;
    ImproveContext improve;
    improve.xi = context.xi;
    improve_mesh(mesh, remesh, improve);
    expect_valid(mesh, "improvement after merging");
    EXPECT_EQ(triangle_components(mesh).count, 1);
    EXPECT_EQ(euler_characteristic(mesh), 2);
}

TEST(Merge, OneContactPatchOpensOneNeckUnlessSpacingIsOff) {
    // Closer than the merge distance over a wide patch: many proximal pairs. The default
    // spacing merges the nearest pair only (one neck, χ = 2); spacing 0 merges every pair it
    // can, as the paper's §3.7 does, and creates handles.
    constexpr double RADIUS = 0.2, GAP = 2e-4, EDGE = 0.05;
    const SurfaceMesh initial = testing::make_two_spheres(RADIUS, GAP, EDGE);
    TopologyOptions options;
    options.merge_distance_fraction = 0.3;
    TopologyContext context;
    context.xi = testing::mean_edge_length(initial);

    SurfaceMesh spaced = initial;
    const TopologyReport r = change_topology(spaced, options, context);
    EXPECT_EQ(r.merge.merges, 1);
    EXPECT_GT(r.merge.deferred_near_merge, 0);
    expect_valid(spaced, "spaced merging");
    EXPECT_EQ(triangle_components(spaced).count, 1);
    EXPECT_EQ(euler_characteristic(spaced), 2);

    SurfaceMesh every = initial;
    options.merge_spacing_fraction = 0.0;
    const TopologyReport all = change_topology(every, options, context);
    EXPECT_GT(all.merge.merges, 1);
    expect_valid(every, "merging every pair");
    EXPECT_EQ(triangle_components(every).count, 1);
    EXPECT_EQ(euler_characteristic(every), 4 - 2 * all.merge.merges);
}

TEST(Merge, SpheresPushedTogetherMergeWhileEveryStepStaysValidAndIntersectionFree) {
    // A small time loop: both spheres are pushed towards each other every step (collision
    // resolution stops them), then improved and merged. Pushing on after contact keeps creating
    // new contacts around the neck, so several zips (handles) are expected; what must hold is
    // admissibility and no intersection after every stage of every step.
    constexpr double RADIUS = 0.2, GAP = 0.03, EDGE = 0.05, PUSH = 0.004;
    SurfaceMesh mesh = testing::make_two_spheres(RADIUS, GAP, EDGE);
    const double xi = testing::mean_edge_length(mesh);
    RemeshOptions remesh;
    ImproveContext improve;
    improve.xi = xi;
    improve.collision.proximity_epsilon = 1e-3 * xi;
    TopologyOptions topology;
    TopologyContext topo_context;
    topo_context.xi = xi;
    int merges = 0;
    constexpr int STEPS = 12;
    for (int step = 0; step < STEPS; ++step) {
        const std::vector<Vec3> x_t0 = mesh.positions();
        std::vector<Vec3> x_t1 = x_t0;
        for (size_t vi = 0; vi < x_t1.size(); ++vi)
            x_t1[vi].x() += x_t0[vi].x() < 0.0 ? PUSH : -PUSH;
        resolve_collisions(mesh, x_t0, x_t1, 1.0, improve.collision);
        mesh.set_positions(x_t1);
        expect_valid(mesh, "the push");
        improve_mesh(mesh, remesh, improve);
        expect_valid(mesh, "improvement");
        merges += change_topology(mesh, topology, topo_context).merge.merges;
        expect_valid(mesh, "topology change");
        mesh.compact();
    }
    EXPECT_GE(merges, 1);
    // One body. A ring of zips around the contact may close over a film of gas and trap it: a
    // separate, inward-facing component (negative volume) that is correct topology, not a
    // failure (with fitted smoothing, step 10 traps a 12-triangle pocket of −1.2e-6 m³).
    const Components components = triangle_components(mesh);
    const std::vector<double> volumes = component_volumes(mesh, components);
    int bodies = 0;
    double body_volume = 0.0, pocket_volume = 0.0;
    for (double v : volumes)
        if (v > 0.0) {
            ++bodies;
            body_volume += v;
        } else {
            pocket_volume -= v;
        }
    EXPECT_EQ(bodies, 1);
    EXPECT_LT(pocket_volume, 1e-3 * body_volume);
}

TEST(Merge, FarApartSpheresDoNotMergeAndMergingOffDoesNothing) {
    SurfaceMesh far = testing::make_two_spheres(0.2, 0.05, 0.05);
    TopologyOptions options;
    TopologyContext context;
    context.xi = testing::mean_edge_length(far);
    EXPECT_EQ(change_topology(far, options, context).merge.merges, 0);
    SurfaceMesh near = testing::make_two_spheres(0.2, 0.002, 0.05);
    options.allow_merging = false;
    EXPECT_EQ(change_topology(near, options, context).merge.merges, 0);
    EXPECT_EQ(triangle_components(near).count, 2);
}

TEST(Separation, ThinningDumbbellPinchesIntoTwoClosedComponents) {
    SurfaceMesh mesh = testing::make_test_dumbbell();
    RemeshOptions remesh;
    ImproveContext improve;
    improve.xi = testing::mean_edge_length(mesh);
    TopologyOptions topology;
    TopologyContext topo_context;
    topo_context.xi = improve.xi;
    constexpr int MAX_STEPS = 60;
    constexpr double STRENGTH = 0.15, WIDTH = 0.12;
    int steps = 0;
    // Right after the pinch the two pieces may still be glued along a non-manifold edge (an
    // admissible state); squeezing on settles them into two sphere-like components.
    while ((triangle_components(mesh).count < 2 || euler_characteristic(mesh) != 4) &&
           steps < MAX_STEPS) {
        squeeze_handle(mesh, STRENGTH, WIDTH);
        ASSERT_TRUE(is_intersection_free(mesh)) << "the squeeze itself intersected";
        improve_mesh(mesh, remesh, improve);
        expect_valid(mesh, "improvement");
        change_topology(mesh, topology, topo_context);
        expect_valid(mesh, "topology change");
        ++steps;
    }
    mesh.compact();
    const Components components = triangle_components(mesh);
    EXPECT_EQ(components.count, 2) << "after " << steps << " steps";
    // Two closed sphere-like pieces: χ = 2 each.
    EXPECT_EQ(euler_characteristic(mesh), 4);
    expect_valid(mesh, "pinch-off");
    for (double v : component_volumes(mesh, components))
        EXPECT_GT(v, 0.0);
}

TEST(TopologyOff, SqueezedDumbbellAndNearSpheresKeepGenusAndComponents) {
    SurfaceMesh dumbbell = testing::make_test_dumbbell();
    RemeshOptions remesh;
    ImproveContext improve;
    improve.xi = testing::mean_edge_length(dumbbell);
    improve.allow_topology_changes = false;
    constexpr int STEPS = 25;
    for (int step = 0; step < STEPS; ++step) {
        squeeze_handle(dumbbell, 0.15, 0.12);
        if (!is_intersection_free(dumbbell))
            break;  // the squeeze (not the remesher) would tangle a collapsed neck
        improve_mesh(dumbbell, remesh, improve);
        expect_valid(dumbbell, "improvement with topology changes off");
        EXPECT_EQ(triangle_components(dumbbell).count, 1);
        EXPECT_EQ(euler_characteristic(dumbbell), 2);
    }

    SurfaceMesh torus = testing::make_test_torus();
    improve.xi = 1.8 * testing::mean_edge_length(torus);  // coarsen hard: many collapses
    for (int step = 0; step < 3; ++step) {
        improve_mesh(torus, remesh, improve);
        expect_valid(torus, "coarsening a torus with topology changes off");
    }
    EXPECT_EQ(euler_characteristic(torus), 0);
    EXPECT_EQ(triangle_components(torus).count, 1);

    SurfaceMesh spheres = testing::make_two_spheres(0.2, 0.002, 0.05);
    improve.xi = testing::mean_edge_length(spheres);
    improve_mesh(spheres, remesh, improve);
    EXPECT_EQ(triangle_components(spheres).count, 2);
    EXPECT_EQ(euler_characteristic(spheres), 4);
}

TEST(Separation, RemovesDegenerateTetrahedraAndSplitsSingularVertices) {
    // Two tetrahedra sharing one vertex (a singular vertex), plus a duplicated pair of faces.
    std::vector<Vec3> p = {{0, 0, 0},  {1, 0, 0},  {0, 1, 0}, {0, 0, 1},
                           {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
    std::vector<Triangle> t = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3},
                               {0, 4, 5}, {0, 6, 4}, {0, 5, 6}, {4, 6, 5}};
    SurfaceMesh mesh(p, t);
    ASSERT_TRUE(validate_mesh(mesh).empty());
    const SeparationReport r = separate(mesh, SeparationOptions{}, true, 0.5);
    EXPECT_EQ(r.singular_vertices_split, 1);
    EXPECT_EQ(r.copies_created, 1);
    EXPECT_EQ(vertex_fans(mesh, 0).size(), 1u);
    EXPECT_TRUE(validate_mesh(mesh).empty());
    EXPECT_TRUE(is_intersection_free(mesh));
    EXPECT_EQ(triangle_components(mesh).count, 2);

    // A degenerate tetrahedron: triangles (0,1,2) and (0,2,1) as a whole component.
    SurfaceMesh flat({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 1}});
    const SeparationReport f = separate(flat, SeparationOptions{}, true, 0.5);
    EXPECT_EQ(f.degenerate_tetrahedra_removed, 1);
    EXPECT_EQ(f.orphan_vertices_removed, 3);
    EXPECT_EQ(flat.count_live_triangles(), 0);
}

TEST(Separation, LooksAgainAtWhatChangedSinceTheLastPass) {
    // separate() only looks at the vertices and triangles that the mesh marked as changed since
    // its last pass. Two disjoint tetrahedra, separated once (nothing to do, marks cleared); then
    // tetrahedron B is rewired onto A's vertex 0 by add/remove_triangle alone, which must make
    // vertex 0 a singular vertex that the next pass finds and splits.
    std::vector<Vec3> p = {{0, 0, 0},  {1, 0, 0},  {0, 1, 0},  {0, 0, 1},
                           {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}, {0, 0, 0}};
    std::vector<Triangle> t = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3},
                               {7, 4, 5}, {7, 6, 4}, {7, 5, 6}, {4, 6, 5}};
    SurfaceMesh mesh(p, t);
    const SeparationReport first = separate(mesh, SeparationOptions{}, false, 0.5);
    EXPECT_EQ(first.singular_vertices_split, 0);
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        EXPECT_FALSE(mesh.vertex_marked(vi)) << "regular vertex " << vi << " kept its mark";
    for (int ti : std::vector<int>(mesh.vertex_triangles(7))) {
        Triangle tri = mesh.triangle(ti);
        for (int& v : tri)
            v = v == 7 ? 0 : v;
        mesh.remove_triangle(ti);
        mesh.add_triangle(tri);
    }
    const SeparationReport second = separate(mesh, SeparationOptions{}, false, 0.5);
    EXPECT_EQ(second.orphan_vertices_removed, 1);  // vertex 7
    EXPECT_EQ(second.singular_vertices_split, 1);
    EXPECT_EQ(vertex_fans(mesh, 0).size(), 1u);
    EXPECT_TRUE(validate_mesh(mesh).empty());
    EXPECT_EQ(triangle_components(mesh).count, 2);

    // A triangle added against an old one of the opposite orientation (unmarked, from before the
    // last pass) is a degenerate tetrahedron: both go.
    const Triangle old = mesh.triangle(mesh.vertex_triangles(1)[0]);
    const int old_ti = mesh.vertex_triangles(1)[0];
    const int added = mesh.add_triangle({old[0], old[2], old[1]});
    const SeparationReport third = separate(mesh, SeparationOptions{}, false, 0.5);
    EXPECT_EQ(third.degenerate_tetrahedra_removed, 1);
    EXPECT_FALSE(mesh.triangle_alive(old_ti));
    EXPECT_FALSE(mesh.triangle_alive(added));
}

TEST(Separation, SplitsTwoSheetsThatShareAnEdge) {
    // Regression (issue #5): a dumbbell neck refined to an eighth of α and β (ξ = 0.02) collapsed
    // into two sheets sharing an edge of 4e-5 m with four triangles. Its triangles all counted as
    // one fan, so its vertices were never split, no collapse could remove it, and the CFL step
    // of 0.1·(4e-5)² stalled the flow at the pinch. Two cubes sharing an edge are the same
    // configuration: separation must pull them apart.
    SurfaceMesh cubes = testing::make_test_edge_sharing_cubes();
    int nonmanifold = 0;
    for (int ei = 0; ei < cubes.num_edges(); ++ei)
        nonmanifold += cubes.edge_alive(ei) && cubes.is_nonmanifold_edge(ei) ? 1 : 0;
    ASSERT_GT(nonmanifold, 0);
    ASSERT_EQ(triangle_components(cubes).count, 1);
    const double volume = enclosed_volume(cubes);
    const SeparationReport r = separate(cubes, SeparationOptions{}, true, 0.1);
    EXPECT_EQ(r.refused_intersection, 0);
    EXPECT_EQ(r.singular_vertices_split, nonmanifold + 1);  // the shared edge's vertices
    for (int ei = 0; ei < cubes.num_edges(); ++ei)
        EXPECT_FALSE(cubes.edge_alive(ei) && cubes.is_nonmanifold_edge(ei)) << "edge " << ei;
    EXPECT_TRUE(validate_mesh(cubes).empty());
    EXPECT_TRUE(is_intersection_free(cubes));
    EXPECT_EQ(triangle_components(cubes).count, 2);
    EXPECT_EQ(euler_characteristic(cubes), 4);  // two spheres
    EXPECT_NEAR(enclosed_volume(cubes), volume, 1e-3 * volume);

    // A manifold mesh keeps one fan per vertex.
    SurfaceMesh sphere = testing::make_test_sphere();
    const SeparationReport none = separate(sphere, SeparationOptions{}, true, 0.1);
    EXPECT_EQ(none.singular_vertices_split, 0);
}

TEST(OpenSurfaces, BoundaryTakesPartInNoMerge) {
    // An open cap next to a sphere: boundary edges never take part in merges.
    SurfaceMesh cap = testing::make_test_open_cap();
    TopologyOptions options;
    TopologyContext context;
    context.xi = testing::mean_edge_length(cap);
    const TopologyReport r = change_topology(cap, options, context);
    EXPECT_EQ(r.merge.merges, 0);
    ValidationOptions vo;
    vo.allow_boundary = true;
    EXPECT_TRUE(validate_mesh(cap, vo).empty());
}

}  // namespace
}  // namespace meniscus::tracker
