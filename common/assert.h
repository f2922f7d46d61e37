#pragma once
/// \file Project-wide invariant checks.
///
/// MENISCUS_ASSERT(cond, message) throws meniscus::InvariantError carrying file:line when `cond`
/// is false. It guards broken *internal* invariants (a bug in Meniscus), not bad user input, which
/// is reported with std::invalid_argument / std::runtime_error. Compiled in unless the build sets
/// MENISCUS_ASSERTS=OFF.

#include <stdexcept>
#include <string>

namespace meniscus {

/// Thrown when an internal invariant is violated; the message starts with "file:line: ".
class InvariantError : public std::logic_error {
public:
    using std::logic_error::logic_error;
};

namespace detail {
[[noreturn]] inline void assertion_failed(const char* condition, const char* file, int line,
                                          const std::string& message) {
    throw InvariantError(std::string(file) + ":" + std::to_string(line) + ": invariant `" +
                         condition + "` failed" + (message.empty() ? "" : ": " + message));
}
}  // namespace detail

}  // namespace meniscus

#if defined(MENISCUS_ENABLE_ASSERTS)
#define MENISCUS_ASSERT(condition, message)                                                  \
    do {                                                                                     \
        if (!(condition))                                                                    \
            ::meniscus::detail::assertion_failed(#condition, __FILE__, __LINE__, (message)); \
    } while (false)
#else
#define MENISCUS_ASSERT(condition, message) \
    do {                                    \
    } while (false)
#endif
