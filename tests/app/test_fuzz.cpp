// Fuzzing `meniscus run` with broken input: seeded mutations of every shipped scene
// (scenes/*.json, scenes/flows/*.json) and of the test meshes (tests/data), each run as a child
// process with --frames 1 --max-steps 2 under a wall-time bound and an address-space bound.
// Bad input must be refused (exit 2) or run (exit 0): never a signal, never exit 1 ("internal
// failure"), never a hang, never an allocation past the bound. Each shard runs its own cases
// from its own seed, so a failure names a reproducible case; the failing scene text is printed.

#include "child_process.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using meniscus::test::ChildLimits;
using meniscus::test::ChildResult;

/// Shards (ctest runs them in parallel) × cases per shard.
constexpr int SHARDS = 8;
constexpr int CASES_PER_SHARD = 40;
constexpr std::uint64_t SEED = 20240537;
/// Per case: the memory the run may plan for (--max-memory, GB: the finest shipped scenes are
/// refused, which keeps cases short), the address space it may take (RLIMIT_AS: the plan,
/// the libraries and thread stacks, with room for the estimate's error) and the wall time
/// after which it counts as hung (generous: the suite runs tests in parallel on two cores).
const char* CASE_MAX_MEMORY_GB = "0.3";
constexpr unsigned long long CASE_ADDRESS_SPACE = 3ull << 30;
constexpr double CASE_WALL_SECONDS = 60.0;
/// Sanitizer builds run several times slower.
constexpr double SANITIZER_SLOWDOWN = 5.0;

