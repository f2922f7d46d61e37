// Issue 38 through the built binary: a run killed with SIGKILL at random moments and resumed
// with `meniscus run --resume DIR` writes the same frames as the run done without interruption,
// byte for byte (PLY and VDB), and the same stats.jsonl lines but for wall-clock fields; a
// truncated checkpoint and a changed scene are refused with exit 2 naming the file; the frames
// do not depend on the thread count.
#include "child_process.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using meniscus::test::ChildLimits;
using meniscus::test::ChildResult;
using meniscus::test::run_child;

/// Two drops that collide and merge (drop_merge at half the size): merging, volume correction,
/// the coupled viscous step, pressure warm starts.
const char* FLUID_SCENE = R"({
  "flow": {"type": "fluid"},
  "domain": {"min": [0, 0, 0], "size": [0.006, 0.004, 0.004], "cells": 18},
  "fluid": {"gravity": [0, 0, 0]},
  "coupling": {"edge_length_cells": 1.0, "volume_correction": true},
  "surface": {"shape": {"type": "union", "shapes": [
    {"type": "sphere", "center": [0.0017, 0.002, 0.002], "radius": 0.001},
    {"type": "sphere", "center": [0.0043, 0.002, 0.002], "radius": 0.001}]}},
  "initial_velocity": [
    {"shape": {"type": "sphere", "center": [0.0017, 0.002, 0.002], "radius": 0.001}, "velocity": [0.3, 0, 0]},
    {"shape": {"type": "sphere", "center": [0.0043, 0.002, 0.002], "radius": 0.001}, "velocity": [-0.3, 0, 0]}],
  "time": {"end": 0.004, "frames": 8}
})";

/// FLUID_SCENE's drops in a box periodic along x, moving apart inside the box and so towards
/// each other across its x faces, where they meet (issue 39).
const char* PERIODIC_SCENE = R"({
  "flow": {"type": "fluid"},
  "domain": {"min": [0, 0, 0], "size": [0.006, 0.004, 0.004], "cells": 18},
  "fluid": {"gravity": [0, 0, 0], "boundaries": {"x_min": "periodic", "x_max": "periodic"}},
  "coupling": {"edge_length_cells": 1.0, "volume_correction": true},
  "surface": {"shape": {"type": "union", "shapes": [
    {"type": "sphere", "center": [0.0013, 0.002, 0.002], "radius": 0.001},
    {"type": "sphere", "center": [0.0047, 0.002, 0.002], "radius": 0.001}]}},
  "initial_velocity": [
    {"shape": {"type": "sphere", "center": [0.0013, 0.002, 0.002], "radius": 0.001}, "velocity": [-0.3, 0, 0]},
    {"shape": {"type": "sphere", "center": [0.0047, 0.002, 0.002], "radius": 0.001}, "velocity": [0.3, 0, 0]}],
  "time": {"end": 0.004, "frames": 8}
})";

/// A sphere in the Enright field: remeshing, collisions; about 2 s in Release.
const char* FLOW_SCENE = R"({
  "flow": {"type": "enright", "period": 3},
  "surface": {"edge_length": 0.03, "shape": {"type": "sphere", "center": [0.35, 0.35, 0.35], "radius": 0.15}},
  "time": {"end": 0.8, "frames": 8, "dt": 0.02}
})";

