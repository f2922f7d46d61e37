// What `meniscus run` writes, read back: the VDB's `vel` and `pressure` grids are the solver's
// arrays (in the run's length unit, on the fluid's cell centres), and the sidecar describes the
// run. (The render path and independent readers: tests/render/.)
#include "app/frame_output.h"
#include "app/run.h"
#include "app/scene.h"
#include "app/scene_setup.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace meniscus::app {
namespace {

namespace fs = std::filesystem;

/// The solver state of frame `frame` of `scene`, stepped exactly as run_scene() steps.
coupling::Simulation simulate_to_frame(const Scene& scene, int frame) {
    coupling::Simulation sim = make_fluid_simulation(scene);
    const double frame_dt = scene.time.end / scene.time.frames;
    double t = 0.0;
    for (int f = 1; f <= frame; ++f) {
        const double t_frame = f * frame_dt;
        while (t < t_frame) {
            const coupling::SimulationStepReport last = sim.step(t_frame - t);
            t = (t_frame - (t + last.dt) <= 1e-12 * t_frame) ? t_frame : t + last.dt;
        }
    }
    return sim;
}

/// `vel` and `pressure` of `path` against `sim`'s arrays, lengths × `scale`.
void expect_fluid_grids_match(const std::string& path, const coupling::Simulation& sim,
                              double scale) {
    openvdb::initialize();
    openvdb::io::File file(path);
    file.open();
    const auto vel = openvdb::gridPtrCast<openvdb::Vec3SGrid>(file.readGrid("vel"));
    const auto pressure = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("pressure"));
    file.close();
    ASSERT_TRUE(vel && pressure);
    const fluid::MacGrid& grid = sim.fluid().grid();
    const fluid::Array3<double>& p = sim.fluid().pressure();
    double max_speed = 0.0, max_pressure = 0.0;
    for (int k = 0; k < grid.nz(); ++k)
        for (int j = 0; j < grid.ny(); ++j)
            for (int i = 0; i < grid.nx(); ++i) {
                max_speed = std::max(max_speed, std::abs(grid.u()(i, j, k)));
                max_pressure = std::max(max_pressure, std::abs(p(i, j, k)));
            }
    ASSERT_GT(max_speed, 0.0);
    double worst_velocity = 0.0, worst_pressure = 0.0, worst_place = 0.0;
    const auto vacc = vel->getConstAccessor();
    const auto pacc = pressure->getConstAccessor();
    for (int k = 0; k < grid.nz(); ++k)
        for (int j = 0; j < grid.ny(); ++j)
            for (int i = 0; i < grid.nx(); ++i) {
                const openvdb::Coord c(i, j, k);
                const Eigen::Vector3d centre = scale * grid.cell_centre(i, j, k);
                const openvdb::Vec3d w = vel->indexToWorld(c);
                worst_place =
                    std::max(worst_place, (Eigen::Vector3d(w.x(), w.y(), w.z()) - centre).norm());
                const Eigen::Vector3d expected =
                    scale * 0.5 *
                    Eigen::Vector3d(grid.u()(i, j, k) + grid.u()(i + 1, j, k),
                                    grid.v()(i, j, k) + grid.v()(i, j + 1, k),
                                    grid.w()(i, j, k) + grid.w()(i, j, k + 1));
                const openvdb::Vec3s v = vacc.getValue(c);
                worst_velocity = std::max(worst_velocity,
                                          (Eigen::Vector3d(v.x(), v.y(), v.z()) - expected).norm());
                worst_pressure = std::max(worst_pressure, std::abs(pacc.getValue(c) - p(i, j, k)));
            }
    // Stored as float: relative round-off ~1e-7 of the largest value.
    EXPECT_LT(worst_velocity, 1e-5 * scale * max_speed);
    EXPECT_LT(worst_pressure, 1e-5 * max_pressure + 1e-6);
    EXPECT_LT(worst_place, 1e-9 * scale);
    EXPECT_EQ(vel->getConstAccessor().getValue(openvdb::Coord(grid.nx(), 0, 0)),
              openvdb::Vec3s(0.0f));  // nothing beyond the box
}

