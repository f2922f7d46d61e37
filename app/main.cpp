/// The `meniscus` command line. Exit codes: 0 success, 1 internal failure or a failed write,
/// 2 bad input (arguments, scene, mesh file, output folder), 130 / 143 stopped by SIGINT
/// (Ctrl-C) / SIGTERM (all written frames complete).

#include "app/json_fields.h"
#include "app/resource_estimate.h"
#include "app/run.h"
#include "app/scene.h"
#include "app/stop_signals.h"
#include "app/validate.h"
#include "common/assert.h"
#include "common/atomic_file.h"
#include "common/cancellation.h"

#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace meniscus::app;

/// Set once a run has started on several MPI ranks.
bool g_distributed_run = false;

constexpr int EXIT_OK = 0;
constexpr int EXIT_INTERNAL = 1;
constexpr int EXIT_BAD_INPUT = 2;

const char* USAGE =
    "usage: meniscus <command> [options]\n"
    "\n"
    "commands:\n"
    "  run SCENE.json [--out DIR] [--frames N] [--max-steps N] [--quiet] [--threads N]\n"
    "                 [--max-memory GB] [--max-steps-per-frame N]\n"
    "  run --resume DIR [SCENE.json] [--allow-scene-change] [--frames N] [--threads N]\n"
    "        run a scene, writing per frame surface_NNNN.ply, fields_NNNN.vdb and a line of\n"
    "        stats.jsonl into DIR (default: out/), described by DIR/meniscus.json (units,\n"
    "        frame rate, files); an earlier run's frames in DIR are removed first. --frames N\n"
    "        overrides the scene's frame count (keeping its time per frame); --max-steps N\n"
    "        stops after N time steps (smoke tests).\n"
    "        Before it starts, the run's memory and time steps per frame are estimated; a\n"
    "        scene above --max-memory (default: half the machine's memory) or\n"
    "        --max-steps-per-frame (default 100000) is refused, naming what drives the estimate.\n"
    "        Ctrl-C or SIGTERM stops within a second or two (the frame in progress is\n"
    "        discarded; every frame whose stats.jsonl line is written is complete); a second\n"
    "        one ends the program at once.\n"
    "        Every frame (/output/checkpoint_every) also writes DIR/checkpoint.bin; --resume DIR\n"
    "        continues the run in DIR from it, writing the same frames an uninterrupted run\n"
    "        would, byte for byte. The scene is the one the checkpoint names (or SCENE.json); a\n"
    "        scene changed since is refused unless --allow-scene-change. --threads N (or\n"
    "        MENISCUS_THREADS) limits the worker threads.\n"
    "        Started by mpirun -n K, a fluid scene's grid is split over K ranks (rank 0\n"
    "        writes); its checkpoints resume on any number of ranks, or without mpirun.\n"
    "  validate [--quick|--full] [--out DIR] [--case A1|A2|A3|A4|A6|B1|...|B7]...\n"
    "           [--xi X]... [--curvature-operator cotangent|quartic_fit]... [--threads N]\n"
    "        run the validation cases — A: the paper's geometric flows (A1–A4; A5 is the cost\n"
    "        of A1's steps) and Zalesak's notched sphere turned once (A6), B: two-phase flow with\n"
    "        surface tension (quick: coarse, minutes; full: the references' resolutions, hours)\n"
    "        — and write report.md, results.json and plots into DIR\n"
    "        (default: validation/); --case runs only the named cases (repeatable);\n"
    "        --xi runs only the part-A runs at edge length X m (repeatable, e.g.\n"
    "        --full --case A2 --xi 0.01); --curvature-operator runs A2 only with the named\n"
    "        operators (repeatable; naming quartic_fit runs its dumbbell rows in quick mode\n"
    "        too); --threads N (or MENISCUS_THREADS) limits the worker threads; exit code 1\n"
    "        if a run failed or intersected\n"
    "  scene-reference\n"
    "        print every scene key with its type, default, unit and meaning (Markdown)\n"
    "\n"
    "options:\n"
    "  --help     this text\n"
    "  --version  the version\n"
    "\n"
    "exit codes: 0 success, 1 internal failure or failed write (full disk), 2 bad input,\n"
    "            130 stopped by Ctrl-C (SIGINT), 143 stopped by SIGTERM\n";

class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

int parse_positive_int(const std::string& flag, const std::string& text) {
    try {
        size_t used = 0;
        const long v = std::stol(text, &used);
        if (used != text.size() || v <= 0 || v > 1000000)
            throw std::out_of_range(text);
        return static_cast<int>(v);
    } catch (const std::exception&) {
        throw UsageError(flag + ": expected a whole number from 1 to 1000000, got '" + text + "'");
    }
}