class Resume : public testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() /
                ("meniscus_resume_" +
                 std::string(testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override {
        if (!HasFailure())
            fs::remove_all(m_dir);
    }

    std::string write(const std::string& name, const std::string& text) {
        const fs::path p = m_dir / name;
        std::ofstream(p, std::ios::binary) << text;
        return p.string();
    }

    ChildResult meniscus(std::vector<std::string> args,
                         const std::function<void(pid_t, double)>& while_running = {}) {
        args.insert(args.begin(), MENISCUS_BINARY);
        ChildLimits limits;
        limits.wall_seconds = 600.0;
        return run_child(args, limits, (m_dir / "log.txt").string(), while_running);
    }

    /// Runs `scene` whole into reference/, and into stopped/ stopped by --max-steps
    /// `max_steps` (as Ctrl-C does) before its last frame, then resumed: stopped/ must end with
    /// reference/'s frames.
    void expect_stopped_run_resumes(const std::string& scene, const std::string& max_steps);

    fs::path m_dir;
};

std::string describe(const ChildResult& r) {
    return (r.timed_out ? std::string("timed out")
            : r.exited  ? "exit " + std::to_string(r.exit_code)
                        : "signal " + std::to_string(r.signal)) +
           " after " + std::to_string(r.seconds) + " s:\n" + r.output;
}

std::string read_bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// stats.jsonl as JSON lines without the wall-clock fields (every "seconds").
std::vector<nlohmann::json> stats_without_clock(const fs::path& dir) {
    std::vector<nlohmann::json> lines;
    std::istringstream in(read_bytes(dir / "stats.jsonl"));
    for (std::string line; std::getline(in, line);) {
        nlohmann::json j = nlohmann::json::parse(line);
        j.erase("seconds");
        if (j.contains("checkpoint"))
            j["checkpoint"].erase("seconds");
        lines.push_back(j);
    }
    return lines;
}

/// Every frame file of `expected` is in `actual` with the same bytes, and no other; stats.jsonl
/// lines are equal but for wall-clock fields.
void expect_same_frames(const fs::path& expected, const fs::path& actual) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(expected)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("surface_", 0) == 0 || name.rfind("fields_", 0) == 0)
            names.insert(name);
    }
    ASSERT_GT(names.size(), 4u);
    for (const std::string& name : names) {
        ASSERT_TRUE(fs::exists(actual / name)) << name;
        EXPECT_TRUE(read_bytes(expected / name) == read_bytes(actual / name))
            << name << " differs from the uninterrupted run's";
    }
    for (const auto& e : fs::directory_iterator(actual)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("surface_", 0) == 0 || name.rfind("fields_", 0) == 0) {
            EXPECT_EQ(names.count(name), 1u) << name << " is extra";
        }
    }
    const std::vector<nlohmann::json> a = stats_without_clock(expected);
    const std::vector<nlohmann::json> b = stats_without_clock(actual);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i)
        EXPECT_EQ(a[i], b[i]) << "stats.jsonl line " << i + 1;
}

void Resume::expect_stopped_run_resumes(const std::string& scene, const std::string& max_steps) {
    const fs::path reference = m_dir / "reference", stopped = m_dir / "stopped";
    ASSERT_EQ(meniscus({"run", scene, "--out", reference.string(), "--quiet"}).exit_code, 0);
    const ChildResult part =
        meniscus({"run", scene, "--out", stopped.string(), "--quiet", "--max-steps", max_steps});
    ASSERT_TRUE(part.exited) << describe(part);
    ASSERT_FALSE(fs::exists(stopped / "surface_0008.ply"));
    const ChildResult rest = meniscus({"run", "--resume", stopped.string()});
    ASSERT_TRUE(rest.exited && rest.exit_code == 0) << describe(rest);
    EXPECT_NE(rest.output.find("resumed at frame"), std::string::npos) << rest.output;
    expect_same_frames(reference, stopped);
}

