// Issue 37 through the built binary: bad input is refused with exit 2 naming what is wrong,
// before anything large is allocated; SIGINT and SIGTERM stop a run within a second or two even
// inside a long step (130 / 143), a second signal ends it at once; writes are checked, so a
// full disk is exit 1 naming the file and leaves no unreadable file under a frame's name.
#include "child_process.h"
#include "tracker/mesh_io.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <sys/mount.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using meniscus::test::ChildLimits;
using meniscus::test::ChildResult;
using meniscus::test::run_child;

/// Generous bounds: the suite runs tests in parallel on two cores.
constexpr double REFUSAL_SECONDS = 30.0;
constexpr unsigned long long REFUSAL_ADDRESS_SPACE = 3ull << 30;
/// A run stops this soon after SIGINT or SIGTERM ("within a second or two"); sanitizer builds
/// also check the heap for leaks on the way out.
constexpr double SIGNAL_RESPONSE_SECONDS =
    meniscus::test::built_with_address_sanitizer() ? 6.0 : 2.0;

class Robustness : public testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() /
                ("meniscus_robust_" +
                 std::string(testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override { fs::remove_all(m_dir); }

    std::string write(const std::string& name, const std::string& text) {
        const fs::path p = m_dir / name;
        std::ofstream(p, std::ios::binary) << text;
        return p.string();
    }

    /// `meniscus run SCENE --out DIR --quiet ARGS...` with a time and address-space bound.
    ChildResult run(const std::string& scene, std::vector<std::string> args = {},
                    ChildLimits limits = refusal_limits(),
                    const std::function<void(pid_t, double)>& while_running = {}) {
        std::vector<std::string> argv = {MENISCUS_BINARY, "run", scene, "--quiet"};
        bool has_out = false;
        for (const std::string& a : args)
            has_out = has_out || a == "--out";
        if (!has_out) {
            argv.push_back("--out");
            argv.push_back((m_dir / "out").string());
        }
        argv.insert(argv.end(), args.begin(), args.end());
        return run_child(argv, limits, (m_dir / "log.txt").string(), while_running);
    }

    static ChildLimits refusal_limits() {
        ChildLimits l;
        l.wall_seconds = REFUSAL_SECONDS;
        l.address_space_bytes = REFUSAL_ADDRESS_SPACE;
        return l;
    }

    fs::path m_dir;
};

std::string describe(const ChildResult& r) {
    return (r.timed_out ? std::string("timed out")
            : r.exited  ? "exit " + std::to_string(r.exit_code)
                        : "signal " + std::to_string(r.signal)) +
           " after " + std::to_string(r.seconds) + " s:\n" + r.output;
}

const char* OCTAHEDRON_OBJ =
    "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
    "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

/// The octahedron scaled by `s` with every face's winding reversed when `reversed`, its
/// vertices numbered from `first` (1-based OBJ numbers).
std::string octahedron(double s, bool reversed, int first = 1) {
    std::string out;
    const double v[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const int f[8][3] = {{1, 3, 5}, {3, 2, 5}, {2, 4, 5}, {4, 1, 5},
                         {3, 1, 6}, {2, 3, 6}, {4, 2, 6}, {1, 4, 6}};
    for (const auto& p : v)
        out += "v " + std::to_string(s * p[0]) + " " + std::to_string(s * p[1]) + " " +
               std::to_string(s * p[2]) + "\n";
    for (const auto& t : f) {
        const int a = t[0] + first - 1, b = t[1] + first - 1, c = t[2] + first - 1;
        out += reversed ? "f " + std::to_string(a) + " " + std::to_string(c) + " " +
                              std::to_string(b) + "\n"
                        : "f " + std::to_string(a) + " " + std::to_string(b) + " " +
                              std::to_string(c) + "\n";
    }
    return out;
}

// ---- refused input: exit 2 with the file, the key and the reason -----------------------

struct BadScene {
    std::string name;
    std::string json;
    std::string expected;  ///< a substring of the message
    std::vector<std::string> args;
};

void PrintTo(const BadScene& scene, std::ostream* os) {
    *os << scene.name;
}

class RefusedScenes : public Robustness, public testing::WithParamInterface<BadScene> {};

TEST_P(RefusedScenes, ExitTwoNamingTheProblemBeforeAllocating) {
    const BadScene& c = GetParam();
    const std::string scene = write("scene.json", c.json);
    const ChildResult r = run(scene, c.args);
    ASSERT_TRUE(r.exited) << describe(r);
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << describe(r);
    EXPECT_EQ(r.output.find("internal failure"), std::string::npos) << describe(r);
}

std::string fluid_scene(const std::string& extra,
                        const std::string& domain = R"({"min": [0, 0, 0], "size": [0.008, 0.008, 0.008], "cells": 16})",
                        const std::string& center = "[0.004, 0.004, 0.004]") {
    return R"({"flow": {"type": "fluid"}, "time": {"end": 0.002, "frames": 1}, "domain": )" +
           domain + R"(, "surface": {"shape": {"type": "sphere", "center": )" + center +
           R"(, "radius": 0.002}})" + extra + "}";
}

std::string nested_unions(int depth) {
    // Built in linear time: the cases are made when the test program starts (even to list its
    // tests), and wrapping the string 5000 times moved ~375 MB, 3 s per start under ASan.
    std::string opening, closing;
    for (int i = 0; i < depth; ++i) {
        opening += R"({"type": "union", "shapes": [)";
        closing += "]}";
    }
    return R"({"surface": {"edge_length": 0.05, "shape": )" + opening +
           R"({"type": "sphere", "radius": 0.2})" + closing + "}}";
}

std::string many_spheres(int count) {
    std::string list;
    for (int i = 0; i < count; ++i)
        list += std::string(i ? ", " : "") + R"({"type": "sphere", "center": [)" +
                std::to_string(0.01 * i) + R"(, 0, 0], "radius": 0.01})";
    return R"({"surface": {"edge_length": 0.005, "shape": {"type": "union", "shapes": [)" + list +
           "]}}}";
}

std::vector<BadScene> bad_scenes() {
    return {
        {"number_beyond_double", R"({"surface": {"shape": {"type": "sphere", "radius": 1e400}}})",
         "scene.json: /surface/shape/radius: expected a number, got 1e400", {}},
        {"magnitude_1e308", R"({"surface": {"shape": {"type": "sphere", "radius": 1e308}}})",
         "/surface/shape/radius: expected a number > 0, got 1e+308 (magnitudes outside", {}},
        {"tiny_density", fluid_scene(R"(, "fluid": {"phases": {"rho_gas": 1e-300}})"),
         "/fluid/phases/rho_gas: expected a number > 0, got 1e-300", {}},
        {"integer_overflow",
         R"({"surface": {"shape": {"type": "sphere"}}, "time": {"frames": 18446744073709551615}})",
         "/time/frames: expected an integer in [1, 1000000], got 18446744073709551615", {}},
        {"remesh_path_without_cpp_names",
         R"({"surface": {"shape": {"type": "sphere"}}, "tracker": {"remesh": {"max_edge_fraction": 0.4}}})",
         "/tracker/remesh/max_edge_fraction: must be finite and > min_edge_fraction", {}},
        {"fluid_grid_too_large",
         fluid_scene(R"(, "coupling": {"edge_length_cells": 0})",
                     R"({"min": [0, 0, 0], "size": [0.008, 0.008, 0.008], "cells": 1000})"),
         "fluid grid of 1e+03 x 1e+03 x 1e+03 cells (/domain)", {"--max-memory", "1"}},
        {"vdb_band_too_large",
         R"({"surface": {"shape": {"type": "sphere", "radius": 0.2}, "edge_length": 0.05},
             "flow": {"type": "none"}, "output": {"half_width_voxels": 1e6}})",
         "VDB narrow band", {"--max-memory", "1"}},
        {"voxel_size_tiny",
         R"({"surface": {"shape": {"type": "sphere", "radius": 0.2}, "edge_length": 0.05},
             "flow": {"type": "none"}, "output": {"voxel_size": 1e-9}})",
         "/output/voxel_size 1e-09 m", {"--max-memory", "1"}},
        {"edge_length_tiny",
         R"({"surface": {"shape": {"type": "sphere", "radius": 0.2}, "edge_length": 1e-20}})",
         "surface mesh of about", {"--max-memory", "1"}},
        {"capillary_steps", fluid_scene(R"(, "fluid": {"phases": {"sigma": 1e30}})"),
         "the capillary limit", {}},
        {"gravity_steps", fluid_scene(R"(, "fluid": {"gravity": [0, 0, -1e30]})"),
         "--max-steps-per-frame N", {}},
        {"domain_far_away",
         fluid_scene("", R"({"min": [1e20, 0, 0], "size": [0.008, 0.008, 0.008], "cells": 16})"),
         "/domain reaches 1e+20 m from the origin, too far for double precision", {}},
        {"domain_long_axis",
         fluid_scene("", R"({"min": [0, 0, 0], "size": [0.008, 3000, 0.008], "cells": 16})"),
         "fluid grid of 16 x 6e+06 x 16 cells (/domain)", {}},
        {"shape_outside_fluid_box", fluid_scene("", R"({"min": [0, 0, 0], "size": [0.008, 0.008, 0.008], "cells": 16})", "[1, 1, 1]"),
         "/surface/shape (within", {}},
        {"shape_far_from_origin",
         R"({"surface": {"shape": {"type": "sphere", "center": [1e15, 0, 0], "radius": 0.2},
             "edge_length": 0.05}})",
         "too far for double precision", {}},
        {"shapes_nested_deep", nested_unions(20), "shapes nested more than 16 deep", {}},
        {"json_nested_deep", nested_unions(5000), "deep (at most 64)", {}},
        {"too_many_primitives", many_spheres(300), "more than 256 primitive shapes", {}},
        {"out_is_a_file", R"({"surface": {"shape": {"type": "sphere"}}})",
         "--out /proc/version: exists and is not a folder", {"--out", "/proc/version"}},
        {"out_below_a_file", R"({"surface": {"shape": {"type": "sphere"}}})",
         "--out /proc/version/frames: cannot create the output folder",
         {"--out", "/proc/version/frames"}},
    };
}