/// A positive number (e.g. gigabytes) of at most `max`.
double parse_positive_number(const std::string& flag, const std::string& text, double max,
                             const char* what) {
    try {
        size_t used = 0;
        const double v = std::stod(text, &used);
        if (used != text.size() || !(v > 0.0) || !(v <= max))
            throw std::out_of_range(text);
        return v;
    } catch (const std::exception&) {
        throw UsageError(flag + ": expected " + what + ", got '" + text + "'");
    }
}

double parse_positive_length(const std::string& flag, const std::string& text) {
    try {
        size_t used = 0;
        const double v = std::stod(text, &used);
        if (used != text.size() || !(v > 0.0) || !std::isfinite(v))
            throw std::out_of_range(text);
        return v;
    } catch (const std::exception&) {
        throw UsageError(flag + ": expected a positive length in metres, got '" + text + "'");
    }
}

/// The worker-thread limit of --threads N, else of MENISCUS_THREADS, else none (TBB's default:
/// every core). Held for the whole run.
std::unique_ptr<tbb::global_control> thread_control(int threads) {
    if (threads <= 0) {
        const char* env = std::getenv("MENISCUS_THREADS");
        if (env == nullptr || *env == '\0')
            return nullptr;
        threads = parse_positive_int("MENISCUS_THREADS", env);
    }
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                 static_cast<size_t>(threads));
}

int command_run(const std::vector<std::string>& args) {
    std::string scene_path;
    RunOptions options;
    bool allow_scene_change = false, out_given = false;
    int threads = 0;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        const auto value = [&]() -> const std::string& {
            if (i + 1 >= args.size())
                throw UsageError(a + ": missing value");
            return args[++i];
        };
        if (a == "--out") {
            options.out_dir = value();
            out_given = true;
        } else if (a == "--frames")
            options.frames = parse_positive_int(a, value());
        else if (a == "--max-steps")
            options.max_steps = parse_positive_int(a, value());
        else if (a == "--quiet")
            options.quiet = true;
        else if (a == "--resume") {
            options.out_dir = value();
            options.resume = true;
        } else if (a == "--allow-scene-change")
            allow_scene_change = true;
        else if (a == "--threads")
            threads = parse_positive_int(a, value());
        else if (a == "--max-memory")
            options.limits.max_memory_bytes =
                1e9 * parse_positive_number(a, value(), 1e6, "a memory size in GB, up to 1e6");
        else if (a == "--max-steps-per-frame")
            options.limits.max_steps_per_frame = parse_positive_number(
                a, value(), 1e15, "a number of time steps per frame, up to 1e15");
        else if (!a.empty() && a[0] == '-')
            throw UsageError("run: unknown option " + a);
        else if (scene_path.empty())
            scene_path = a;
        else
            throw UsageError("run: more than one scene file given ('" + scene_path + "', '" + a +
                             "')");
    }
    if (options.resume && out_given)
        throw UsageError("run: --resume DIR continues the run in DIR; --out cannot name another");
    if (allow_scene_change && !options.resume)
        throw UsageError("run: --allow-scene-change only applies with --resume DIR");
    if (scene_path.empty() && !options.resume)
        throw UsageError("run: no scene file given");
    const auto thread_limit = thread_control(threads);
    // Under mpirun (or another MPI launcher) with more than one rank, a fluid scene's grid is
    // split over the ranks (issue 40); without a launcher MPI is not even started here.
    if (meniscus::fluid::launched_by_mpi_launcher()) {
        options.ranks = meniscus::fluid::RankCommunicator::world();
        if (options.ranks.size() > 1) {
            g_distributed_run = true;
            options.limits.ranks = options.ranks.size();
            if (options.ranks.rank() != 0)
                options.quiet = true;
        }
    }
    install_stop_signal_handlers();
    std::string note;
    const Scene scene = options.resume
                            ? scene_for_resume(options.out_dir, scene_path, allow_scene_change, &note)
                            : load_scene(scene_path);
    if (!note.empty())
        std::fprintf(stderr, "meniscus: warning: %s\n", note.c_str());
    if (options.ranks.size() > 1 && scene.flow.type != "fluid")
        throw UsageError("run: a geometric flow (/flow/type " + scene.flow.type +
                         ") has no grid to split: run it without mpirun");
    const RunResult result = run_scene(scene, options, stop_requested_flag());
    if (result.interrupted) {
        std::fprintf(stderr, "meniscus: interrupted at t = %g s; frames 0..%d in %s are complete\n",
                     result.simulated_time, result.frames_written - 1, options.out_dir.c_str());
        return stop_exit_code();
    }
    if (result.stalled) {
        std::fprintf(stderr,
                     "meniscus: the flow stalled at t = %g s (steps advanced no time); frames "
                     "0..%d in %s are complete\n",
                     result.simulated_time, result.frames_written - 1, options.out_dir.c_str());
        return EXIT_INTERNAL;
    }
    if (!options.quiet)
        std::fprintf(stderr, "meniscus: wrote %d frames (%lld steps) to %s\n",
                     result.frames_written, result.steps, options.out_dir.c_str());
    return EXIT_OK;
}

