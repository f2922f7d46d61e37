// Runs the built `meniscus` binary and checks exit codes and messages of each error path.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

namespace {

namespace fs = std::filesystem;

struct Outcome {
    int exit_code = -1;
    std::string output;  // stdout and stderr together
};

Outcome run_meniscus(const std::string& args) {
    const std::string command = std::string(MENISCUS_BINARY) + " " + args + " 2>&1";
    Outcome o;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe)
        return o;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, pipe)) > 0)
        o.output.append(buf, n);
    const int status = pclose(pipe);
    o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return o;
}

class CliTest : public testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() /
                ("meniscus_cli_" +
                 std::string(testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override { fs::remove_all(m_dir); }
    std::string write(const std::string& name, const std::string& text) {
        const fs::path p = m_dir / name;
        std::ofstream(p) << text;
        return p.string();
    }
    fs::path m_dir;
};

const char* SMALL_SCENE = R"({
  "surface": {"edge_length": 0.05, "shape": {"type": "sphere", "center": [0.5, 0.5, 0.5], "radius": 0.15}},
  "time": {"end": 0.04, "frames": 2, "dt": 0.01},
  "output": {"vdb": true, "obj": true}
})";

const char* OCTAHEDRON_OBJ =
    "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
    "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

TEST_F(CliTest, HelpAndVersionSucceed) {
    const Outcome help = run_meniscus("--help");
    EXPECT_EQ(help.exit_code, 0);
    EXPECT_NE(help.output.find("usage: meniscus"), std::string::npos);
    const Outcome version = run_meniscus("--version");
    EXPECT_EQ(version.exit_code, 0);
    EXPECT_NE(version.output.find("meniscus "), std::string::npos);
}

TEST_F(CliTest, NoCommandIsBadInput) {
    const Outcome o = run_meniscus("");
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("no command given"), std::string::npos);
}

TEST_F(CliTest, UnknownCommandIsBadInput) {
    const Outcome o = run_meniscus("frobnicate");
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("unknown command 'frobnicate'"), std::string::npos);
}

TEST_F(CliTest, RunWithoutSceneIsBadInput) {
    const Outcome o = run_meniscus("run");
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("no scene file given"), std::string::npos);
}

TEST_F(CliTest, UnknownOptionIsBadInput) {
    const Outcome o = run_meniscus("run x.json --fast");
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("unknown option --fast"), std::string::npos);
}

TEST_F(CliTest, BadFramesValueIsBadInput) {
    const Outcome o = run_meniscus("run x.json --frames zero");
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("--frames: expected a whole number"), std::string::npos);
}

TEST_F(CliTest, ValidateXiThatNoSelectedCaseRunsIsBadInput) {
    // Quick A2 runs only ξ = 0.04; the check runs before anything is computed.
    const Outcome o =
        run_meniscus("validate --quick --case A2 --xi 0.01 --out " + (m_dir / "v").string());
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("--xi 0.01 is not a resolution"), std::string::npos) << o.output;
    EXPECT_NE(o.output.find("they run 0.04"), std::string::npos) << o.output;
    EXPECT_FALSE(fs::exists(m_dir / "v" / "report.md"));
}

TEST_F(CliTest, ValidateUnknownCaseIsBadInput) {
    const Outcome o = run_meniscus("validate --case A9 --out " + (m_dir / "v").string());
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("unknown case 'A9' (expected A1, A2, A3, A4, A6 or B1"),
              std::string::npos)
        << o.output;
    EXPECT_FALSE(fs::exists(m_dir / "v" / "report.md"));
}

TEST_F(CliTest, ValidateBadXiValueIsBadInput) {
    for (const char* value : {"fine", "-0.01", "0", "0.01m"}) {
        const Outcome o = run_meniscus(std::string("validate --xi ") + value);
        EXPECT_EQ(o.exit_code, 2) << value;
        EXPECT_NE(o.output.find("--xi: expected a positive length"), std::string::npos) << value;
    }
}