INSTANTIATE_TEST_SUITE_P(Cases, RefusedScenes, testing::ValuesIn(bad_scenes()),
                         [](const testing::TestParamInfo<BadScene>& param) { return param.param.name; });

// ---- mesh files: refused in the file's own terms -----------------------------------------

TEST_F(Robustness, EmptyMeshFilesAndDirectoriesAreRefusedNamingTheFile) {
    write("empty.obj", "");
    write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    fs::create_directories(m_dir / "folder.obj");
    for (const char* mesh : {"empty.obj", "points.obj", "folder.obj"}) {
        const std::string scene =
            write("s.json", std::string(R"({"surface": {"mesh_file": ")") + mesh + "\"}}");
        const ChildResult r = run(scene);
        ASSERT_TRUE(r.exited) << describe(r);
        EXPECT_EQ(r.exit_code, 2) << mesh << ": " << describe(r);
        EXPECT_NE(r.output.find(mesh), std::string::npos) << describe(r);
    }
    const std::string scene = write("s.json", R"({"surface": {"mesh_file": "points.obj"}})");
    EXPECT_NE(run(scene).output.find("points.obj: no faces (3 vertices, 0 faces)"),
              std::string::npos);
    const std::string dir_scene = write("d.json", R"({"surface": {"mesh_file": "folder.obj"}})");
    EXPECT_NE(run(dir_scene).output.find("folder.obj: is a directory, not a mesh file"),
              std::string::npos);
}

