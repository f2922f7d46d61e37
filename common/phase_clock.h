#pragma once
/// \file Wall and CPU seconds of the phases of a step.
///
/// CPU time is the whole process's (every thread's), so with N busy threads a phase's CPU
/// seconds approach N times its wall seconds; CPU seconds per cell per step is the figure that
/// says how much work a phase does, wall seconds what a user waits.

#include <chrono>
#include <ctime>

namespace meniscus {

/// Seconds spent in a phase: wall-clock and process CPU.
struct PhaseSeconds {
    double wall = 0.0;
    double cpu = 0.0;

    PhaseSeconds& operator+=(const PhaseSeconds& other) {
        wall += other.wall;
        cpu += other.cpu;
        return *this;
    }
    PhaseSeconds& operator-=(const PhaseSeconds& other) {
        wall -= other.wall;
        cpu -= other.cpu;
        return *this;
    }
};

/// CPU seconds used so far by every thread of this process.
inline double process_cpu_seconds() {
    timespec now{};
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now) != 0)
        return 0.0;
    return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

/// A stopwatch that hands out the seconds since its last lap (or its start).
class PhaseClock {
public:
    PhaseClock() : m_wall(std::chrono::steady_clock::now()), m_cpu(process_cpu_seconds()) {}

    /// Seconds since the last lap (or construction); restarts the clock.
    PhaseSeconds lap() {
        const auto wall = std::chrono::steady_clock::now();
        const double cpu = process_cpu_seconds();
        const PhaseSeconds elapsed{std::chrono::duration<double>(wall - m_wall).count(),
                                   cpu - m_cpu};
        m_wall = wall;
        m_cpu = cpu;
        return elapsed;
    }

    /// Adds the seconds since the last lap to `phase` and restarts the clock.
    void lap_into(PhaseSeconds& phase) { phase += lap(); }

private:
    std::chrono::steady_clock::time_point m_wall;
    double m_cpu;
};

}  // namespace meniscus
