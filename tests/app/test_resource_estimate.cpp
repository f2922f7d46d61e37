// The run's estimates before it allocates: every shipped scene fits the defaults, and the
// estimates follow the scaling laws they are built on.
#include "app/resource_estimate.h"
#include "app/run.h"
#include "app/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

namespace meniscus::app {
namespace {

SurfaceSize surface_size(const Scene& scene) {
    if (scene.shape) {
        SurfaceSize s = shape_surface_size(scene);
        s.bounds = scene.shape->bounds();
        return s;
    }
    // Shipped mesh files are small: the estimate from the file's area and triangle count.
    SurfaceSize s;
    s.from_mesh_file = true;
    s.triangles = 1000.0;
    s.area = 0.25;
    return s;
}

double frame_time(const Scene& scene) {
    return scene.time.end / scene.time.frames;
}

TEST(ResourceEstimate, EveryShippedSceneFitsTheDefaultLimits) {
    ResourceLimits limits;
    limits.max_memory_bytes = 2e9;  // below any machine that runs the suite
    int count = 0;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(
             std::string(MENISCUS_SOURCE_DIR) + "/scenes")) {
        if (entry.path().extension() != ".json")
            continue;
        ++count;
        const Scene scene = load_scene(entry.path().string());
        const ResourceEstimate e = estimate_resources(scene, surface_size(scene), frame_time(scene));
        EXPECT_NO_THROW(check_resources(scene, e, limits)) << entry.path();
        EXPECT_NO_THROW(check_scene_scale(scene)) << entry.path();
        EXPECT_GT(e.memory_bytes(), 0.0) << entry.path();
        EXPECT_GT(e.steps_per_frame, 0.0) << entry.path();
    }
    EXPECT_GT(count, 30);
}

double part(const ResourceEstimate& e, const std::string& prefix) {
    for (const MemoryPart& p : e.memory)
        if (p.what.rfind(prefix, 0) == 0)
            return p.bytes;
    return 0.0;
}

TEST(ResourceEstimate, FollowsGridMeshAndCapillaryScaling) {
    Scene scene = load_scene(std::string(MENISCUS_SOURCE_DIR) + "/scenes/drop_merge.json");
    const ResourceEstimate base = estimate_resources(scene, surface_size(scene), frame_time(scene));
    // Twice the cells along every axis: eight times the grid.
    Scene fine = scene;
    fine.domain.cells *= 2;
    fine.surface.edge_length *= 0.5;
    const ResourceEstimate finer = estimate_resources(fine, surface_size(fine), frame_time(fine));
    EXPECT_NEAR(part(finer, "fluid grid") / part(base, "fluid grid"), 8.0, 0.5);
    // Half the edge length: four times the triangles.
    EXPECT_NEAR(finer.initial_triangles / base.initial_triangles, 4.0, 1e-9);
    // Capillary limit sqrt(ρ h³ / (2πσ)): 4σ halves the step, doubling the steps (at rest, so
    // that no CFL steps add to them).
    scene.initial_velocity.clear();
    const ResourceEstimate resting = estimate_resources(scene, surface_size(scene), frame_time(scene));
    Scene stiff = scene;
    stiff.fluid.phases.sigma *= 4.0;
    const ResourceEstimate stiffer = estimate_resources(stiff, surface_size(stiff), frame_time(stiff));
    EXPECT_NEAR(stiffer.steps_per_frame / resting.steps_per_frame, 2.0, 1e-6);
    EXPECT_NE(stiffer.step_limit.find("capillary"), std::string::npos);
}

TEST(ResourceEstimate, RefusalsNameTheOptionThatRaisesTheLimit) {
    Scene scene = load_scene(std::string(MENISCUS_SOURCE_DIR) + "/scenes/drop_merge.json");
    const ResourceEstimate e = estimate_resources(scene, surface_size(scene), frame_time(scene));
    ResourceLimits tight;
    tight.max_memory_bytes = 0.5 * e.memory_bytes();
    try {
        check_resources(scene, e, tight);
        FAIL() << "over the memory limit";
    } catch (const InputError& error) {
        EXPECT_NE(std::string(error.what()).find("raise the limit with --max-memory GB"),
                  std::string::npos);
    }
    tight.max_memory_bytes = 0.0;
    tight.max_steps_per_frame = 0.5 * e.steps_per_frame;
    try {
        check_resources(scene, e, tight);
        FAIL() << "over the steps limit";
    } catch (const InputError& error) {
        EXPECT_NE(std::string(error.what()).find("raise the limit with --max-steps-per-frame N"),
                  std::string::npos);
    }
}

TEST(ResourceEstimate, RigidTurnAboutAFarCentreIsRefusedBeforeItStarts) {
    // Found by the fuzz test: Zalesak's scene turned about a centre 5e8 m away moves its surface
    // by 3e9 m/s; the run started and spent minutes on steps that each moved it by thousands of
    // edge lengths. The rigid flow's speed is now bounded from the surface's bounds.
    Scene scene =
        load_scene(std::string(MENISCUS_SOURCE_DIR) + "/scenes/flows/zalesak_xi0.02.json");
    const ResourceEstimate shipped =
        estimate_resources(scene, surface_size(scene), frame_time(scene));
    EXPECT_NO_THROW(check_resources(scene, shipped, ResourceLimits{}));
    // The shipped turn: 2π rad/s at up to about 0.4 m from the axis (0.25 + 0.15, corners more).
    EXPECT_GT(shipped.step_motion, 2.0 * M_PI * 0.4 * scene.time.dt);
    scene.flow.rigid.center.x() = 5e8;
    const ResourceEstimate far = estimate_resources(scene, surface_size(scene), frame_time(scene));
    EXPECT_NEAR(far.step_motion, 2.0 * M_PI * 5e8 * scene.time.dt, 1e-6 * far.step_motion);
    try {
        check_resources(scene, far, ResourceLimits{});
        FAIL() << "a step of " << far.step_motion << " m was accepted";
    } catch (const InputError& error) {
        EXPECT_NE(std::string(error.what()).find("/flow/rigid"), std::string::npos)
            << error.what();
    }
}

}  // namespace
}  // namespace meniscus::app