TEST_F(Robustness, SceneFileThatIsADirectoryIsRefused) {
    fs::create_directories(m_dir / "scene_dir.json");
    const ChildResult r = run((m_dir / "scene_dir.json").string());
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_NE(r.output.find("scene_dir.json: is a directory, not a scene file"), std::string::npos)
        << describe(r);
}

TEST_F(Robustness, InsideOutMeshIsRefusedWithTheFix) {
    write("inside_out.obj", octahedron(0.2, true));
    const std::string scene = write("s.json", R"({"surface": {"mesh_file": "inside_out.obj"}})");
    const ChildResult r = run(scene);
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_NE(r.output.find("inside_out.obj: the surface is inside-out"), std::string::npos)
        << describe(r);
    EXPECT_NE(r.output.find("set /surface/inside to \"gas\""), std::string::npos) << describe(r);
}

TEST_F(Robustness, NestedSurfacesMustAlternateTheirWinding) {
    // A smaller octahedron inside a larger one, both wound outward: refused. Wound inward (a
    // cavity), the same pair is a valid shell and runs.
    write("same.obj", octahedron(0.3, false) + octahedron(0.1, false, 7));
    write("shell.obj", octahedron(0.3, false) + octahedron(0.1, true, 7));
    const ChildResult same =
        run(write("s.json", R"({"surface": {"mesh_file": "same.obj"}, "flow": {"type": "none"},
                              "time": {"end": 0.02, "frames": 1}, "output": {"vdb": false}})"));
    EXPECT_EQ(same.exit_code, 2) << describe(same);
    EXPECT_NE(same.output.find("lies inside another (e.g. the face on line 7) and winds the same way"),
              std::string::npos)
        << describe(same);
    const ChildResult shell =
        run(write("t.json", R"({"surface": {"mesh_file": "shell.obj"}, "flow": {"type": "none"},
                              "time": {"end": 0.02, "frames": 1}, "output": {"vdb": false}})"));
    EXPECT_EQ(shell.exit_code, 0) << describe(shell);
}

