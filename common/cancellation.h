#pragma once
/// \file Cooperative cancellation of long computations.
///
/// A CancellationToken is a read-only view of a stop flag that someone else sets (the `meniscus`
/// command sets it from its SIGINT/SIGTERM handlers; libraries never know why). Long loops —
/// linear-solver iterations, meshing, remeshing passes, collision rounds — call
/// throw_if_requested() at safe points; it throws Cancelled, which unwinds the computation.
/// The object being computed is then in an unspecified but destructible state: a caller that
/// catches Cancelled discards it (e.g. the frame in progress). A default token is never
/// requested, so code that is not given one runs as before.

#include <atomic>
#include <stdexcept>
#include <string>

namespace meniscus {

/// Thrown by throw_if_requested(); what() names the place that noticed the request.
class Cancelled : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A cheap, copyable view of a stop flag owned elsewhere (which must outlive every copy).
class CancellationToken {
public:
    /// A token that is never requested.
    CancellationToken() = default;
    /// A token that is requested once `*flag` becomes true.
    explicit CancellationToken(const std::atomic<bool>* flag) : m_flag(flag) {}

    /// True when the token is tied to a flag (it may be requested some day).
    bool can_be_requested() const { return m_flag != nullptr; }
    /// True once the owner asked to stop.
    bool requested() const { return m_flag != nullptr && m_flag->load(std::memory_order_relaxed); }
    /// Throws Cancelled("cancelled in <where>") when requested().
    void throw_if_requested(const char* where) const {
        if (requested())
            throw Cancelled(std::string("cancelled in ") + where);
    }

private:
    const std::atomic<bool>* m_flag = nullptr;
};

}  // namespace meniscus