TEST_F(CliTest, ValidateThreadsLimitTheWorkerThreadsAndAreRecorded) {
    // validate used to ignore MENISCUS_THREADS and had no --threads: its timings then came from
    // every core whatever the user asked. results.json records the limit the runs had.
    const auto threads_recorded = [&](const std::string& args) {
        const fs::path out = m_dir / "v";
        fs::remove_all(out);
        const Outcome o =
            run_meniscus("validate --quick --case A6 --xi 0.04 --out " + out.string() + " " + args);
        EXPECT_EQ(o.exit_code, 0) << o.output;
        std::ifstream f(out / "results.json");
        return nlohmann::json::parse(f).value("threads", -1);
    };
    EXPECT_EQ(threads_recorded("--threads 1"), 1);
    ::setenv("MENISCUS_THREADS", "1", 1);
    EXPECT_EQ(threads_recorded(""), 1);
    ::unsetenv("MENISCUS_THREADS");
    const Outcome zero = run_meniscus("validate --case A6 --threads 0 --out " + m_dir.string());
    EXPECT_EQ(zero.exit_code, 2);
    EXPECT_NE(zero.output.find("--threads: expected a whole number"), std::string::npos)
        << zero.output;
}

TEST_F(CliTest, MissingSceneFileNamesTheFile) {
    const Outcome o = run_meniscus((m_dir / "nope.json").string());
    EXPECT_EQ(o.exit_code, 2);  // unknown command (a path is not a command)
    const Outcome r = run_meniscus("run " + (m_dir / "nope.json").string());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.output.find("nope.json: cannot open the scene file"), std::string::npos);
}

TEST_F(CliTest, JsonSyntaxErrorIsBadInput) {
    const std::string scene = write("broken.json", "{\"time\": {\"end\": 1,}");
    const Outcome o = run_meniscus("run " + scene);
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("broken.json: invalid JSON"), std::string::npos);
}

TEST_F(CliTest, UnknownKeyNamesItsJsonPath) {
    const std::string scene =
        write("typo.json", R"({"surface": {"shape": {"type": "sphere"}, "edge_lenght": 0.1}})");
    const Outcome o = run_meniscus("run " + scene);
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("/surface/edge_lenght: unknown key"), std::string::npos) << o.output;
}

TEST_F(CliTest, OutOfRangeValueNamesItsJsonPath) {
    const std::string scene =
        write("range.json", R"({"surface": {"shape": {"type": "sphere"}}, "time": {"dt": -1}})");
    const Outcome o = run_meniscus("run " + scene);
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("/time/dt: expected a number > 0, got -1"), std::string::npos)
        << o.output;
}

TEST_F(CliTest, OpenMeshFileIsRejectedWithTheCheckThatFailed) {
    write("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
    const std::string scene = write("s.json", R"({"surface": {"mesh_file": "open.obj"}})");
    const Outcome o = run_meniscus("run " + scene + " --out " + (m_dir / "out").string());
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("open.obj: not a valid closed surface"), std::string::npos) << o.output;
    EXPECT_NE(o.output.find("boundary edge"), std::string::npos) << o.output;
}

TEST_F(CliTest, InconsistentlyOrientedMeshFileIsRejected) {
    std::string obj = OCTAHEDRON_OBJ;
    obj.replace(obj.find("f 1 3 5"), 7, "f 1 5 3");
    write("flipped.obj", obj);
    const std::string scene = write("s.json", R"({"surface": {"mesh_file": "flipped.obj"}})");
    const Outcome o = run_meniscus("run " + scene + " --out " + (m_dir / "out").string());
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("inconsistent orientation"), std::string::npos) << o.output;
}

TEST_F(CliTest, BadIndexInMeshFileNamesTheLine) {
    write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n");
    const std::string scene = write("s.json", R"({"surface": {"mesh_file": "bad.obj"}})");
    const Outcome o = run_meniscus("run " + scene + " --out " + (m_dir / "out").string());
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("bad.obj: line 4: malformed face index 'x'"), std::string::npos)
        << o.output;
}

TEST_F(CliTest, DuplicateTriangleInMeshFileIsRejected) {
    write("dup.obj", std::string(OCTAHEDRON_OBJ) + "f 1 3 5\nf 1 5 3\n");
    const std::string scene = write("s.json", R"({"surface": {"mesh_file": "dup.obj"}})");
    const Outcome o = run_meniscus("run " + scene + " --out " + (m_dir / "out").string());
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("duplicate triangle"), std::string::npos) << o.output;
}