TEST_F(Robustness, MeshOutsideTheFluidBoxIsRefused) {
    write("far.obj", octahedron(0.002, false));
    const std::string scene = write(
        "s.json", R"({"flow": {"type": "fluid"}, "surface": {"mesh_file": "far.obj"},
                     "domain": {"min": [1, 1, 1], "size": [0.008, 0.008, 0.008], "cells": 16}})");
    const ChildResult r = run(scene);
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_NE(r.output.find("far.obj"), std::string::npos) << describe(r);
    EXPECT_NE(r.output.find("lies entirely outside the fluid box /domain"), std::string::npos)
        << describe(r);
}

TEST_F(Robustness, MeshProblemsUseTheFilesOwnNumbers) {
    // OBJ: vertices from 1, faces by line. The duplicate face is on line 15, its twin on 7.
    write("dup.obj", std::string(OCTAHEDRON_OBJ) + "f 1 3 5\n");
    const ChildResult dup = run(write("s.json", R"({"surface": {"mesh_file": "dup.obj"}})"));
    EXPECT_EQ(dup.exit_code, 2) << describe(dup);
    EXPECT_NE(dup.output.find("duplicate triangle: the face on line 15 (vertices 1, 3, 5) has the "
                              "same vertices as the face on line 7"),
              std::string::npos)
        << describe(dup);
    write("range.obj", std::string(OCTAHEDRON_OBJ) + "f 1 2 9\n");
    const ChildResult range = run(write("r.json", R"({"surface": {"mesh_file": "range.obj"}})"));
    EXPECT_EQ(range.exit_code, 2) << describe(range);
    EXPECT_NE(range.output.find("the face on line 15 refers to vertex 9, but the file has 6 "
                                "vertices (vertices numbered from 1"),
              std::string::npos)
        << describe(range);
}

TEST_F(Robustness, FaceIndexFarBeyondTheVerticesIsRefusedBeforeAnythingReadsIt) {
    // Was a crash (signal 11): the memory estimate summed the triangle areas before the
    // indices were checked, reading position 2e9 of 6.
    write("far_index.obj", std::string(OCTAHEDRON_OBJ) + "f 1 2 2000000000\n");
    const ChildResult r = run(write("s.json", R"({"surface": {"mesh_file": "far_index.obj"}})"));
    ASSERT_TRUE(r.exited) << describe(r);
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_NE(r.output.find("far_index.obj: the face on line 15 refers to vertex 2000000000, but "
                            "the file has 6 vertices"),
              std::string::npos)
        << describe(r);
}

TEST_F(Robustness, PlyCountsAreCheckedAgainstTheFileSize) {
    // A 9 KB binary PLY whose face count says 2e9: refused at once, within the memory bound.
    std::string ply =
        "ply\nformat binary_little_endian 1.0\nelement vertex 6\nproperty float x\n"
        "property float y\nproperty float z\nelement face 2000000000\n"
        "property list uchar int vertex_indices\nend_header\n";
    ply += std::string(9000, '\0');
    write("huge.ply", ply);
    const ChildResult r = run(write("s.json", R"({"surface": {"mesh_file": "huge.ply"}})"));
    ASSERT_TRUE(r.exited) << describe(r);
    EXPECT_EQ(r.exit_code, 2) << describe(r);
    EXPECT_NE(r.output.find("huge.ply: the header declares 2000000000 'face' elements"),
              std::string::npos)
        << describe(r);
    EXPECT_LT(r.seconds, 10.0) << describe(r);
}

// ---- signals --------------------------------------------------------------------------