std::string read_text(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_text(const fs::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
}

/// Every shipped scene, with mesh_file made absolute (the cases run from a temporary folder).
std::vector<std::pair<std::string, json>> shipped_scenes() {
    std::vector<std::pair<std::string, json>> scenes;
    for (const char* dir : {"scenes", "scenes/flows"}) {
        std::vector<fs::path> files;
        for (const auto& entry : fs::directory_iterator(fs::path(MENISCUS_SOURCE_DIR) / dir))
            if (entry.path().extension() == ".json")
                files.push_back(entry.path());
        std::sort(files.begin(), files.end());
        for (const fs::path& f : files) {
            json j = json::parse(read_text(f));
            if (j.contains("surface") && j["surface"].contains("mesh_file"))
                j["surface"]["mesh_file"] =
                    (f.parent_path() / j["surface"]["mesh_file"].get<std::string>()).string();
            scenes.emplace_back(f.filename().string(), std::move(j));
        }
    }
    return scenes;
}

/// A parsed OBJ (positions, faces with 0-based indices).
struct Obj {
    std::vector<std::array<double, 3>> v;
    std::vector<std::vector<long long>> f;
};

Obj read_obj(const fs::path& p) {
    Obj o;
    std::istringstream in(read_text(p));
    for (std::string line; std::getline(in, line);) {
        std::istringstream w(line);
        std::string k;
        w >> k;
        if (k == "v") {
            std::array<double, 3> x{};
            w >> x[0] >> x[1] >> x[2];
            o.v.push_back(x);
        } else if (k == "f") {
            std::vector<long long> face;
            for (std::string t; w >> t;)
                face.push_back(std::stoll(t.substr(0, t.find('/'))) - 1);
            o.f.push_back(face);
        }
    }
    return o;
}

std::string to_obj(const Obj& o) {
    std::ostringstream s;
    s.precision(17);
    for (const auto& x : o.v)
        s << "v " << x[0] << ' ' << x[1] << ' ' << x[2] << '\n';
    for (const auto& f : o.f) {
        s << 'f';
        for (long long i : f)
            s << ' ' << i + 1;
        s << '\n';
    }
    return s.str();
}

/// Binary little-endian PLY of `o`; `face_count` overrides the declared face count.
std::string to_ply(const Obj& o, long long face_count) {
    std::ostringstream s;
    s << "ply\nformat binary_little_endian 1.0\nelement vertex " << o.v.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << face_count
      << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (const auto& x : o.v)
        for (double c : x) {
            const float f = static_cast<float>(c);
            s.write(reinterpret_cast<const char*>(&f), 4);
        }
    for (const auto& f : o.f) {
        const auto n = static_cast<unsigned char>(f.size());
        s.write(reinterpret_cast<const char*>(&n), 1);
        for (long long i : f) {
            const auto k = static_cast<std::int32_t>(i);
            s.write(reinterpret_cast<const char*>(&k), 4);
        }
    }
    return s.str();
}

/// JSON pointers of every value under `j` (leaves and containers).
void collect_paths(const json& j, const std::string& path, std::vector<std::string>& out) {
    out.push_back(path);
    if (j.is_object())
        for (const auto& item : j.items())
            collect_paths(item.value(), path + "/" + item.key(), out);
    else if (j.is_array())
        for (size_t i = 0; i < j.size(); ++i)
            collect_paths(j[i], path + "/" + std::to_string(i), out);
}

/// One generated case: the scene text, extra files it refers to, extra arguments.
struct Case {
    std::string description;
    std::string scene_text;
    std::vector<std::pair<std::string, std::string>> files;  ///< name → contents
    std::vector<std::string> arguments;
};

class Generator {
public:
    Generator(std::uint64_t seed, const fs::path& dir) : m_rng(seed), m_dir(dir) {
        m_scenes = shipped_scenes();
        for (const char* mesh : {"sphere.obj", "torus.obj", "dumbbell.obj", "open_cap.obj",
                                 "edge_sharing_cubes.obj"})
            m_meshes.emplace_back(mesh, read_obj(fs::path(MENISCUS_TEST_DATA_DIR) / mesh));
    }

    Case next() {
        const int kind = static_cast<int>(pick(100));
        // Mesh files go into geometric-flow scenes (the fluid scenes' boxes are millimetres).
        std::pair<std::string, json> chosen = m_scenes[pick(m_scenes.size())];
        while (kind >= 50 && kind < 70 && chosen.second.contains("flow") &&
               chosen.second["flow"].value("type", "") == "fluid")
            chosen = m_scenes[pick(m_scenes.size())];
        Case c;
        json scene = chosen.second;
        c.description = chosen.first;
        if (kind < 40) {
            const int n = 1 + static_cast<int>(pick(3));
            for (int i = 0; i < n; ++i)
                scale_number(scene, c.description);
        } else if (kind < 45) {
            mutate_value(scene, c.description);
        } else if (kind < 48) {
            mutate_structure(scene, c.description);
        } else if (kind < 50) {
            deep_nesting(scene, c.description);
        } else if (kind < 70) {
            mesh_case(scene, c);
        } else if (kind < 76) {
            std::string text = scene.dump(1);
            const size_t cut = pick(text.size());
            c.description += " truncated at byte " + std::to_string(cut);
            c.scene_text = text.substr(0, cut);
        } else if (kind < 84) {
            raw_number(scene, c);
        } else if (kind < 90) {
            command_line(c);
        } else {
            mutate_value(scene, c.description);
            mutate_structure(scene, c.description);
        }
        if (c.scene_text.empty())
            c.scene_text = scene.dump(1);
        return c;
    }

private:
    size_t pick(size_t n) { return n == 0 ? 0 : static_cast<size_t>(m_rng() % n); }

    json extreme_value() {
        static const std::vector<json> values = {
            0,      -1,       1e308,     -1e308, 1e-300, -1e-300, 1e30,  1e-30,  1e9,
            -1e9,   1e6,      2147483648LL, -2147483649LL, 0.5, 1e15, 3,     "NaN",  "inf",
            true,   nullptr,  json::array(), json::object(), json::array({1, 2}),
            json::array({1e308, 1e308, 1e308}), json::array({-1, -1, -1}),
            json::array({0, 0, 0}), 18446744073709551615ULL};
        return values[pick(values.size())];
    }

    /// A number of the scene scaled (mildly or wildly), negated or zeroed: values of the right
    /// type that reach the solvers.
    void scale_number(json& scene, std::string& description) {
        std::vector<std::string> paths;
        collect_paths(scene, "", paths);
        std::vector<std::string> numbers;
        for (const std::string& p : paths)
            if (scene.at(json::json_pointer(p)).is_number())
                numbers.push_back(p);
        if (numbers.empty())
            return mutate_value(scene, description);
        const std::string p = numbers[pick(numbers.size())];
        const json& old = scene.at(json::json_pointer(p));
        static const double factors[] = {1e-9, 1e-4, 0.01, 0.1, 0.3, 0.5, 0.9, 1.1, 2.0,
                                         3.0,  10.0, 100.0, 1e4, 1e9, -1.0, 0.0};
        json v = old.get<double>() * factors[pick(16)];
        if (old.is_number_integer())
            v = static_cast<long long>(std::clamp(v.get<double>(), -9e18, 9e18));
        description += "; " + p + " = " + v.dump();
        scene[json::json_pointer(p)] = v;
    }

    void mutate_value(json& scene, std::string& description) {
        std::vector<std::string> paths;
        collect_paths(scene, "", paths);
        std::vector<std::string> leaves;
        for (const std::string& p : paths)
            if (!p.empty() && scene.at(json::json_pointer(p)).is_primitive() &&
                p.find("description") == std::string::npos)
                leaves.push_back(p);
        if (leaves.empty())
            return;
        const std::string p = leaves[pick(leaves.size())];
        json v = extreme_value();
        // Scale an existing number instead, half of the time: plausible-looking extremes.
        const json& old = scene.at(json::json_pointer(p));
        if (old.is_number() && pick(2) == 0) {
            static const double factors[] = {1e-12, 1e-6, 1e-3, 0.1, 0.5, 2.0,
                                             10.0,  1e3,  1e6,  1e12, -1.0, 0.0};
            v = old.get<double>() * factors[pick(12)];
            if (old.is_number_integer() && std::abs(v.get<double>()) < 9e18)
                v = static_cast<long long>(v.get<double>());
        }
        description += "; " + p + " = " + v.dump();
        scene[json::json_pointer(p)] = v;
    }

    void mutate_structure(json& scene, std::string& description) {
        std::vector<std::string> paths;
        collect_paths(scene, "", paths);
        const std::string p = paths[pick(paths.size())];
        const int what = static_cast<int>(pick(3));
        if (what == 0 && !p.empty()) {
            description += "; removed " + p;
            const auto slash = p.rfind('/');
            json& parent = scene[json::json_pointer(p.substr(0, slash))];
            const std::string key = p.substr(slash + 1);
            if (parent.is_object())
                parent.erase(key);
            else if (parent.is_array() && !parent.empty())
                parent.erase(parent.begin() + static_cast<long>(std::stoul(key)));
        } else if (what == 1) {
            json& node = scene[json::json_pointer(p)];
            if (node.is_object()) {
                node["bogus_key"] = 1;
                description += "; unknown key under " + p;
            } else {
                node = json::object({{"type", "sphere"}});
                description += "; " + p + " = an object";
            }
        } else {
            // A shipped section swapped for another scene's.
            const json& other = m_scenes[pick(m_scenes.size())].second;
            for (const char* section : {"fluid", "domain", "flow", "tracker", "time", "coupling"})
                if (other.contains(section) && pick(2) == 0) {
                    scene[section] = other[section];
                    description += std::string("; /") + section + " from another scene";
                }
        }
    }

    void deep_nesting(json& scene, std::string& description) {
        if (!scene.contains("surface") || !scene["surface"].contains("shape"))
            return mutate_value(scene, description);
        static const int depths[] = {2, 8, 17, 40, 300, 5000};
        const int depth = depths[pick(6)];
        json shape = scene["surface"]["shape"];
        for (int i = 0; i < depth; ++i)
            shape = json{{"type", pick(2) ? "union" : "intersection"}, {"shapes", json::array({shape})}};
        scene["surface"]["shape"] = shape;
        description += "; shape nested " + std::to_string(depth) + " deep";
    }

    void raw_number(const json& scene, Case& c) {
        // Numbers nlohmann cannot hold, written into the text.
        std::vector<std::string> paths;
        collect_paths(scene, "", paths);
        std::vector<std::string> numbers;
        for (const std::string& p : paths)
            if (scene.at(json::json_pointer(p)).is_number())
                numbers.push_back(p);
        json copy = scene;
        if (numbers.empty())
            return;
        const std::string p = numbers[pick(numbers.size())];
        copy[json::json_pointer(p)] = "@RAW@";
        static const char* raws[] = {"1e400", "-1e400", "1e-400", "123456789012345678901234567890",
                                     "-0", "NaN", "Infinity", "0x10", "1.", ".5"};
        const char* raw = raws[pick(10)];
        std::string text = copy.dump(1);
        text.replace(text.find("\"@RAW@\""), 7, raw);
        c.scene_text = text;
        c.description += "; " + p + " = " + raw + " (raw text)";
    }

    void command_line(Case& c) {
        static const std::vector<std::vector<std::string>> lines = {
            {"--frames", "0"},        {"--frames", "-3"},         {"--max-steps", "1e3"},
            {"--out"},                {"--max-memory", "0"},      {"--max-memory", "abc"},
            {"--max-steps-per-frame", "-1"}, {"--unknown"},       {"--frames", "99999999999"},
            {"--out", "@FILE@"}, {"--out", "/proc/version/x"}};
        c.arguments = lines[pick(lines.size())];
        for (std::string& a : c.arguments)
            if (a == "@FILE@")
                a = (m_dir / "a_file").string();
        std::string joined;
        for (const std::string& a : c.arguments)
            joined += " " + a;
        c.description += "; arguments" + joined;
    }

    void mesh_case(json& scene, Case& c) {
        const auto& [mesh_name, base] = m_meshes[pick(m_meshes.size())];
        Obj o = base;
        std::string contents;
        std::string file = "mesh.obj";
        c.description += "; mesh_file " + mesh_name;
        const int what = static_cast<int>(pick(14));
        switch (what) {
            case 0:  // inside-out
                for (auto& f : o.f)
                    std::reverse(f.begin(), f.end());
                c.description += " reversed";
                break;
            case 1:  // far away
                for (auto& x : o.v)
                    x[0] += pick(2) ? 1.0 : 1e9;
                c.description += " translated";
                break;
            case 2:  // scaled to extremes
            {
                const double s = pick(2) ? 1e-20 : 1e20;
                for (auto& x : o.v)
                    for (double& v : x)
                        v *= s;
                c.description += " scaled";
                break;
            }
            case 3:  // nested copy, same orientation
            {
                const size_t n = o.v.size();
                const size_t nf = o.f.size();
                for (size_t i = 0; i < n; ++i)
                    o.v.push_back({0.5 * o.v[i][0], 0.5 * o.v[i][1], 0.5 * o.v[i][2]});
                for (size_t i = 0; i < nf; ++i) {
                    auto f = o.f[i];
                    for (long long& k : f)
                        k += static_cast<long long>(n);
                    o.f.push_back(f);
                }
                c.description += " with a half-size copy inside";
                break;
            }
            case 4:
                o.f.clear();
                c.description += " without faces";
                break;
            case 5:
                o = Obj{};
                c.description += " empty";
                break;
            case 6:  // an index out of range / zero
                o.f[pick(o.f.size())][0] = pick(2) ? static_cast<long long>(o.v.size()) + 5 : -1;
                c.description += " bad index";
                break;
            case 7:  // NaN coordinate
                contents = to_obj(o);
                contents.replace(contents.find("v ") + 2, 0, "nan ");
                c.description += " NaN coordinate";
                break;
            case 8:  // a face removed (open)
                o.f.erase(o.f.begin() + static_cast<long>(pick(o.f.size())));
                c.description += " with a hole";
                break;
            case 9:  // bogus PLY face count
                file = "mesh.ply";
                contents = to_ply(o, pick(2) ? 2000000000LL : static_cast<long long>(o.f.size()) + 7);
                c.description += " as PLY with a bogus face count";
                break;
            case 10:  // PLY truncated
                file = "mesh.ply";
                contents = to_ply(o, static_cast<long long>(o.f.size()));
                contents.resize(pick(contents.size()));
                c.description += " as truncated PLY";
                break;
            case 11:  // OBJ truncated
                contents = to_obj(o);
                contents.resize(pick(contents.size()));
                c.description += " truncated";
                break;
            case 12:  // a directory
                file = "mesh_dir.obj";
                c.description += " (a directory)";
                break;
            default:  // a duplicated face
                o.f.push_back(o.f[pick(o.f.size())]);
                c.description += " with a duplicate face";
                break;
        }
        if (contents.empty() && file == "mesh.obj")
            contents = to_obj(o);
        if (file == "mesh.ply" && contents.empty())
            contents = to_ply(o, static_cast<long long>(o.f.size()));
        if (file != "mesh_dir.obj")
            c.files.emplace_back(file, contents);
        else
            fs::create_directories(m_dir / file);
        json surface = {{"mesh_file", (m_dir / file).string()}};
        if (scene.contains("surface") && scene["surface"].contains("inside"))
            surface["inside"] = scene["surface"]["inside"];
        scene["surface"] = surface;
        scene.erase("initial_velocity");
    }

    std::mt19937_64 m_rng;
    fs::path m_dir;
    std::vector<std::pair<std::string, json>> m_scenes;
    std::vector<std::pair<std::string, Obj>> m_meshes;
};

class FuzzRun : public testing::TestWithParam<int> {};

TEST_P(FuzzRun, BadInputIsRefusedOrRunsNeverCrashesHangsOrFailsInternally) {
    const int shard = GetParam();
    const fs::path dir = fs::temp_directory_path() / ("meniscus_fuzz_" + std::to_string(shard));
    fs::remove_all(dir);
    fs::create_directories(dir);
    write_text(dir / "a_file", "not a folder\n");
    Generator generator(SEED + static_cast<std::uint64_t>(shard), dir);
    // MENISCUS_FUZZ_VERBOSE=1 prints every case and the first line of its output.
    const bool verbose = std::getenv("MENISCUS_FUZZ_VERBOSE") != nullptr;
    std::map<int, int> outcomes;
    int failures = 0;
    double slowest = 0.0, total = 0.0;
    std::string slowest_case;
    for (int i = 0; i < CASES_PER_SHARD; ++i) {
        const Case c = generator.next();
        const fs::path scene = dir / "scene.json";
        write_text(scene, c.scene_text);
        for (const auto& [name, contents] : c.files)
            write_text(dir / name, contents);
        const fs::path out = dir / "out";
        fs::remove_all(out);
        std::vector<std::string> argv = {MENISCUS_BINARY, "run", scene.string(),
                                         "--quiet", "--frames", "1", "--max-steps", "2",
                                         "--max-memory", CASE_MAX_MEMORY_GB};
        bool custom_out = false;
        for (const std::string& a : c.arguments) {
            argv.push_back(a);
            custom_out = custom_out || a == "--out";
        }
        if (!custom_out) {
            argv.push_back("--out");
            argv.push_back(out.string());
        }
        ChildLimits limits;
        limits.wall_seconds = CASE_WALL_SECONDS;
        limits.address_space_bytes = CASE_ADDRESS_SPACE;
        if (meniscus::test::built_with_address_sanitizer())
            limits.wall_seconds *= SANITIZER_SLOWDOWN;
        const ChildResult r = meniscus::test::run_child(argv, limits, (dir / "log.txt").string());
        total += r.seconds;
        if (r.seconds > slowest) {
            slowest = r.seconds;
            slowest_case = c.description;
        }
        ++outcomes[r.exited ? r.exit_code : -1];
        const bool ok = r.exited && (r.exit_code == 0 || r.exit_code == 2);
        if (!ok) {
            ++failures;
            ADD_FAILURE() << "case " << shard << "." << i << " (" << c.description << "): "
                          << (r.timed_out ? "timed out"
                              : r.exited  ? "exit code " + std::to_string(r.exit_code)
                                          : "signal " + std::to_string(r.signal))
                          << " after " << r.seconds << " s\n--- output ---\n"
                          << r.output.substr(0, 2000) << "\n--- scene ---\n"
                          << c.scene_text.substr(0, 3000);
        }
        if (verbose)
            std::printf("case %d.%d (%s): %s %.1f s: %s\n", shard, i, c.description.c_str(),
                        r.exited ? ("exit " + std::to_string(r.exit_code)).c_str() : "killed",
                        r.seconds, r.output.substr(0, r.output.find('\n')).c_str());
    }
    std::printf("fuzz shard %d: %d cases in %.1f s (slowest %.1f s: %s); exit 0: %d, exit 2: %d, "
                "other: %d\n",
                shard, CASES_PER_SHARD, total, slowest, slowest_case.c_str(), outcomes[0],
                outcomes[2], CASES_PER_SHARD - outcomes[0] - outcomes[2]);
    EXPECT_EQ(failures, 0);
    fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Shards, FuzzRun, testing::Range(0, SHARDS));

}  // namespace
