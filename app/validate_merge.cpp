/// Part B of `meniscus validate`, B5: the shipped merge and pinch scenes run through run_scene()
/// exactly as `meniscus run` runs them, with the exact self-intersection test after every step,
/// read back from their stats.jsonl; and the convergence of the time of their first topology
/// change in Δt and in Δx.

#include "app/validate_merge.h"

#include "app/run.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace meniscus::app::validate_fluid {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// B5 pass/fail: relative drift of each phase's volume.
constexpr double B5_VOLUME_TOLERANCE = 0.005;

/// The time of a scene's first topology change (first frame whose component count differs
/// from the first frame's; −1 if none) from a run's stats.jsonl.
double topology_change_time(const std::filesystem::path& stats_path) {
    std::ifstream stats(stats_path);
    int first = -1;
    for (std::string line; std::getline(stats, line);) {
        const Json l = Json::parse(line);
        const int components = l["components"];
        if (first < 0)
            first = components;
        else if (components != first)
            return l["time"].get<double>();
    }
    return -1.0;
}

/// B5 convergence: the time of the first topology change of `scene_name` at its own
/// resolution at Δt, Δt/2, Δt/4 and at 4/3 and 2 times its cells (quick: its own resolution
/// at Δt and Δt/2), each run to one base frame past `base_event` (the base run's change).
/// Δt is the base run's mean step `mean_dt` times the factor, imposed as both the largest
/// step (/time/dt) and the frame spacing, so the change is resolved to one step. No exact
/// reference: the observed orders come from the differences of the three values along each
/// axis.
Json event_study(CaseContext& context, const std::string& scene_name, double base_event,
                 double frame_duration, double mean_dt) {
    const std::string path = std::string(MENISCUS_SCENES_DIR) + "/" + scene_name + ".json";
    std::ifstream in(path);
    const Json original = Json::parse(in);
    const int cells = original["domain"]["cells"];
    struct Variant {
        double scale, factor;
    };
    const std::vector<Variant> variants = context.options.full
                                              ? std::vector<Variant>{{1.0, 1.0},
                                                                     {1.0, 0.5},
                                                                     {1.0, 0.25},
                                                                     {4.0 / 3.0, 1.0},
                                                                     {2.0, 1.0}}
                                              : std::vector<Variant>{{1.0, 1.0}, {1.0, 0.5}};
    const double end = base_event + frame_duration;
    Json runs = Json::array();
    for (const Variant& v : variants) {
        Json j = original;
        j["domain"]["cells"] = static_cast<int>(std::lround(cells * v.scale));
        const double dt = mean_dt * v.factor;
        j["time"]["end"] = end;
        j["time"]["frames"] = static_cast<int>(std::ceil(end / dt));
        j["time"]["dt"] = dt;
        j["output"] = {{"ply", false}, {"vdb", false}, {"checkpoint_every", 0}};
        Scene scene = parse_scene(j.dump(), path, MENISCUS_SCENES_DIR);
        scene.tracker.verify_intersection_free = true;
        RunOptions ro;
        ro.out_dir = (context.options.out_dir / ("b5_study_" + scene_name)).string();
        ro.quiet = true;
        const std::atomic<bool> stop{false};
        const auto start = Clock::now();
        const RunResult rr = run_scene(scene, ro, stop);
        const double wall = seconds_since(start);
        const double event =
            topology_change_time(std::filesystem::path(ro.out_dir) / "stats.jsonl");
        std::filesystem::remove_all(ro.out_dir);
        const std::string what = "B5 " + scene_name + " at " +
                                 std::to_string(j["domain"]["cells"].get<int>()) + " cells, " +
                                 dt_factor_text(v.factor);
        if (rr.interrupted || rr.max_intersecting_pairs != 0 || event < 0.0) {
            context.out.all_ok = false;
            context.out.failures.push_back(what + (rr.max_intersecting_pairs != 0
                                                       ? ": intersecting triangle pairs"
                                                       : ": no topology change"));
        }
        context.log(what + ": topology change at " + fmt(1e3 * event) + " ms, " +
                    fmt(wall, "%.0f") + " s");
        runs.push_back({{"cells", j["domain"]["cells"]},
                        {"cells_scale", v.scale},
                        {"dt_factor", v.factor},
                        {"dt", dt},
                        {"steps", rr.steps},
                        {"event_time", event},
                        {"max_intersecting_pairs", rr.max_intersecting_pairs},
                        {"wall_seconds", wall}});
    }
    // Observed orders from three values v₁, v₂, v₃ at steps h, h/r₁, h/(r₁r₂): solve
    // (v₁ − v₂)/(v₂ − v₃) = (1 − r₁^−p)/(r₁^−p − (r₁r₂)^−p) for p by bisection.
    const auto order = [](double v1, double v2, double v3, double r1, double r2) -> Json {
        const double q = (v1 - v2) / (v2 - v3);
        if (!std::isfinite(q) || q <= 0.0)
            return nullptr;
        const auto f = [&](double p) {
            return (1.0 - std::pow(r1, -p)) / (std::pow(r1, -p) - std::pow(r1 * r2, -p)) - q;
        };
        double lo = 0.05, hi = 8.0;
        if (f(lo) * f(hi) > 0.0)
            return nullptr;
        for (int i = 0; i < 60; ++i) {
            const double mid = 0.5 * (lo + hi);
            (f(lo) * f(mid) <= 0.0 ? hi : lo) = mid;
        }
        return 0.5 * (lo + hi);
    };
    Json study = {{"mean_dt", mean_dt}, {"runs", runs}};
    const auto at = [&](size_t i) { return runs[i]["event_time"].get<double>(); };
    study["time_order"] = runs.size() >= 3 ? order(at(0), at(1), at(2), 2.0, 2.0) : Json(nullptr);
    study["space_order"] =
        runs.size() >= 5 ? order(at(0), at(3), at(4), 4.0 / 3.0, 1.5) : Json(nullptr);
    return study;
}

}  // namespace

