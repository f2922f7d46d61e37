// make_edge_manifold(): meshes the tracker admits (non-manifold edges with an even number of
// consistently oriented triangles, singular vertices) become closed edge-manifold surfaces for
// files, without moving the surface.
#include "tracker/mesh_io.h"
#include "tracker/mesh_measures.h"
#include "tracker/mesh_validate.h"
#include "tracker/topology/separate.h"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>
#include <utility>

namespace meniscus::tracker {
namespace {

SurfaceMesh load(const std::string& name) {
    return to_surface_mesh(read_mesh_file(std::string(MENISCUS_TEST_DATA_DIR) + "/" + name), name);
}

int count_nonmanifold_edges(const SurfaceMesh& mesh) {
    int n = 0;
    for (int ei = 0; ei < mesh.num_edges(); ++ei)
        n += mesh.edge_alive(ei) && mesh.is_nonmanifold_edge(ei) ? 1 : 0;
    return n;
}

/// Closed, edge-manifold and consistently oriented: every directed edge (a, b) of a live
/// triangle appears exactly once and its reverse (b, a) exactly once; every live vertex has one
/// fan. Checked on the triangle list alone, not on the mesh's own adjacency.
void expect_closed_edge_manifold(const SurfaceMesh& mesh) {
    std::map<std::pair<int, int>, int> directed;
    for (int ti = 0; ti < mesh.num_triangles(); ++ti) {
        if (!mesh.triangle_alive(ti))
            continue;
        const Triangle& t = mesh.triangle(ti);
        for (int k = 0; k < 3; ++k)
            ++directed[{t[k], t[(k + 1) % 3]}];
    }
    int bad = 0;
    for (const auto& [edge, count] : directed) {
        const auto reverse = directed.find({edge.second, edge.first});
        bad += count != 1 || reverse == directed.end() || reverse->second != 1 ? 1 : 0;
    }
    EXPECT_EQ(bad, 0) << "directed edges not paired exactly once with their reverse";
    int singular = 0;
    for (int vi = 0; vi < mesh.num_vertices(); ++vi)
        singular += mesh.vertex_alive(vi) && vertex_fans(mesh, vi).size() > 1 ? 1 : 0;
    EXPECT_EQ(singular, 0) << "vertices with more than one fan";
    EXPECT_TRUE(validate_mesh(mesh).empty());
}

/// Every vertex of `after` sits where a vertex of `before` was, or at the midpoint of an edge
/// of `before` (the split non-manifold edges).
void expect_nothing_moved(const SurfaceMesh& before, const SurfaceMesh& after,
                          const EdgeManifoldReport& report) {
    for (int vi = 0; vi < before.num_vertices(); ++vi)
        if (before.vertex_alive(vi)) {
            EXPECT_EQ(after.position(vi), before.position(vi));
        }
    for (const AddedVertex& a : report.added) {
        const Vec3 expected = (1.0 - a.s) * after.position(a.from0) + a.s * after.position(a.from1);
        EXPECT_EQ(after.position(a.vi), expected);
    }
}

TEST(EdgeManifold, CubesSharingAnEdgeBecomeTwoSurfaces) {
    const SurfaceMesh before = load("edge_sharing_cubes.obj");
    ASSERT_GT(count_nonmanifold_edges(before), 0);
    SurfaceMesh after = before;
    const EdgeManifoldReport report = make_edge_manifold(after);
    EXPECT_EQ(report.nonmanifold_edges, count_nonmanifold_edges(before));
    EXPECT_GT(report.vertices_split, 0);
    EXPECT_EQ(count_nonmanifold_edges(after), 0);
    expect_closed_edge_manifold(after);
    expect_nothing_moved(before, after, report);
    EXPECT_EQ(triangle_components(after).count, 2);
    EXPECT_NEAR(enclosed_volume(after), enclosed_volume(before), 1e-14);
}

TEST(EdgeManifold, PinchedNeckWhoseEndpointsHaveOneFanIsSplitAtItsMidpoint) {
    // Regression: drop_merge frame 9 (written in mm) as the tracker left it: three edges with
    // four triangles each at the merge neck, where a thin air gap is pinched shut along an edge
    // and opens again around both endpoints — so each endpoint's triangles form ONE fan and
    // splitting singular vertices alone changes nothing (the PLY had 3 edges in 4 triangles).
    const SurfaceMesh before = load("regression/drop_merge_frame9_nonmanifold.ply");
    ASSERT_EQ(count_nonmanifold_edges(before), 3);
    for (int ei = 0; ei < before.num_edges(); ++ei)
        if (before.edge_alive(ei) && before.is_nonmanifold_edge(ei)) {
            EXPECT_EQ(vertex_fans(before, before.edge(ei)[0]).size(), 1u);
            EXPECT_EQ(vertex_fans(before, before.edge(ei)[1]).size(), 1u);
        }
    SurfaceMesh after = before;
    const EdgeManifoldReport report = make_edge_manifold(after);
    EXPECT_EQ(report.nonmanifold_edges, 3);
    EXPECT_EQ(report.vertices_split, 3);  // the three midpoints
    EXPECT_EQ(count_nonmanifold_edges(after), 0);
    expect_closed_edge_manifold(after);
    expect_nothing_moved(before, after, report);
    const double v0 = enclosed_volume(before);
    EXPECT_NEAR(enclosed_volume(after), v0, 1e-12 * v0);
}

TEST(EdgeManifold, ManifoldMeshIsUnchanged) {
    const SurfaceMesh before = load("torus.obj");
    SurfaceMesh after = before;
    const EdgeManifoldReport report = make_edge_manifold(after);
    EXPECT_EQ(report.nonmanifold_edges, 0);
    EXPECT_EQ(report.vertices_split, 0);
    EXPECT_TRUE(report.added.empty());
    EXPECT_EQ(after.num_vertices(), before.num_vertices());
    EXPECT_EQ(after.count_live_triangles(), before.count_live_triangles());
}

}  // namespace
}  // namespace meniscus::tracker