/// Complete lines in `dir`/stats.jsonl (frames done).
int complete_stats_lines(const fs::path& dir) {
    const std::string text = read_bytes(dir / "stats.jsonl");
    return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

/// Runs `scene` into `out`, kills it with SIGKILL `kills` times, resuming after each kill, and
/// returns the number of kills that hit a running process. Each kill comes after a random frame
/// still to come has completed (so a resumed run is killed too), plus a uniformly random part
/// of one frame's time (from the uninterrupted run's `duration`): in a step, in a frame's
/// files, in the checkpoint's own write.
int run_with_kills(const std::string& scene, const fs::path& out, double duration, int frames,
                   int kills, unsigned seed,
                   const std::function<ChildResult(
                       std::vector<std::string>, const std::function<void(pid_t, double)>&)>& run) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> part(0.0, 1.0);
    const double frame_seconds = duration / (frames + 1);
    int hit = 0;
    bool resume = false;
    for (int attempt = 0; attempt <= kills + 20; ++attempt) {
        const int done = resume ? complete_stats_lines(out) : 0;  // frames 0..done-1
        const int last = std::max(done, frames - 2);
        const int after = std::uniform_int_distribution<int>(done, last)(rng);
        const double delay = part(rng) * frame_seconds;
        double since = -1.0;
        bool killed = false;
        std::vector<std::string> args =
            resume ? std::vector<std::string>{"run", "--resume", out.string(), "--quiet"}
                   : std::vector<std::string>{"run", scene, "--out", out.string(), "--quiet"};
        const bool kill_this = hit < kills;
        const ChildResult r = run(args, [&](pid_t pid, double t) {
            if (!kill_this || killed)
                return;
            if (since < 0.0 && complete_stats_lines(out) > after)
                since = t;
            if (since >= 0.0 && t >= since + delay) {
                kill(pid, SIGKILL);
                killed = true;
            }
        });
        if (r.exited) {
            EXPECT_EQ(r.exit_code, 0) << describe(r);
            return hit;
        }
        EXPECT_EQ(r.signal, SIGKILL) << describe(r);
        if (r.signal != SIGKILL)
            return hit;
        ++hit;
        resume = true;
    }
    ADD_FAILURE() << "the run never finished";
    return hit;
}

TEST_F(Resume, FluidRunKilledAtRandomMomentsEndsWithTheUninterruptedRunsFrames) {
    const std::string scene = write("drop.json", FLUID_SCENE);
    const fs::path reference = m_dir / "reference", killed = m_dir / "killed";
    const ChildResult r = meniscus({"run", scene, "--out", reference.string(), "--quiet"});
    ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
    const int hits = run_with_kills(
        scene, killed, r.seconds, 8, 3, 38u,
        [&](std::vector<std::string> a, const auto& w) { return meniscus(std::move(a), w); });
    EXPECT_GE(hits, 2);
    expect_same_frames(reference, killed);
}

TEST_F(Resume, GeometricFlowKilledAtRandomMomentsEndsWithTheUninterruptedRunsFrames) {
    const std::string scene = write("enright.json", FLOW_SCENE);
    const fs::path reference = m_dir / "reference", killed = m_dir / "killed";
    const ChildResult r = meniscus({"run", scene, "--out", reference.string(), "--quiet"});
    ASSERT_TRUE(r.exited && r.exit_code == 0) << describe(r);
    const int hits = run_with_kills(
        scene, killed, r.seconds, 8, 3, 3800u,
        [&](std::vector<std::string> a, const auto& w) { return meniscus(std::move(a), w); });
    EXPECT_GE(hits, 2);
    expect_same_frames(reference, killed);
}

TEST_F(Resume, StoppedRunResumesFromItsLastCheckpoint) {
    // --max-steps stops a run part way (as Ctrl-C does); --resume finishes it.
    expect_stopped_run_resumes(write("enright.json", FLOW_SCENE), "13");
}

TEST_F(Resume, PeriodicFluidRunResumesWithTheUninterruptedRunsFrames) {
    // Regression: a resumed periodic scene failed to set up ("the fluid box is periodic along x
    // but the surface mesh does not wrap around it"): the stand-in surface the checkpoint's
    // state replaces had no periods.
    expect_stopped_run_resumes(write("periodic.json", PERIODIC_SCENE), "15");
    // The drops met across the seam: one component at the end.
    const std::vector<nlohmann::json> lines = stats_without_clock(m_dir / "reference");
    EXPECT_EQ(lines.front()["components"].get<int>(), 2);
    EXPECT_EQ(lines.back()["components"].get<int>(), 1);
}