/// A geometric-flow scene whose steps take seconds each (4096 curl-noise modes evaluated four
/// times at 14 000 vertices), with frame 0 written after a few seconds of meshing.
const char* SLOW_STEP_SCENE = R"({
  "surface": {"edge_length": 0.008, "shape": {"type": "sphere", "center": [0, 0, 0], "radius": 0.25}},
  "flow": {"type": "curl_noise", "curl_noise": {"octaves": 1, "modes_per_octave": 4096,
           "base_wavelength": 0.5, "rms_speed": 0.07}},
  "time": {"end": 100, "frames": 10, "dt": 0.05}, "output": {"vdb": false}})";

/// Runs SLOW_STEP_SCENE, sends `signals` (in order) `delay` seconds after frame 0 exists, and
/// returns how it ended and how long after the first signal.
ChildResult run_and_signal(const fs::path& dir, const std::string& scene,
                           const std::vector<int>& signals, double delay, double* after_signal,
                           bool stopped_together = false) {
    const fs::path out = dir / "out";
    double first_frame_at = -1.0, signalled_at = -1.0;
    ChildLimits limits;
    limits.wall_seconds = 300.0;
    const ChildResult r = run_child(
        {MENISCUS_BINARY, "run", scene, "--quiet", "--out", out.string()}, limits,
        (dir / "log.txt").string(), [&](pid_t pid, double t) {
            if (first_frame_at < 0.0 && fs::exists(out / "surface_0000.ply"))
                first_frame_at = t;
            if (first_frame_at >= 0.0 && signalled_at < 0.0 && t > first_frame_at + delay) {
                signalled_at = t;
                if (stopped_together)
                    kill(pid, SIGSTOP);
                for (int s : signals)
                    kill(pid, s);
                if (stopped_together)
                    kill(pid, SIGCONT);
            }
        });
    *after_signal = signalled_at >= 0.0 ? r.seconds - signalled_at : -1.0;
    return r;
}

void expect_complete_frames_only(const fs::path& out, int min_lines = 1) {
    std::ifstream stats(out / "stats.jsonl", std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(stats)), std::istreambuf_iterator<char>());
    EXPECT_TRUE(text.empty() || text.back() == '\n') << "stats.jsonl ends in a partial line";
    std::istringstream in(text);
    int lines = 0;
    for (std::string line; std::getline(in, line);) {
        EXPECT_TRUE(line.size() > 2 && line.front() == '{' && line.back() == '}')
            << "stats.jsonl line " << lines + 1 << " is not a whole JSON object: " << line;
        ++lines;
    }
    for (const auto& entry : fs::directory_iterator(out)) {
        const std::string name = entry.path().filename().string();
        EXPECT_EQ(name.find(".partial"), std::string::npos) << name;
        std::smatch m;
        if (std::regex_match(name, m, std::regex("(surface|fields)_(\\d{4})\\..*"))) {
            EXPECT_LT(std::stoi(m[2]), lines) << name << " has no stats line";
        }
    }
    EXPECT_GE(lines, min_lines);
}

TEST_F(Robustness, SigintStopsInsideALongStepWithin2Seconds) {
    const std::string scene = write("slow.json", SLOW_STEP_SCENE);
    double after = 0.0;
    const ChildResult r = run_and_signal(m_dir, scene, {SIGINT}, 1.0, &after);
    ASSERT_TRUE(r.exited) << describe(r);
    EXPECT_EQ(r.exit_code, 130) << describe(r);
    EXPECT_GE(after, 0.0) << describe(r);
    EXPECT_LT(after, SIGNAL_RESPONSE_SECONDS) << describe(r);
    EXPECT_NE(r.output.find("interrupted at t = 0 s; frames 0..0"), std::string::npos)
        << describe(r);
    expect_complete_frames_only(m_dir / "out");
}

TEST_F(Robustness, SigtermStopsLikeSigintWithExit143) {
    const std::string scene = write("slow.json", SLOW_STEP_SCENE);
    double after = 0.0;
    const ChildResult r = run_and_signal(m_dir, scene, {SIGTERM}, 1.0, &after);
    ASSERT_TRUE(r.exited) << describe(r);
    EXPECT_EQ(r.exit_code, 143) << describe(r);
    EXPECT_LT(after, SIGNAL_RESPONSE_SECONDS) << describe(r);
    expect_complete_frames_only(m_dir / "out");
}

