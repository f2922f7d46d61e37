#pragma once
// Running the built `meniscus` binary as a child process with limits: a wall-time bound (the
// child is killed with SIGKILL past it), an address-space bound (RLIMIT_AS) and a file-size
// bound (RLIMIT_FSIZE, to inject write failures), with its output captured.

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <chrono>
#include <csignal>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

namespace meniscus::test {

/// How a child ended.
struct ChildResult {
    bool exited = false;     ///< ended by exit() (else by a signal, or timed out)
    int exit_code = -1;      ///< when exited
    int signal = 0;          ///< the signal that ended it, when !exited
    bool timed_out = false;  ///< killed for exceeding the wall-time bound
    double seconds = 0.0;    ///< wall time
    std::string output;      ///< stdout and stderr together
};

/// Limits applied in the child before exec (0 = none).
struct ChildLimits {
    double wall_seconds = 120.0;
    /// RLIMIT_AS; under AddressSanitizer, ASan's hard_rss_limit_mb instead.
    unsigned long long address_space_bytes = 0;
    unsigned long long file_size_bytes = 0;      ///< RLIMIT_FSIZE (SIGXFSZ ignored: EFBIG)
};

/// True when built with AddressSanitizer (which reserves terabytes of address space, so
/// RLIMIT_AS cannot bound it).
constexpr bool built_with_address_sanitizer() {
#if defined(__SANITIZE_ADDRESS__)
    return true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
    return true;
#else
    return false;
#endif
#else
    return false;
#endif
}

/// Starts `argv` (argv[0] is the program) with `limits`, output to `log_path`. `while_running`
/// (optional) is called every 20 ms with the child's pid until it ends; it may signal it.
inline ChildResult run_child(const std::vector<std::string>& argv, const ChildLimits& limits,
                             const std::string& log_path,
                             const std::function<void(pid_t, double seconds)>& while_running = {}) {
    std::vector<char*> args;
    for (const std::string& a : argv)
        args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    // The environment, prepared before fork. Under AddressSanitizer the address-space bound
    // becomes ASan's own resident-memory bound (RLIMIT_AS cannot hold its shadow memory).
    std::vector<std::string> environment;
    for (char** e = environ; *e != nullptr; ++e)
        if (!built_with_address_sanitizer() || std::string(*e).rfind("ASAN_OPTIONS=", 0) != 0)
            environment.emplace_back(*e);
    if (built_with_address_sanitizer() && limits.address_space_bytes > 0) {
        const char* asan = std::getenv("ASAN_OPTIONS");
        environment.push_back(std::string("ASAN_OPTIONS=") + (asan ? asan : "") +
                              (asan && *asan ? ":" : "") + "hard_rss_limit_mb=" +
                              std::to_string(limits.address_space_bytes >> 20));
    } else if (const char* asan = std::getenv("ASAN_OPTIONS")) {
        environment.push_back(std::string("ASAN_OPTIONS=") + asan);
    }
    std::vector<char*> envp;
    for (const std::string& e : environment)
        envp.push_back(const_cast<char*>(e.c_str()));
    envp.push_back(nullptr);
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    ChildResult r;
    if (pid < 0)
        return r;
    if (pid == 0) {
        // Only async-signal-safe calls from here to exec.
        const int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd < 0)
            _exit(127);
        dup2(fd, STDOUT_FILENO);
        dup2(fd, STDERR_FILENO);
        setpgid(0, 0);  // its own process group: the test's signals reach only it
        if (limits.address_space_bytes > 0 && !built_with_address_sanitizer()) {
            const rlimit as{limits.address_space_bytes, limits.address_space_bytes};
            setrlimit(RLIMIT_AS, &as);
        }
        if (limits.file_size_bytes > 0) {
            signal(SIGXFSZ, SIG_IGN);  // stays ignored across exec: writes fail with EFBIG
            const rlimit fs{limits.file_size_bytes, limits.file_size_bytes};
            setrlimit(RLIMIT_FSIZE, &fs);
        }
        execve(args[0], args.data(), envp.data());
        _exit(127);
    }
    int status = 0;
    while (true) {
        const pid_t done = waitpid(pid, &status, WNOHANG);
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (done == pid)
            break;
        if (elapsed > limits.wall_seconds) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            r.timed_out = true;
            break;
        }
        if (while_running)
            while_running(pid, elapsed);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.exited = !r.timed_out && WIFEXITED(status);
    r.exit_code = r.exited ? WEXITSTATUS(status) : -1;
    r.signal = !r.exited && WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    std::ifstream in(log_path);
    r.output.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return r;
}

}  // namespace meniscus::test
