#pragma once
/// \file SIGINT and SIGTERM as a cooperative stop request for `meniscus run`.
///
/// The first SIGINT (Ctrl-C) or SIGTERM (`timeout`, batch schedulers, `docker stop`) sets a flag
/// that the run's CancellationToken reads: the run stops at its next safe point, keeps every
/// complete frame and exits with 128 + the signal number (130, 143). A second signal of either
/// kind ends the process at once (default action). Only app/ installs handlers; libraries see
/// the token alone.

#include <atomic>

namespace meniscus::app {

/// Installs the handlers (idempotent). Call once, before the work that should be stoppable.
void install_stop_signal_handlers();
/// The flag the first SIGINT or SIGTERM sets (what run_scene() watches).
const std::atomic<bool>& stop_requested_flag();
/// The signal that requested the stop (SIGINT or SIGTERM), 0 if none arrived.
int stop_signal();
/// The exit code for a run stopped by stop_signal(): 128 + the signal number.
int stop_exit_code();

}  // namespace meniscus::app
