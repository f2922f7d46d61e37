#pragma once
/// \file Progress display: a redrawn bar on a terminal, one plain line per frame otherwise.

#include <chrono>
#include <cstdio>
#include <string>

namespace meniscus::app {

class Progress {
public:
    /// `stream` is where progress goes (stderr); `quiet` silences it entirely. `unit` names
    /// what is counted ("frame"; "%" for a share of a run). Off a terminal, a plain line is
    /// written at most every `min_line_seconds` of wall time (the last one always).
    Progress(std::FILE* stream, bool quiet, std::string unit = "frame",
             double min_line_seconds = 0.0);
    /// Frame `frame` of `frames` is done at simulated time `time` (s); `detail` is appended.
    void frame_done(int frame, int frames, double time, const std::string& detail);
    /// Ends the bar (newline on a terminal). Idempotent.
    void finish();
    /// Ends the bar too, so that a message after a run that was stopped by an exception (a
    /// stop request inside a step) starts on its own line.
    ~Progress() { finish(); }
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

private:
    std::FILE* m_stream;
    bool m_quiet;
    bool m_terminal;
    std::string m_unit;
    double m_min_line_seconds;
    bool m_drawn = false;
    std::chrono::steady_clock::time_point m_start;
    double m_last_line = -1.0;  ///< elapsed seconds at the last plain line; < 0: none yet
};

/// "mm:ss" or "h:mm:ss" for a duration in seconds.
std::string format_duration(double seconds);

}  // namespace meniscus::app