TEST(FrameOutput, VelAndPressureOfARunAreTheSolversArrays) {
    // scenes/drop_merge.json for one frame (1 ms), lengths in millimetres (the default): frame 0
    // holds the initial velocity (±0.15 m/s = ±150 mm/s in the drops), frame 1 the solver's
    // state after the run's steps, which this test repeats.
    const Scene scene = load_scene(std::string(MENISCUS_SOURCE_DIR) + "/scenes/drop_merge.json");
    ASSERT_EQ(scene.output.length_unit, "mm");
    RunOptions options;
    options.out_dir = (fs::temp_directory_path() / "meniscus_frame_output_fluid").string();
    options.frames = 1;
    options.quiet = true;
    const std::atomic<bool> stop{false};
    const RunResult r = run_scene(scene, options, stop);
    ASSERT_EQ(r.frames_written, 2);
    expect_fluid_grids_match(options.out_dir + "/fields_0000.vdb", simulate_to_frame(scene, 0),
                             1000.0);
    expect_fluid_grids_match(options.out_dir + "/fields_0001.vdb", simulate_to_frame(scene, 1),
                             1000.0);

    // The sidecar: units, frame rate, files, grids and the Blender offset of the surface grids.
    std::ifstream in(options.out_dir + "/meniscus.json");
    const nlohmann::json sidecar = nlohmann::json::parse(in);
    EXPECT_EQ(sidecar["scene"], "drop_merge");
    EXPECT_EQ(sidecar["length_unit"], "mm");
    EXPECT_DOUBLE_EQ(sidecar["metres_per_unit"].get<double>(), 0.001);
    EXPECT_EQ(sidecar["velocity_unit"], "mm/s");
    EXPECT_DOUBLE_EQ(sidecar["frame_rate"].get<double>(), 1000.0);
    EXPECT_EQ(sidecar["frame_count"], 2);
    EXPECT_EQ(sidecar["complete"], true);
    EXPECT_EQ(sidecar["inside"], "liquid");
    EXPECT_EQ(sidecar["files"]["surface_ply"], "surface_%04d.ply");
    EXPECT_EQ(sidecar["files"]["fields_vdb"], "fields_%04d.vdb");
    EXPECT_EQ(sidecar["vdb"]["grids"], nlohmann::json({"surface", "density", "vel", "pressure"}));
    const double h = 1000.0 * 0.5 * scene.surface.edge_length;  // mm
    EXPECT_NEAR(sidecar["vdb"]["voxel_size"].get<double>(), h, 1e-12);
    EXPECT_NEAR(sidecar["vdb"]["blender_offset"][0].get<double>(), -0.5 * h, 1e-12);
    fs::remove_all(options.out_dir);
}

TEST(FrameOutput, LengthUnits) {
    EXPECT_DOUBLE_EQ(metres_per_unit("m"), 1.0);
    EXPECT_DOUBLE_EQ(metres_per_unit("cm"), 0.01);
    EXPECT_DOUBLE_EQ(metres_per_unit("mm"), 0.001);
    EXPECT_THROW(metres_per_unit("in"), std::invalid_argument);
}

TEST(FrameOutput, EarlierRunsFilesAreRemovedAndOthersKept) {
    const fs::path dir = fs::temp_directory_path() / "meniscus_frame_output_earlier";
    fs::remove_all(dir);
    fs::create_directories(dir);
    for (const char* name :
         {"surface_0000.ply", "surface_0012.obj", "fields_12345.vdb", "fields_0003.vdb.partial",
          "stats.jsonl", "meniscus.json", "surface_12.ply", "surface_0001.ply.bak", "notes.txt",
          "render_0001.png"})
        std::ofstream(dir / name) << "x";
    const std::vector<std::string> removed = remove_earlier_run(dir.string());
    EXPECT_EQ(removed, (std::vector<std::string>{"fields_0003.vdb.partial", "fields_12345.vdb",
                                                 "meniscus.json", "stats.jsonl", "surface_0000.ply",
                                                 "surface_0012.obj"}));
    for (const char* kept :
         {"surface_12.ply", "surface_0001.ply.bak", "notes.txt", "render_0001.png"})
        EXPECT_TRUE(fs::exists(dir / kept)) << kept;
    EXPECT_TRUE(remove_earlier_run((dir / "missing").string()).empty());
    fs::remove_all(dir);
}

}  // namespace
}  // namespace meniscus::app
