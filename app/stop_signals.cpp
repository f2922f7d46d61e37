#include "app/stop_signals.h"

#include <atomic>
#include <csignal>

#include <signal.h>

namespace meniscus::app {

namespace {

/// Lock-free atomics are async-signal-safe to store from a handler.
std::atomic<bool> g_stop_requested{false};
std::atomic<int> g_stop_signal{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "signal handlers need lock-free atomics");

/// Both signals are blocked while the handler runs (sa_mask), so it is never re-entered.
extern "C" void on_stop_signal(int signal_number) {
    if (g_stop_requested.load()) {
        // A second SIGINT or SIGTERM: end at once by the default action. The raised signal is
        // blocked until the handler returns, then delivered.
        struct sigaction fallback {};
        fallback.sa_handler = SIG_DFL;
        sigemptyset(&fallback.sa_mask);
        sigaction(signal_number, &fallback, nullptr);
        raise(signal_number);
        return;
    }
    g_stop_signal.store(signal_number);
    g_stop_requested.store(true);
}

}  // namespace

void install_stop_signal_handlers() {
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    sigaddset(&action.sa_mask, SIGINT);
    sigaddset(&action.sa_mask, SIGTERM);
    action.sa_flags = SA_RESTART;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

const std::atomic<bool>& stop_requested_flag() {
    return g_stop_requested;
}

int stop_signal() {
    return g_stop_signal.load();
}

int stop_exit_code() {
    const int s = stop_signal();
    return 128 + (s != 0 ? s : SIGINT);
}

}  // namespace meniscus::app
