#include "app/progress.h"

#include <unistd.h>

#include <cmath>
#include <utility>

namespace meniscus::app {

namespace {
constexpr int BAR_WIDTH = 30;
}

std::string format_duration(double seconds) {
    if (!std::isfinite(seconds) || seconds < 0)
        return "--:--";
    const long s = std::lround(seconds);
    char buf[32];
    if (s >= 3600)
        std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
    else
        std::snprintf(buf, sizeof buf, "%02ld:%02ld", s / 60, s % 60);
    return buf;
}

Progress::Progress(std::FILE* stream, bool quiet, std::string unit, double min_line_seconds)
    : m_stream(stream),
      m_quiet(quiet),
      m_terminal(isatty(fileno(stream)) != 0),
      m_unit(std::move(unit)),
      m_min_line_seconds(min_line_seconds),
      m_start(std::chrono::steady_clock::now()) {}

void Progress::frame_done(int frame, int frames, double time, const std::string& detail) {
    if (m_quiet)
        return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
    const double eta = frame > 0 ? elapsed / frame * (frames - frame) : NAN;
    if (m_terminal) {
        const int filled = frames > 0 ? BAR_WIDTH * frame / frames : BAR_WIDTH;
        std::string bar(static_cast<size_t>(filled), '#');
        bar.resize(BAR_WIDTH, '.');
        std::fprintf(m_stream, "\r\033[K[%s] %s %d/%d  t=%.4g s  ETA %s  %s", bar.c_str(),
                     m_unit.c_str(), frame, frames, time, format_duration(eta).c_str(),
                     detail.c_str());
        m_drawn = true;
    } else {
        const bool due = m_last_line < 0 || elapsed - m_last_line >= m_min_line_seconds;
        if (!due && frame < frames)
            return;
        m_last_line = elapsed;
        std::fprintf(m_stream, "%s %d/%d t=%.6g s elapsed %s ETA %s %s\n", m_unit.c_str(), frame,
                     frames, time, format_duration(elapsed).c_str(),
                     format_duration(eta).c_str(), detail.c_str());
    }
    std::fflush(m_stream);
}

void Progress::finish() {
    if (m_drawn && m_terminal)
        std::fputc('\n', m_stream);
    m_drawn = false;
    std::fflush(m_stream);
}

}  // namespace meniscus::app