TEST_F(Robustness, SecondSignalEndsTheRunAtOnce) {
    // Both signals pending together (the child stopped while they arrive): the first asks for
    // a clean stop, the second ends the process by its default action.
    const std::string scene = write("slow.json", SLOW_STEP_SCENE);
    double after = 0.0;
    const ChildResult r =
        run_and_signal(m_dir, scene, {SIGINT, SIGTERM}, 0.5, &after, /*stopped_together=*/true);
    ASSERT_FALSE(r.exited) << describe(r);
    EXPECT_TRUE(r.signal == SIGTERM || r.signal == SIGINT) << describe(r);
    EXPECT_LT(after, SIGNAL_RESPONSE_SECONDS) << describe(r);
}

TEST_F(Robustness, SigintWhileMeshingExits130BeforeTheFirstFrame) {
    // 100 remeshing passes over 72 000 triangles: tens of seconds before frame 0.
    const std::string scene = write(
        "mesh.json", R"({"surface": {"edge_length": 0.004, "remesh_iterations": 100,
                         "shape": {"type": "sphere", "radius": 0.2}},
                         "flow": {"type": "none"}, "output": {"vdb": false}})");
    double signalled_at = -1.0;
    ChildLimits limits;
    limits.wall_seconds = 300.0;
    const ChildResult r = run_child(
        {MENISCUS_BINARY, "run", scene, "--quiet", "--out", (m_dir / "out").string()}, limits,
        (m_dir / "log.txt").string(), [&](pid_t pid, double t) {
            if (signalled_at < 0.0 && t > 1.0) {
                signalled_at = t;
                kill(pid, SIGINT);
            }
        });
    ASSERT_TRUE(r.exited) << describe(r);
    EXPECT_EQ(r.exit_code, 130) << describe(r);
    EXPECT_NE(r.output.find("interrupted before the first frame"), std::string::npos)
        << describe(r);
    EXPECT_LT(r.seconds - signalled_at, SIGNAL_RESPONSE_SECONDS) << describe(r);
    EXPECT_FALSE(fs::exists(m_dir / "out" / "surface_0000.ply"));
}

// ---- writes ---------------------------------------------------------------------------

const char* SMALL_SCENE = R"({
  "surface": {"edge_length": 0.05, "shape": {"type": "sphere", "center": [0.5, 0.5, 0.5], "radius": 0.15}},
  "time": {"end": 0.04, "frames": 2, "dt": 0.01}, "output": {"vdb": %VDB%, "ply": %PLY%}})";

std::string small_scene(bool ply, bool vdb) {
    std::string s = SMALL_SCENE;
    s.replace(s.find("%VDB%"), 5, vdb ? "true" : "false");
    s.replace(s.find("%PLY%"), 5, ply ? "true" : "false");
    return s;
}

TEST_F(Robustness, FailedWritesAreExitOneNamingTheFileAndLeaveNothingUnderItsName) {
    // RLIMIT_FSIZE makes every write past 4 kB fail (EFBIG): an injected write failure.
    for (const bool vdb : {false, true}) {
        const fs::path out = m_dir / (vdb ? "out_vdb" : "out_ply");
        const std::string scene = write("s.json", small_scene(!vdb, vdb));
        ChildLimits limits = refusal_limits();
        limits.file_size_bytes = 4096;
        const ChildResult r = run(scene, {"--out", out.string()}, limits);
        ASSERT_TRUE(r.exited) << describe(r);
        EXPECT_EQ(r.exit_code, 1) << describe(r);
        const std::string file = vdb ? "fields_0000.vdb" : "surface_0000.ply";
        EXPECT_NE(r.output.find("cannot write output: " + (out / file).string() +
                                ": write failed: File too large"),
                  std::string::npos)
            << describe(r);
        EXPECT_FALSE(fs::exists(out / file)) << describe(r);
        EXPECT_FALSE(fs::exists(out / (file + ".partial"))) << describe(r);
    }
}