TEST_F(CliTest, SelfIntersectingMeshFileIsRejected) {
    // Two octahedra overlapping: closed and oriented, but the surfaces cross.
    std::string obj = OCTAHEDRON_OBJ;
    obj +=
        "v 1.5 0 0\nv -0.5 0 0\nv 0.5 1 0\nv 0.5 -1 0\nv 0.5 0 1\nv 0.5 0 -1\n"
        "f 7 9 11\nf 9 8 11\nf 8 10 11\nf 10 7 11\nf 9 7 12\nf 8 9 12\nf 10 8 12\nf 7 10 12\n";
    write("crossing.obj", obj);
    const std::string scene = write("s.json", R"({"surface": {"mesh_file": "crossing.obj"}})");
    const Outcome o = run_meniscus("run " + scene + " --out " + (m_dir / "out").string());
    EXPECT_EQ(o.exit_code, 2);
    EXPECT_NE(o.output.find("crossing.obj: the surface intersects itself"), std::string::npos)
        << o.output;
}

TEST_F(CliTest, RunWritesEveryFrameAndStats) {
    const std::string scene = write("small.json", SMALL_SCENE);
    const fs::path out = m_dir / "out";
    const Outcome o = run_meniscus("run " + scene + " --out " + out.string() + " --quiet");
    ASSERT_EQ(o.exit_code, 0) << o.output;
    for (const char* f : {"surface_0000.ply", "surface_0002.ply", "surface_0002.obj",
                          "fields_0000.vdb", "fields_0002.vdb", "stats.jsonl"})
        EXPECT_TRUE(fs::exists(out / f)) << f;
    EXPECT_FALSE(fs::exists(out / "surface_0003.ply"));
    std::ifstream stats(out / "stats.jsonl");
    int lines = 0;
    for (std::string line; std::getline(stats, line);)
        ++lines;
    EXPECT_EQ(lines, 3);
    for (const auto& entry : fs::directory_iterator(out))
        EXPECT_EQ(entry.path().string().find(".partial"), std::string::npos) << entry.path();
}

TEST_F(CliTest, UnconvergedViscousSolveIsWarnedAbout) {
    // Issue 34: a viscous or pressure solve that does not converge is said in the run log.
    const std::string scene = write("drop.json", R"({
  "flow": {"type": "fluid"},
  "domain": {"min": [0, 0, 0], "size": [0.006, 0.006, 0.006], "cells": 12},
  "fluid": {"gravity": [0, 0, 0], "viscosity_max_iterations": 1, "viscosity_tolerance": 1e-12},
  "surface": {"shape": {"type": "sphere", "center": [0.003, 0.003, 0.003], "radius": 0.0015}},
  "time": {"end": 0.0005, "frames": 1},
  "output": {"ply": false, "vdb": false}
})");
    const Outcome o = run_meniscus("run " + scene + " --out " + (m_dir / "out").string());
    ASSERT_EQ(o.exit_code, 0) << o.output;
    EXPECT_NE(o.output.find("warning: frame 1: the viscosity solve did not converge"),
              std::string::npos)
        << o.output;
    EXPECT_NE(o.output.find("/fluid/viscosity_max_iterations"), std::string::npos) << o.output;
}