TEST_F(Resume, TruncatedOrDamagedCheckpointIsRefusedNamingTheFile) {
    const std::string scene = write("enright.json", FLOW_SCENE);
    const fs::path out = m_dir / "out";
    ASSERT_EQ(meniscus({"run", scene, "--out", out.string(), "--quiet", "--frames", "2"}).exit_code,
              0);
    const std::string whole = read_bytes(out / "checkpoint.bin");
    ASSERT_GT(whole.size(), 1000u);
    std::mt19937 rng(380u);
    for (int trial = 0; trial < 4; ++trial) {
        std::string damaged = whole;
        const size_t at = std::uniform_int_distribution<size_t>(0, whole.size() - 1)(rng);
        if (trial % 2 == 0)
            damaged.resize(at);  // truncated at a random byte
        else
            damaged[at] = static_cast<char>(damaged[at] ^ 0x5a);  // one byte changed
        std::ofstream(out / "checkpoint.bin", std::ios::binary | std::ios::trunc) << damaged;
        const ChildResult r = meniscus({"run", "--resume", out.string(), "--quiet"});
        EXPECT_TRUE(r.exited && r.exit_code == 2) << "byte " << at << ": " << describe(r);
        EXPECT_NE(r.output.find((out / "checkpoint.bin").string()), std::string::npos) << r.output;
    }
    fs::remove(out / "checkpoint.bin");
    const ChildResult none = meniscus({"run", "--resume", out.string(), "--quiet"});
    EXPECT_TRUE(none.exited && none.exit_code == 2) << describe(none);
    EXPECT_NE(none.output.find("no checkpoint"), std::string::npos) << none.output;
}

TEST_F(Resume, ChangedSceneIsRefusedNamingWhatChangedUnlessAllowed) {
    const std::string scene = write("enright.json", FLOW_SCENE);
    const fs::path out = m_dir / "out";
    ASSERT_EQ(
        meniscus({"run", scene, "--out", out.string(), "--quiet", "--max-steps", "5"}).exit_code,
        0);
    nlohmann::json changed = nlohmann::json::parse(FLOW_SCENE);
    changed["time"]["dt"] = 0.01;
    write("enright.json", changed.dump(2));
    const ChildResult refused = meniscus({"run", "--resume", out.string(), "--quiet"});
    EXPECT_TRUE(refused.exited && refused.exit_code == 2) << describe(refused);
    EXPECT_NE(refused.output.find("/time/dt"), std::string::npos) << refused.output;
    EXPECT_NE(refused.output.find("--allow-scene-change"), std::string::npos) << refused.output;
    const ChildResult allowed =
        meniscus({"run", "--resume", out.string(), "--allow-scene-change", "--quiet"});
    EXPECT_TRUE(allowed.exited && allowed.exit_code == 0) << describe(allowed);
    EXPECT_TRUE(fs::exists(out / "surface_0008.ply"));
    // The same JSON written differently is the same scene.
    write("enright.json", nlohmann::json::parse(FLOW_SCENE).dump());
    const fs::path again = m_dir / "again";
    ASSERT_EQ(
        meniscus({"run", scene, "--out", again.string(), "--quiet", "--max-steps", "5"}).exit_code,
        0);
    write("enright.json", nlohmann::json::parse(FLOW_SCENE).dump(4));
    const ChildResult reformatted = meniscus({"run", "--resume", again.string(), "--quiet"});
    EXPECT_TRUE(reformatted.exited && reformatted.exit_code == 0) << describe(reformatted);
}

TEST_F(Resume, OneAndTwoThreadsWriteTheSameFrames) {
    for (const char* name : {"drop.json", "enright.json"}) {
        const std::string scene = write(name, name[0] == 'd' ? FLUID_SCENE : FLOW_SCENE);
        const fs::path one = m_dir / (std::string(name) + "_1"),
                       two = m_dir / (std::string(name) + "_2");
        const ChildResult a =
            meniscus({"run", scene, "--out", one.string(), "--quiet", "--threads", "1"});
        ASSERT_TRUE(a.exited && a.exit_code == 0) << describe(a);
        const ChildResult b =
            meniscus({"run", scene, "--out", two.string(), "--quiet", "--threads", "2"});
        ASSERT_TRUE(b.exited && b.exit_code == 0) << describe(b);
        expect_same_frames(one, two);
    }
}

}  // namespace