TEST_F(Robustness, FailedStatsLineIsCutBackWithItsFrameFiles) {
    // Frame 0's PLY (about 9 kB) fits under a 12 kB file-size bound, stats.jsonl (about
    // 640 bytes a line) outgrows it near frame 19: the line that fails is cut back off and its
    // frame's PLY removed, so every PLY left has a whole stats line.
    // Checkpoints off: checkpoint.bin (tens of kB) would hit the bound first (the next test).
    std::string scene_text = small_scene(true, false);
    scene_text.replace(scene_text.find("\"frames\": 2"), 11, "\"frames\": 40");
    scene_text.replace(scene_text.find("\"end\": 0.04"), 11, "\"end\": 0.4");
    scene_text.replace(scene_text.find("\"output\": {"), 11, "\"output\": {\"checkpoint_every\": 0, ");
    const fs::path out = m_dir / "out";
    ChildLimits limits = refusal_limits();
    limits.file_size_bytes = 12000;
    const ChildResult r = run(write("s.json", scene_text), {"--out", out.string()}, limits);
    ASSERT_TRUE(r.exited) << describe(r);
    EXPECT_EQ(r.exit_code, 1) << describe(r);
    EXPECT_NE(r.output.find("cannot write output: " + (out / "stats.jsonl").string() +
                            ": write failed: File too large"),
              std::string::npos)
        << describe(r);
    ASSERT_TRUE(fs::exists(out / "surface_0005.ply")) << "the bound should hit stats.jsonl late";
    expect_complete_frames_only(out);
}

TEST_F(Robustness, FailedCheckpointWriteIsExitOneAndLeavesCompleteFramesOnly) {
    // The checkpoint is written after its frame's files and before its stats line: when it
    // cannot be written the frame is cut back like a failed stats line, and no temporary is
    // left (an earlier frame's checkpoint.bin stays whole).
    std::string scene_text = small_scene(true, false);
    const fs::path out = m_dir / "out";
    ChildLimits limits = refusal_limits();
    limits.file_size_bytes = 12000;
    const ChildResult r = run(write("s.json", scene_text), {"--out", out.string()}, limits);
    ASSERT_TRUE(r.exited) << describe(r);
    EXPECT_EQ(r.exit_code, 1) << describe(r);
    EXPECT_NE(r.output.find("cannot write output: " + (out / "checkpoint.bin").string() +
                            ": write failed: File too large"),
              std::string::npos)
        << describe(r);
    EXPECT_FALSE(fs::exists(out / "checkpoint.bin.partial")) << describe(r);
    expect_complete_frames_only(out, 0);
}

TEST_F(Robustness, StalePartialFilesAreRemovedByTheNextRun) {
    const fs::path out = m_dir / "out";
    fs::create_directories(out);
    std::ofstream(out / "fields_0003.vdb.partial") << "half a file";
    const ChildResult r = run(write("s.json", small_scene(true, false)), {"--frames", "1"});
    EXPECT_EQ(r.exit_code, 0) << describe(r);
    EXPECT_FALSE(fs::exists(out / "fields_0003.vdb.partial"));
    EXPECT_TRUE(fs::exists(out / "surface_0001.ply"));
}

TEST_F(Robustness, FullDiskLeavesOnlyCompleteReadableFrames) {
    // A real full disk: a small tmpfs (needs root; CI runs as root).
    const fs::path mount_point = m_dir / "tmpfs";
    fs::create_directories(mount_point);
    if (mount("tmpfs", mount_point.c_str(), "tmpfs", 0, "size=96k") != 0)
        GTEST_SKIP() << "cannot mount a tmpfs here (not root?)";
    const fs::path out = mount_point / "out";
    std::string scene_text = small_scene(true, true);
    scene_text.replace(scene_text.find("\"frames\": 2"), 11, "\"frames\": 40");
    scene_text.replace(scene_text.find("\"end\": 0.04"), 11, "\"end\": 0.4");
    const ChildResult r = run(write("s.json", scene_text), {"--out", out.string()});
    EXPECT_EQ(r.exit_code, 1) << describe(r);
    EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << describe(r);
    expect_complete_frames_only(out);
    openvdb::initialize();
    for (const auto& entry : fs::directory_iterator(out)) {
        const std::string path = entry.path().string();
        if (entry.path().extension() == ".ply") {
            EXPECT_NO_THROW(meniscus::tracker::read_ply(path)) << path;
        }
        if (entry.path().extension() == ".vdb") {
            openvdb::io::File file(path);
            EXPECT_NO_THROW({
                file.open();
                file.getGrids();
                file.close();
            }) << path;
        }
    }
    umount(mount_point.c_str());
}

}  // namespace
