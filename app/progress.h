#pragma once
/// \file Progress display: a redrawn bar on a terminal, one plain line per frame otherwise.

#include <chrono>
#include <cstdio>
#include <string>

namespace meniscus::app {

class Progress {
public:
    /// `stream` is where progress goes (stderr); `quiet` silences it entirely.
    Progress(std::FILE* stream, bool quiet);
    /// Frame `frame` of `frames` is done at simulated time `time` (s); `detail` is appended.
    void frame_done(int frame, int frames, double time, const std::string& detail);
    /// Ends the bar (newline on a terminal).
    void finish();

private:
    std::FILE* m_stream;
    bool m_quiet;
    bool m_terminal;
    bool m_drawn = false;
    std::chrono::steady_clock::time_point m_start;
};

/// "mm:ss" or "h:mm:ss" for a duration in seconds.
std::string format_duration(double seconds);

}  // namespace meniscus::app
