// Checkpoint state of the mesh and the tracker (issue 38): a saved state loads back into any
// mesh and gives the same bytes and the same later operations; damaged state is refused.
#include "common/binary_io.h"
#include "flow_test_meshes.h"
#include "tracker/mesh.h"
#include "tracker/mesh_validate.h"
#include "tracker/surface_tracker.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace meniscus::tracker {
namespace {

SurfaceMesh tetrahedron() {
    return SurfaceMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                       {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
}

std::string saved(const SurfaceMesh& mesh) {
    BinaryWriter out;
    mesh.save_state(out);
    return out.bytes();
}

std::string saved(const SurfaceTracker& tracker) {
    BinaryWriter out;
    tracker.save_state(out);
    return out.bytes();
}

/// A millimetre sphere after a few tracked steps: dead slots, labels and changed adjacency.
SurfaceTracker stepped_sphere() {
    SurfaceTracker tracker(testing::meshed_sphere({0, 0, 0}, 1e-3, 2e-4), TrackerOptions{});
    for (int step = 0; step < 3; ++step) {
        std::vector<Vec3> v(static_cast<size_t>(tracker.mesh().num_vertices()));
        for (int i = 0; i < tracker.mesh().num_vertices(); ++i) {
            const Vec3& p = tracker.mesh().position(i);
            v[static_cast<size_t>(i)] = Vec3(-p.y(), p.x(), 0.3 * p.z()) * 50.0;
        }
        tracker.integrate(v, 1e-3);
        tracker.improve();
        tracker.change_topology();
    }
    return tracker;
}

TEST(MeshState, LoadsBackIntoAnyMeshWithTheSameBytes) {
    const SurfaceMesh original = stepped_sphere().mesh();
    const std::string bytes = saved(original);
    SurfaceMesh restored = tetrahedron();
    BinaryReader in(bytes.data(), bytes.size());
    restored.load_state(in);
    EXPECT_TRUE(in.at_end());
    EXPECT_TRUE(saved(restored) == bytes) << "the restored state saves different bytes";
    EXPECT_TRUE(validate_mesh(restored).empty());
    ASSERT_EQ(restored.num_vertices(), original.num_vertices());
    for (int i = 0; i < original.num_vertices(); ++i) {
        EXPECT_EQ(restored.position(i), original.position(i)) << "vertex " << i;
        // The separation marks are not saved: all set, the next pass looks at everything.
        EXPECT_TRUE(restored.vertex_marked(i)) << "vertex " << i;
    }
}

TEST(MeshState, TruncatedStateIsRefusedLeavingTheMeshUnchanged) {
    const std::string bytes = saved(stepped_sphere().mesh());
    const std::string before = saved(tetrahedron());
    for (size_t cut = 0; cut < bytes.size(); cut += 1 + bytes.size() / 97) {
        SurfaceMesh mesh = tetrahedron();
        const std::string part = bytes.substr(0, cut);
        BinaryReader in(part.data(), part.size());
        EXPECT_THROW(mesh.load_state(in), FormatError) << "cut at byte " << cut;
        EXPECT_TRUE(saved(mesh) == before) << "cut at byte " << cut << " changed the mesh";
    }
}

TEST(TrackerState, RestoredTrackerTakesItsProximityFromTheSavedXi) {
    // Bug found by the SIGKILL resume test: a resumed fluid run builds its tracker on a unit
    // tetrahedron and loads the millimetre state into it; ε_p stayed 1e-3 × the tetrahedron's
    // ξ (1e-3 m, the size of the drop), and the broad phase paired every edge with every edge.
    const SurfaceTracker original = stepped_sphere();
    SurfaceTracker restored(tetrahedron(), TrackerOptions{});
    const std::string bytes = saved(original);
    BinaryReader in(bytes.data(), bytes.size());
    restored.load_state(in);
    EXPECT_EQ(restored.characteristic_length(), original.characteristic_length());
    EXPECT_EQ(restored.options().collision.proximity_epsilon,
              original.options().collision.proximity_epsilon);
    EXPECT_TRUE(saved(restored) == bytes) << "the restored state saves different bytes";
}

TEST(TrackerState, RestoredTrackerStepsExactlyAsTheOriginal) {
    SurfaceTracker original = stepped_sphere();
    SurfaceTracker restored(tetrahedron(), TrackerOptions{});
    const std::string bytes = saved(original);
    BinaryReader in(bytes.data(), bytes.size());
    restored.load_state(in);
    for (SurfaceTracker* t : {&original, &restored}) {
        std::vector<Vec3> v(static_cast<size_t>(t->mesh().num_vertices()));
        for (int i = 0; i < t->mesh().num_vertices(); ++i)
            v[static_cast<size_t>(i)] = Vec3(0.0, 0.0, -t->mesh().position(i).z()) * 400.0;
        t->integrate(v, 1e-3);
        t->improve();
        t->change_topology();
    }
    EXPECT_TRUE(saved(restored) == saved(original)) << "the two trackers diverged";
}

}  // namespace
}  // namespace meniscus::tracker