TEST_F(CliTest, ASecondRunIntoTheSameFolderReplacesTheFirst) {
    // Never a mix of two runs: a shorter run into the folder of a longer one removes the
    // longer run's frames (and a stale temporary, which prepare_output_dir() removes first and
    // the count leaves out), says so, and leaves other files alone.
    const std::string scene = write("small.json", SMALL_SCENE);
    const fs::path out = m_dir / "out";
    ASSERT_EQ(run_meniscus("run " + scene + " --out " + out.string() + " --quiet").exit_code, 0);
    ASSERT_TRUE(fs::exists(out / "surface_0002.ply"));
    std::ofstream(out / "notes.txt") << "mine";
    std::ofstream(out / "fields_0007.vdb.partial") << "stale";
    const Outcome o = run_meniscus("run " + scene + " --out " + out.string() + " --frames 1");
    ASSERT_EQ(o.exit_code, 0) << o.output;
    EXPECT_NE(o.output.find("removed 12 files of an earlier run"), std::string::npos) << o.output;
    for (const char* gone :
         {"surface_0002.ply", "surface_0002.obj", "fields_0002.vdb", "fields_0007.vdb.partial"})
        EXPECT_FALSE(fs::exists(out / gone)) << gone;
    for (const char* kept : {"surface_0001.ply", "fields_0001.vdb", "notes.txt", "meniscus.json"})
        EXPECT_TRUE(fs::exists(out / kept)) << kept;
    std::ifstream stats(out / "stats.jsonl");
    int lines = 0;
    for (std::string line; std::getline(stats, line);)
        ++lines;
    EXPECT_EQ(lines, 2);
}

TEST_F(CliTest, FramesOptionOverridesTheSceneKeepingTimePerFrame) {
    const std::string scene = write("small.json", SMALL_SCENE);
    const fs::path out = m_dir / "out";
    const Outcome o =
        run_meniscus("run " + scene + " --out " + out.string() + " --quiet --frames 1");
    ASSERT_EQ(o.exit_code, 0) << o.output;
    EXPECT_TRUE(fs::exists(out / "surface_0001.ply"));
    EXPECT_FALSE(fs::exists(out / "surface_0002.ply"));
}

TEST_F(CliTest, InterruptFinishesCleanly) {
    // A long run interrupted by one SIGINT (what Ctrl-C sends) exits 130 and leaves only
    // complete files. The signal is sent once frame 0 exists, by this test itself: GNU
    // `timeout` signals both the child and its process group, so the child could get two
    // SIGINTs, and the second one ends the run at once by design (a CI failure).
    const std::string scene = write("long.json", R"({
      "surface": {"edge_length": 0.02, "shape": {"type": "sphere", "center": [0.35, 0.35, 0.35], "radius": 0.15}},
      "time": {"end": 3000, "frames": 1000, "dt": 0.01}, "output": {"vdb": false}})");
    const fs::path out = m_dir / "out";
    const fs::path log = m_dir / "log.txt";
    const std::string out_dir = out.string();  // built before fork: the child only execs
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd < 0)
            _exit(127);
        dup2(fd, STDOUT_FILENO);
        dup2(fd, STDERR_FILENO);
        execl(MENISCUS_BINARY, MENISCUS_BINARY, "run", scene.c_str(), "--out", out_dir.c_str(),
              "--quiet", static_cast<char*>(nullptr));
        _exit(127);
    }
    // Frame 1 is 3 s of simulated time away, so the run is inside its time loop once
    // frame 0 is on disk; wait for it (generously: the suite runs tests in parallel).
    bool started = false;
    for (int i = 0; i < 1200 && !started; ++i) {
        started = fs::exists(out / "surface_0000.ply");
        if (!started)
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    kill(pid, SIGINT);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    std::ifstream in(log);
    const std::string output((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
    ASSERT_TRUE(started) << output;
    ASSERT_TRUE(WIFEXITED(status)) << "ended by signal " << WTERMSIG(status) << "\n" << output;
    EXPECT_EQ(WEXITSTATUS(status), 130) << output;
    EXPECT_NE(output.find("interrupted at t ="), std::string::npos) << output;
    EXPECT_TRUE(fs::exists(out / "surface_0000.ply"));
    for (const auto& entry : fs::directory_iterator(out))
        EXPECT_EQ(entry.path().string().find(".partial"), std::string::npos) << entry.path();
}

TEST_F(CliTest, SceneReferenceListsEveryKey) {
    const Outcome o = run_meniscus("scene-reference");
    EXPECT_EQ(o.exit_code, 0);
    for (const char* key : {"`edge_length`", "`mesh_file`", "`dt`", "`voxel_size`",
                            "`major_radius`", "`handle_radius`", "### `/output`"})
        EXPECT_NE(o.output.find(key), std::string::npos) << key;
}

}  // namespace