int dispatch(int argc, char** argv) {
    const std::vector<std::string> args(argv + 1, argv + argc);
    if (args.empty())
        throw UsageError("no command given");
    const std::string& command = args[0];
    if (command == "--help" || command == "-h" || command == "help") {
        std::fputs(USAGE, stdout);
        return EXIT_OK;
    }
    if (command == "--version") {
        std::printf("meniscus %s\n", MENISCUS_VERSION);
        return EXIT_OK;
    }
    if (command == "run")
        return command_run({args.begin() + 1, args.end()});
    if (command == "validate") {
        ValidateOptions options;
        int threads = 0;
        for (size_t i = 1; i < args.size(); ++i) {
            if (args[i] == "--quick")
                options.full = false;
            else if (args[i] == "--full")
                options.full = true;
            else if (args[i] == "--out" && i + 1 < args.size())
                options.out_dir = args[++i];
            else if (args[i] == "--case" && i + 1 < args.size())
                options.cases.push_back(args[++i]);  // checked below with the rest
            else if (args[i] == "--xi" && i + 1 < args.size())
                options.xis.push_back(parse_positive_length("--xi", args[++i]));
            else if (args[i] == "--curvature-operator" && i + 1 < args.size())
                options.curvature_operators.push_back(args[++i]);  // checked below
            else if (args[i] == "--threads" && i + 1 < args.size())
                threads = parse_positive_int("--threads", args[++i]);
            else
                throw UsageError("validate: unknown or incomplete option " + args[i]);
        }
        try {
            check_validate_options(options);
        } catch (const std::invalid_argument& e) {
            throw UsageError(e.what());
        }
        const auto thread_limit = thread_control(threads);
        return run_validation(options);
    }
    if (command == "scene-reference") {
        std::fputs(scene_reference_markdown().c_str(), stdout);
        return EXIT_OK;
    }
    throw UsageError("unknown command '" + command + "'");
}

}  // namespace

int run_main(int argc, char** argv) {
    try {
        return dispatch(argc, argv);
    } catch (const UsageError& e) {
        std::fprintf(stderr, "meniscus: %s\n\n%s", e.what(), USAGE);
        return EXIT_BAD_INPUT;
    } catch (const SceneError& e) {
        std::fprintf(stderr, "meniscus: bad scene: %s\n", e.what());
        return EXIT_BAD_INPUT;
    } catch (const InputError& e) {
        std::fprintf(stderr, "meniscus: bad input: %s\n", e.what());
        return EXIT_BAD_INPUT;
    } catch (const meniscus::Cancelled&) {
        std::fprintf(stderr, "meniscus: interrupted before the first frame was written\n");
        return stop_exit_code();
    } catch (const meniscus::WriteError& e) {
        std::fprintf(stderr, "meniscus: cannot write output: %s\n", e.what());
        return EXIT_INTERNAL;
    } catch (const InternalFailure& e) {
        std::fprintf(stderr,
                     "meniscus: internal failure %s\n(a fault in meniscus, not in the input: "
                     "please report it with the scene)\n",
                     e.what());
        return EXIT_INTERNAL;
    } catch (const meniscus::InvariantError& e) {
        std::fprintf(stderr,
                     "meniscus: internal failure: broken invariant at %s\n(a fault in meniscus, "
                     "not in the input: please report it with the scene)\n",
                     e.what());
        return EXIT_INTERNAL;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "meniscus: internal failure: out of memory\n");
        return EXIT_INTERNAL;
    } catch (const std::exception& e) {
        std::fprintf(stderr,
                     "meniscus: internal failure: %s\n(a fault in meniscus, not in the input: "
                     "please report it with the scene)\n",
                     e.what());
        return EXIT_INTERNAL;
    }
}

int main(int argc, char** argv) {
    const int code = run_main(argc, argv);
    // A rank of a distributed run that fails ends the job: the others would wait for it in their
    // next collective call for ever.
    if (g_distributed_run && code != EXIT_OK && code != stop_exit_code())
        meniscus::fluid::RankCommunicator::world().abort(code);
    return code;
}