void merge_scenes_case(CaseContext& context, std::ostringstream& md) {
    struct Case {
        const char* scene;
        int frames;  // 0 = the scene's own
        int components_before;
        int components_after_at_least;  // expected after the topology change
        bool merge;                     // true: fewer components expected
    };
    // Quick: drop_merge until the drops have merged (10 of 30 frames). Full: the shipped
    // scenes to their end. (The quick jet pinch-off is a suite test,
    // tests/coupling/test_scenes_physics.cpp.)
    const std::vector<Case> cases = context.options.full
                                        ? std::vector<Case>{{"drop_merge", 0, 2, 1, true},
                                                            {"bubble_merge", 0, 2, 1, true},
                                                            {"jet_pinch", 0, 1, 2, false}}
                                        : std::vector<Case>{{"drop_merge", 10, 2, 1, true}};
    Json runs = Json::array();
    for (const Case& c : cases) {
        Scene scene = load_scene(std::string(MENISCUS_SCENES_DIR) + "/" + c.scene + ".json");
        scene.tracker.verify_intersection_free = true;
        scene.output.ply = false;
        scene.output.vdb = false;
        RunOptions ro;
        ro.out_dir = (context.options.out_dir / ("b5_" + std::string(c.scene))).string();
        ro.frames = c.frames;
        ro.quiet = true;
        const std::atomic<bool> stop{false};
        const auto start = Clock::now();
        const RunResult rr = run_scene(scene, ro, stop);
        const double wall = seconds_since(start);
        std::ifstream stats(std::filesystem::path(ro.out_dir) / "stats.jsonl");
        std::vector<double> t, inside_volume, other_volume;
        std::vector<int> components;
        int merges = 0, splits = 0;
        const double box = scene.domain.size.prod();
        for (std::string line; std::getline(stats, line);) {
            const Json l = Json::parse(line);
            t.push_back(l["time"]);
            components.push_back(l["components"]);
            inside_volume.push_back(l["volume"]);
            other_volume.push_back(box - l["volume"].get<double>());
            merges += l.value("merges", 0);
            splits += l.value("splits", 0);
        }
        const bool completed =
            !rr.interrupted && !t.empty() &&
            rr.frames_written == (c.frames > 0 ? c.frames : scene.time.frames) + 1;
        const double drift_inside = max_relative_drift(inside_volume);
        const double drift_other = max_relative_drift(other_volume);
        const int final_components = components.empty() ? 0 : components.back();
        const bool topology_ok = !components.empty() && components.front() == c.components_before &&
                                 (c.merge ? final_components == c.components_after_at_least
                                          : final_components >= c.components_after_at_least);
        const std::string what = std::string("B5 ") + c.scene;
        if (!completed || rr.max_intersecting_pairs != 0 || drift_inside > B5_VOLUME_TOLERANCE ||
            drift_other > B5_VOLUME_TOLERANCE || !topology_ok) {
            context.out.all_ok = false;
            context.out.failures.push_back(what + ": " +
                                           (!completed ? "did not finish"
                                            : rr.max_intersecting_pairs != 0
                                                ? "intersecting triangle pairs"
                                            : !topology_ok ? "component count not as expected"
                                                           : "volume drift above 0.5 %"));
        }
        const std::string inside = scene.surface.inside;
        const std::string other = inside == "gas" ? "liquid" : "gas";
        runs.push_back(
            {{"scene", c.scene},
             {"frames", static_cast<int>(t.size()) - 1},
             {"t_end", t.empty() ? 0.0 : t.back()},
             {"steps", rr.steps},
             {"completed", completed},
             {"max_intersecting_pairs", rr.max_intersecting_pairs},
             {"components_initial", components.empty() ? 0 : components.front()},
             {"components_final", final_components},
             {"components_expected_final", c.components_after_at_least},
             {"expect_merge", c.merge},
             {"topology_ok", topology_ok},
             {"merges", merges},
             {"splits", splits},
             {"inside_phase", inside},
             {"volume_drift_inside", drift_inside},
             {"volume_drift_other", drift_other},
             {"wall_seconds", wall},
             {"series", {{"t", t}, {"components", components}, {"inside_volume", inside_volume}}}});
        context.log(what + ": components " + std::to_string(components.front()) + " → " +
                    std::to_string(final_components) + ", volume drift " +
                    fmt(100.0 * drift_inside, "%.3f") + " %, " + fmt(wall, "%.0f") + " s");
        std::filesystem::remove_all(ro.out_dir);
        double event = -1.0;
        for (size_t i = 1; i < components.size(); ++i)
            if (components[i] != components.front()) {
                event = t[i];
                break;
            }
        if (event > 0.0)
            runs.back()["convergence"] =
                event_study(context, c.scene, event, scene.time.end / scene.time.frames,
                            t.back() / static_cast<double>(std::max(1LL, rr.steps)));
    }
    context.out.results["B5"] = {{"runs", runs}, {"volume_tolerance", B5_VOLUME_TOLERANCE}};
    md << "## B5 — merge and pinch scenes\n\n"
       << "The shipped scenes through `meniscus run`'s loop with the exact self-intersection "
          "test after every step and volume correction on"
       << (context.options.full ? ""
                                : " (quick: drop_merge for its first 10 frames, by which the "
                                  "drops have merged; the quick jet pinch-off runs in the test "
                                  "suite, tests/coupling/test_scenes_physics.cpp)")
       << ". Volume drift: the largest |V(t)/V(0) − 1| over the frames, for the phase the "
          "surface encloses and for the other (box volume minus it).\n\n"
       << "| scene | frames | t end (s) | steps | components start → end | expected end | "
          "merges | splits | volume drift inside | volume drift other phase | target | max "
          "intersecting pairs | wall (s) |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Json& r : runs)
        md << "| " << r["scene"].get<std::string>() << " | " << r["frames"] << " | "
           << fmt(r["t_end"].get<double>()) << " | " << r["steps"] << " | "
           << r["components_initial"] << " → " << r["components_final"] << " | "
           << (r["expect_merge"].get<bool>() ? "" : "≥ ") << r["components_expected_final"] << " | "
           << r["merges"] << " | " << r["splits"] << " | "
           << fmt(100.0 * r["volume_drift_inside"].get<double>(), "%.3f %%") << " ("
           << r["inside_phase"].get<std::string>() << ") | "
           << fmt(100.0 * r["volume_drift_other"].get<double>(), "%.4f %%") << " | 0.5 % | "
           << r["max_intersecting_pairs"] << " | " << fmt(r["wall_seconds"].get<double>(), "%.0f")
           << " |\n";
    md << "\nConvergence: the time of the first topology change, each run to one frame past "
          "the change above with Δt the run above's mean step times 1, ½, ¼, imposed as the "
          "largest step and as the frame spacing (so each time below is resolved to its "
          "step), at the scene's own cells at Δt, Δt/2, Δt/4"
       << (context.options.full ? " and at 4/3 and 2 times its cells" : " (quick: Δt and Δt/2)")
       << ". There is no exact reference: the observed orders come from the differences "
          "of the three values along each axis.\n\n"
          "| scene | cells | Δt | Δt (s) | steps | topology change at (ms) | max intersecting "
          "pairs | wall (s) |\n|---|---|---|---|---|---|---|---|\n";
    for (const Json& r : runs) {
        if (!r.contains("convergence"))
            continue;
        for (const Json& v : r["convergence"]["runs"])
            md << "| " << r["scene"].get<std::string>() << " | " << v["cells"] << " | "
               << dt_factor_text(v["dt_factor"].get<double>()) << " | "
               << fmt(v["dt"].get<double>(), "%.3g") << " | " << v["steps"] << " | "
               << fmt(1e3 * v["event_time"].get<double>(), "%.4g") << " | "
               << v["max_intersecting_pairs"] << " | "
               << fmt(v["wall_seconds"].get<double>(), "%.0f") << " |\n";
    }
    md << "\n";
    for (const Json& r : runs) {
        if (!r.contains("convergence"))
            continue;
        const Json& c = r["convergence"];
        const auto text = [](const Json& o) {
            return o.is_null() ? std::string("— (not monotone)") : fmt(o.get<double>(), "%.2f");
        };
        md << r["scene"].get<std::string>() << ": observed order in Δt " << text(c["time_order"])
           << ", in Δx " << text(c["space_order"]) << ".  \n";
    }
    md << "\nPlots: b5_volume.png, b5_convergence.png (the topology change against the cells and "
          "against Δt).\n\n";
}

}  // namespace meniscus::app::validate_fluid
